//! The global Jacobian of the collocation residuals (scipy's
//! `construct_global_jac`): the blocks ∂Φᵢ/∂yᵢ, ∂Φᵢ/∂yᵢ₊₁ from the caller's
//! ∂f/∂y at the nodes and midpoints, and the boundary blocks B_a, B_b.

use super::block::{resize, BlockFactor};
use super::collocation::Colloc;
use super::scaled::Eval;
use super::{BvpError, BvpProblem};

/// Buffers of the global Jacobian, kept across Newton iterations and meshes.
#[derive(Default)]
pub(super) struct JacWork {
    /// ∂f/∂y at the nodes, m × (n × n).
    jn: Vec<f64>,
    /// ∂Φᵢ/∂yᵢ, ∂Φᵢ/∂yᵢ₊₁, (m−1) × (n × n).
    a: Vec<f64>,
    b: Vec<f64>,
    jm: Vec<f64>,
    ba: Vec<f64>,
    bb: Vec<f64>,
    pub(super) fac: BlockFactor,
}

/// Builds the global Jacobian blocks (scipy's `construct_global_jac`) and
/// factors it into `w.fac`; Ok(false) when it is singular.
pub(super) fn jacobian_factor<P: BvpProblem + ?Sized>(
    ev: &mut Eval<'_, P>,
    x: &[f64],
    y: &[f64],
    c: &Colloc,
    w: &mut JacWork,
) -> Result<bool, BvpError> {
    let n = ev.n;
    let nn = n * n;
    let m = x.len();
    w.jn.resize(m * nn, 0.0);
    w.a.resize((m - 1) * nn, 0.0);
    w.b.resize((m - 1) * nn, 0.0);
    resize(&mut w.jm, nn);
    resize(&mut w.ba, nn);
    resize(&mut w.bb, nn);
    for i in 0..m {
        ev.jac(
            x[i],
            &y[i * n..(i + 1) * n],
            &mut w.jn[i * nn..(i + 1) * nn],
        )?;
    }
    let jm = &mut w.jm;
    for i in 0..m - 1 {
        let h = x[i + 1] - x[i];
        ev.jac(x[i] + 0.5 * h, &c.y_mid[i * n..(i + 1) * n], jm)?;
        let j0 = &w.jn[i * nn..(i + 1) * nn];
        let j1 = &w.jn[(i + 1) * nn..(i + 2) * nn];
        let ai = &mut w.a[i * nn..(i + 1) * nn];
        let bi = &mut w.b[i * nn..(i + 1) * nn];
        for r in 0..n {
            for col in 0..n {
                let mut t0 = 0.0;
                let mut t1 = 0.0;
                for k in 0..n {
                    t0 += jm[r * n + k] * j0[k * n + col];
                    t1 += jm[r * n + k] * j1[k * n + col];
                }
                let id = if r == col { 1.0 } else { 0.0 };
                let q = r * n + col;
                ai[q] = -id - h / 6.0 * (j0[q] + 2.0 * jm[q]) - h * h / 12.0 * t0;
                bi[q] = id - h / 6.0 * (j1[q] + 2.0 * jm[q]) + h * h / 12.0 * t1;
            }
        }
    }
    ev.bc_jac(x[0], &y[..n], &y[(m - 1) * n..], &mut w.ba, &mut w.bb)?;
    Ok(w.fac
        .factor(
            n,
            m,
            &w.a[..(m - 1) * nn],
            &w.b[..(m - 1) * nn],
            &w.ba,
            &w.bb,
        )
        .is_ok())
}
