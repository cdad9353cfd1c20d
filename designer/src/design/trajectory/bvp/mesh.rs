//! Residual control: the error estimate of every interval and the refined
//! mesh.
//!
//! After Newton, the relative residual r = (S′ − f(t, S))/(1 + |f|) of the
//! cubic S is estimated on every interval in the RMS sense by 5-point Lobatto
//! quadrature (the residual vanishes at the nodes; midpoint and ±√(3/7)·h/2
//! are sampled). Intervals with residual > tol get one node (two if
//! ≥ 100·tol); the new mesh is initialized from the cubic.

use super::collocation::Colloc;
use super::scaled::Eval;
use super::solution::hermite;
use super::{BvpError, BvpProblem};

/// The RMS relative residual of every interval (scipy's
/// `estimate_rms_residuals`).
pub(super) fn rms_residuals<P: BvpProblem + ?Sized>(
    ev: &mut Eval<'_, P>,
    x: &[f64],
    y: &[f64],
    c: &Colloc,
) -> Result<Vec<f64>, BvpError> {
    let n = ev.n;
    let m = x.len();
    let mut out = vec![0.0; m - 1];
    let mut ys = vec![0.0; n];
    let mut dys = vec![0.0; n];
    let mut fs = vec![0.0; n];
    let d = 0.5 * (3.0f64 / 7.0).sqrt();
    for i in 0..m - 1 {
        let h = x[i + 1] - x[i];
        let mut rm = 0.0;
        for k in 0..n {
            let r = 1.5 * c.res[i * n + k] / h / (1.0 + c.f_mid[i * n + k].abs());
            rm += r * r;
        }
        let mut r12 = 0.0;
        for s in [0.5 + d, 0.5 - d] {
            hermite(
                s,
                h,
                &y[i * n..(i + 1) * n],
                &c.f[i * n..(i + 1) * n],
                &y[(i + 1) * n..(i + 2) * n],
                &c.f[(i + 1) * n..(i + 2) * n],
                &mut ys,
                &mut dys,
            );
            ev.rhs(x[i] + s * h, &ys, &mut fs)?;
            for k in 0..n {
                let r = (dys[k] - fs[k]) / (1.0 + fs[k].abs());
                r12 += r * r;
            }
        }
        out[i] = (0.5 * (32.0 / 45.0 * rm + 49.0 / 90.0 * r12)).sqrt();
    }
    Ok(out)
}

/// The nodes residual control adds to an interval of RMS residual `r`.
fn nodes_for(r: f64, tol: f64) -> usize {
    if r >= 100.0 * tol {
        2
    } else if r > tol {
        1
    } else {
        0
    }
}

/// The nodes residual control adds to the mesh.
pub(super) fn nodes_added(rms: &[f64], tol: f64) -> usize {
    rms.iter().map(|&r| nodes_for(r, tol)).sum()
}

/// The refined mesh and the iterate on it, initialized from the cubic:
/// thirds of the intervals whose residual is ≥ 100·tol, midpoints of those
/// above tol.
pub(super) fn refine(
    x: &[f64],
    y: &[f64],
    c: &Colloc,
    rms: &[f64],
    tol: f64,
    n: usize,
) -> (Vec<f64>, Vec<f64>) {
    let m = x.len();
    let added = nodes_added(rms, tol);
    let mut nx = Vec::with_capacity(m + added);
    let mut ny = Vec::with_capacity((m + added) * n);
    let mut ys = vec![0.0; n];
    let mut dys = vec![0.0; n];
    for i in 0..m - 1 {
        nx.push(x[i]);
        ny.extend_from_slice(&y[i * n..(i + 1) * n]);
        let h = x[i + 1] - x[i];
        let fracs: &[f64] = match nodes_for(rms[i], tol) {
            2 => &[1.0 / 3.0, 2.0 / 3.0],
            1 => &[0.5],
            _ => &[],
        };
        for &s in fracs {
            let xs = if s == 0.5 {
                0.5 * (x[i] + x[i + 1])
            } else if s < 0.5 {
                (2.0 * x[i] + x[i + 1]) / 3.0
            } else {
                (x[i] + 2.0 * x[i + 1]) / 3.0
            };
            hermite(
                (xs - x[i]) / h,
                h,
                &y[i * n..(i + 1) * n],
                &c.f[i * n..(i + 1) * n],
                &y[(i + 1) * n..(i + 2) * n],
                &c.f[(i + 1) * n..(i + 2) * n],
                &mut ys,
                &mut dys,
            );
            nx.push(xs);
            ny.extend_from_slice(&ys);
        }
    }
    nx.push(x[m - 1]);
    ny.extend_from_slice(&y[(m - 1) * n..]);
    (nx, ny)
}
