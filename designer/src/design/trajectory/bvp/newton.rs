//! Damped Newton on one mesh (scipy's `solve_newton`).
//!
//! The (m−1)·n collocation residuals and the n boundary residuals are solved
//! by scipy's damped Newton: at most 8 iterations and 4 Jacobian evaluations
//! per mesh, Armijo backtracking (σ = 0.2, τ = 0.5, 4 halvings) on the squared
//! norm of the Newton step J⁻¹·res (a step that leaves the domain of f,
//! non-finite values, is halved up to 24 times: iterates stay where f is
//! defined), and a Jacobian re-use (chord step) after a full step was
//! accepted.

use super::collocation::{collocation, Colloc};
use super::jacobian::{jacobian_factor, JacWork};
use super::scaled::Eval;
use super::{BvpError, BvpProblem};

/// How a Newton pass ended.
pub(super) struct NewtonOut {
    pub(super) singular: bool,
    pub(super) iterations: usize,
    pub(super) jacobians: usize,
    pub(super) converged: bool,
}

/// The mesh node of the first non-finite entry of `v` (m·n).
fn first_nonfinite_t(x: &[f64], n: usize, v: &[f64]) -> f64 {
    let m = x.len();
    match v.iter().position(|a| !a.is_finite()) {
        Some(p) => x[(p / n).min(m - 1)],
        None => x[0],
    }
}

/// scipy's Newton criterion: every collocation residual below
/// 2/3·h·5e-2·tol·(1 + |f_mid|), every boundary residual below bc_tol.
fn converged(x: &[f64], n: usize, c: &Colloc, tol: f64, bc_tol: f64) -> bool {
    let m = x.len();
    for i in 0..m - 1 {
        let h = x[i + 1] - x[i];
        let tol_r = 2.0 / 3.0 * h * 5e-2 * tol;
        for k in 0..n {
            if !(c.res[i * n + k].abs() < tol_r * (1.0 + c.f_mid[i * n + k].abs())) {
                return false;
            }
        }
    }
    c.bc.iter().all(|r| r.abs() < bc_tol)
}

/// One Newton pass on the mesh `x`, from the iterate `y` (updated in place);
/// `c` ends with the collocation data of the final `y`.
#[allow(clippy::too_many_arguments)]
pub(super) fn newton<P: BvpProblem + ?Sized>(
    ev: &mut Eval<'_, P>,
    x: &[f64],
    y: &mut Vec<f64>,
    c: &mut Colloc,
    tol: f64,
    bc_tol: f64,
    max_iter: usize,
    max_njev: usize,
    work: &mut JacWork,
) -> Result<NewtonOut, BvpError> {
    const SIGMA: f64 = 0.2;
    const TAU: f64 = 0.5;
    const N_TRIAL: usize = 4;
    const N_DOMAIN: usize = 24;
    let n = ev.n;
    let m = x.len();
    let len = m * n;
    collocation(ev, x, y, c)?;
    let mut res = vec![0.0; len];
    let pack = |c: &Colloc, res: &mut [f64]| {
        res[..(m - 1) * n].copy_from_slice(&c.res);
        res[(m - 1) * n..].copy_from_slice(&c.bc);
    };
    pack(c, &mut res);
    let mut out = NewtonOut {
        singular: false,
        iterations: 0,
        jacobians: 0,
        converged: false,
    };
    let mut step = vec![0.0; len];
    let mut step_new = vec![0.0; len];
    let mut y_new = vec![0.0; len];
    let mut c_new = Colloc::new(n, m);
    let mut cost = 0.0;
    let mut recompute = true;
    for _ in 0..max_iter {
        if recompute {
            if !jacobian_factor(ev, x, y, c, work)? {
                out.singular = true;
                out.jacobians += 1;
                break;
            }
            out.jacobians += 1;
            work.fac.solve(&res, &mut step);
            cost = step.iter().map(|s| s * s).sum();
        }
        let fac = &mut work.fac;
        out.iterations += 1;
        let mut alpha = 1.0;
        let mut ok;
        let mut cost_new = f64::INFINITY;
        let mut bad_t = x[0];
        let mut trial = 0;
        loop {
            for q in 0..len {
                y_new[q] = y[q] - alpha * step[q];
            }
            match collocation(ev, x, &y_new, &mut c_new) {
                Ok(()) => {
                    pack(&c_new, &mut res);
                    fac.solve(&res, &mut step_new);
                    cost_new = step_new.iter().map(|s| s * s).sum();
                    ok = cost_new.is_finite();
                    if !ok {
                        bad_t = first_nonfinite_t(x, n, &step_new);
                    }
                }
                Err(BvpError::NonFinite { t, .. }) => {
                    ok = false;
                    bad_t = t;
                }
                Err(e) => return Err(e),
            }
            if ok && cost_new < (1.0 - 2.0 * alpha * SIGMA) * cost {
                break;
            }
            // Armijo backtracking ends after N_TRIAL halvings; a step that
            // leaves the domain of f (non-finite values) is halved further,
            // down to 2^-N_DOMAIN, so iterates stay where f is defined.
            let limit = if ok { N_TRIAL } else { N_DOMAIN };
            if trial >= limit {
                break;
            }
            trial += 1;
            alpha *= TAU;
        }
        if !ok {
            return Err(BvpError::NewtonDiverged { nodes: m, t: bad_t });
        }
        std::mem::swap(y, &mut y_new);
        std::mem::swap(c, &mut c_new);
        if converged(x, n, c, tol, bc_tol) {
            out.converged = true;
            break;
        }
        if out.jacobians == max_njev {
            break;
        }
        if alpha == 1.0 {
            std::mem::swap(&mut step, &mut step_new);
            cost = cost_new;
            recompute = false;
        } else {
            recompute = true;
        }
    }
    Ok(out)
}
