//! The collocation residuals: the solution is a C¹ piecewise cubic (3-stage
//! Lobatto IIIA). On each interval [tᵢ, tᵢ₊₁] of width h it interpolates yᵢ,
//! fᵢ, yᵢ₊₁, fᵢ₊₁ and satisfies the ODE at the midpoint, which gives the
//! residual (Simpson's rule)
//! `Φᵢ = yᵢ₊₁ − yᵢ − h/6·(fᵢ + 4·f(t_mid, y_mid) + fᵢ₊₁)`,
//! `y_mid = (yᵢ + yᵢ₊₁)/2 − h/8·(fᵢ₊₁ − fᵢ)`. Fourth order at the nodes.

use super::scaled::Eval;
use super::{BvpError, BvpProblem};

/// The collocation data of one iterate on a mesh of m nodes.
pub(super) struct Colloc {
    /// Φᵢ, (m−1)·n.
    pub(super) res: Vec<f64>,
    /// y_mid, (m−1)·n.
    pub(super) y_mid: Vec<f64>,
    /// f at nodes, m·n.
    pub(super) f: Vec<f64>,
    /// f at midpoints, (m−1)·n.
    pub(super) f_mid: Vec<f64>,
    /// bc residuals, n.
    pub(super) bc: Vec<f64>,
}

impl Colloc {
    pub(super) fn new(n: usize, m: usize) -> Colloc {
        Colloc {
            res: vec![0.0; (m - 1) * n],
            y_mid: vec![0.0; (m - 1) * n],
            f: vec![0.0; m * n],
            f_mid: vec![0.0; (m - 1) * n],
            bc: vec![0.0; n],
        }
    }
}

/// Fills `c` for the iterate `y` (m·n, scaled) on the mesh `x`.
pub(super) fn collocation<P: BvpProblem + ?Sized>(
    ev: &mut Eval<'_, P>,
    x: &[f64],
    y: &[f64],
    c: &mut Colloc,
) -> Result<(), BvpError> {
    let n = ev.n;
    let m = x.len();
    for i in 0..m {
        ev.rhs(x[i], &y[i * n..(i + 1) * n], &mut c.f[i * n..(i + 1) * n])?;
    }
    for i in 0..m - 1 {
        let h = x[i + 1] - x[i];
        let (y0, y1) = (&y[i * n..(i + 1) * n], &y[(i + 1) * n..(i + 2) * n]);
        let (f0, f1) = (&c.f[i * n..(i + 1) * n], &c.f[(i + 1) * n..(i + 2) * n]);
        let ym = &mut c.y_mid[i * n..(i + 1) * n];
        for k in 0..n {
            ym[k] = 0.5 * (y0[k] + y1[k]) - 0.125 * h * (f1[k] - f0[k]);
        }
        ev.rhs(x[i] + 0.5 * h, ym, &mut c.f_mid[i * n..(i + 1) * n])?;
        let fm = &c.f_mid[i * n..(i + 1) * n];
        let r = &mut c.res[i * n..(i + 1) * n];
        for k in 0..n {
            r[k] = y1[k] - y0[k] - h / 6.0 * (f0[k] + f1[k] + 4.0 * fm[k]);
        }
    }
    ev.bc(x[0], &y[..n], &y[(m - 1) * n..], &mut c.bc)
}
