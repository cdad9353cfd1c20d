//! Why a solve failed: invalid input, non-finite values, a singular Jacobian,
//! divergence, or a tolerance not met (the last three carry the best
//! solution found).

use super::BvpSolution;

/// Why [`solve_bvp`](super::solve_bvp) failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum BvpError {
    #[error("invalid BVP input: {0}")]
    InvalidInput(String),
    #[error("the {what} returned a non-finite value at t = {t:e} (y = {y:?})")]
    NonFinite {
        what: &'static str,
        t: f64,
        y: Vec<f64>,
    },
    #[error("singular collocation Jacobian on a mesh of {nodes} nodes (pass {iteration}, max relative residual {max_residual:.3e}): the linearized BVP has no unique solution at the current iterate (check the boundary conditions, the Jacobians and the initial guess)")]
    SingularJacobian {
        nodes: usize,
        iteration: usize,
        max_residual: f64,
    },
    #[error("Newton diverged on a mesh of {nodes} nodes: f or bc is non-finite at t = {t:e} even after the smallest damped step: the Newton iterates leave the domain of f")]
    NewtonDiverged { nodes: usize, t: f64 },
    #[error("the mesh would need {needed} nodes > max_nodes = {max_nodes}; on the current {nodes} nodes the max relative residual is {max_residual:.3e} (tol {tol:e}) and the BC residual {bc_residual:.3e}")]
    MaxNodesExceeded {
        nodes: usize,
        needed: usize,
        max_nodes: usize,
        max_residual: f64,
        tol: f64,
        bc_residual: f64,
        best: Box<BvpSolution>,
    },
    #[error("the boundary residual {bc_residual:.3e} is still above bc_tol = {bc_tol:e} after {iterations} passes (max relative residual {max_residual:.3e})")]
    BcTolerance {
        iterations: usize,
        bc_residual: f64,
        bc_tol: f64,
        max_residual: f64,
        best: Box<BvpSolution>,
    },
    #[error("Newton did not converge on the fixed mesh of {nodes} nodes: max collocation residual {collocation_residual:.3e}, BC residual {bc_residual:.3e}")]
    NotConverged {
        nodes: usize,
        collocation_residual: f64,
        bc_residual: f64,
        best: Box<BvpSolution>,
    },
}
