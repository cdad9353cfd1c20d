//! A two-point boundary-value-problem solver of the bvp4c / scipy `solve_bvp`
//! class, generic: it knows nothing about actuators.
//!
//! Solves y' = f(t, y), bc(y(a), y(b)) = 0 with y ∈ ℝⁿ and n boundary
//! conditions (separated or not). The algorithm follows Kierzenka & Shampine,
//! "A BVP solver based on residual control and the MATLAB PSE" (ACM TOMS 27,
//! 2001) as implemented in scipy's `scipy/integrate/_bvp.py`, one step per
//! module:
//!
//! - `scaled.rs`: the inputs checked, the problem seen in scaled variables;
//! - `collocation.rs`: the residuals of the C¹ piecewise cubic (Lobatto IIIA);
//! - `jacobian.rs`: the blocks of the global Jacobian of those residuals;
//! - `block.rs`: its factorization by block elimination (Householder QR, LU);
//! - `newton.rs`: scipy's damped Newton on one mesh;
//! - `mesh.rs`: residual control: the RMS residual of every interval, the
//!   refined mesh;
//! - `solve.rs`: the drivers [`solve_bvp`] and [`solve_collocation`];
//! - `solution.rs`, `error.rs`: what they return.
//!
//! Right-hand sides that are only piecewise smooth (e.g. a saturated optimal
//! input u* = clamp(·)) are handled: the residual control concentrates nodes
//! around the kinks.

// `!(x > tol)` is deliberate: it is also true for NaN. Index loops mirror the
// matrix formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

mod block;
mod collocation;
mod error;
mod jacobian;
mod mesh;
mod newton;
mod scaled;
mod solution;
mod solve;

pub use error::BvpError;
pub use solution::BvpSolution;
pub use solve::{solve_bvp, solve_collocation};

/// y' = f(t, y), bc(y(a), y(b)) = 0.
pub trait BvpProblem {
    /// n, the number of states (and of boundary conditions).
    fn dim(&self) -> usize;
    /// dy = f(t, y).
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]);
    /// ∂fᵢ/∂yⱼ, row-major n×n (`j[i * n + j]`).
    fn jacobian(&self, t: f64, y: &[f64], j: &mut [f64]);
    /// The n boundary residuals.
    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]);
    /// ∂bcₖ/∂y(a)ⱼ and ∂bcₖ/∂y(b)ⱼ, row-major n×n each.
    fn bc_jacobian(&self, ya: &[f64], yb: &[f64], ja: &mut [f64], jb: &mut [f64]);
}

/// Options of [`solve_bvp`]. `Default` is scipy's (tol = 1e-3, bc_tol = tol,
/// max_nodes = 1000).
#[derive(Debug, Clone, PartialEq)]
pub struct BvpOptions {
    /// Tolerance on the RMS relative collocation residual of every interval.
    pub tol: f64,
    /// Tolerance on the absolute (scaled) boundary residuals; `None` = tol.
    pub bc_tol: Option<f64>,
    /// The solver fails rather than grow the mesh beyond this.
    pub max_nodes: usize,
    /// Newton iterations per mesh (scipy: 8).
    pub max_newton: usize,
    /// Jacobian evaluations per mesh (scipy: 4).
    pub max_jacobians: usize,
    /// Refinements that add no node but leave the boundary residual above
    /// bc_tol before giving up (scipy: 10).
    pub max_iterations: usize,
    /// Per-component scale of y (length n, positive): the solver works in y/scale.
    pub scale: Option<Vec<f64>>,
    /// Per-condition scale of the boundary residuals (length n, positive).
    pub bc_scale: Option<Vec<f64>>,
}

impl Default for BvpOptions {
    fn default() -> Self {
        BvpOptions {
            tol: 1e-3,
            bc_tol: None,
            max_nodes: 1000,
            max_newton: 8,
            max_jacobians: 4,
            max_iterations: 10,
            scale: None,
            bc_scale: None,
        }
    }
}

/// Largest entry-wise discrepancy between `problem.jacobian` at (t, y) and a
/// central finite difference, relative to max(1, |J|): a check for hand-written
/// Jacobians.
pub fn jacobian_discrepancy<P: BvpProblem + ?Sized>(problem: &P, t: f64, y: &[f64]) -> f64 {
    let n = problem.dim();
    let mut j = vec![0.0; n * n];
    problem.jacobian(t, y, &mut j);
    let mut yp = y.to_vec();
    let mut fp = vec![0.0; n];
    let mut fm = vec![0.0; n];
    let mut worst: f64 = 0.0;
    for c in 0..n {
        let h = f64::EPSILON.cbrt() * (1.0 + y[c].abs());
        yp[c] = y[c] + h;
        problem.rhs(t, &yp, &mut fp);
        yp[c] = y[c] - h;
        problem.rhs(t, &yp, &mut fm);
        yp[c] = y[c];
        for r in 0..n {
            let fd = (fp[r] - fm[r]) / (2.0 * h);
            let e = (fd - j[r * n + c]).abs() / j[r * n + c].abs().max(1.0);
            worst = worst.max(if e.is_nan() { f64::INFINITY } else { e });
        }
    }
    worst
}
