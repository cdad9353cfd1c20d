//! Air-gap reluctance R_gap(z), symbolic, for every gap model of the spec.
//!
//! McLyman fringing (perfect-tracking-soft-landing [PT 6]; jiles-atherton-
//! actuator-model [JA 11]) contains `z·ln(k/z)`. Its value and first derivative
//! have finite limits at z → 0⁺, but R_gap'' diverges like ln z, and R_gap''
//! enters the jerk, α(x) and the costate equations. We therefore use one smooth
//! regularisation everywhere:
//!
//! ```text
//! ln(k/z)  →  ln(k/(z + Z_EPS)),   Z_EPS = 1e-9 m
//! ```
//!
//! It is C^∞ on z ≥ 0, gives the exact limits R_gap(0) and R_gap'(0), keeps
//! every derivative finite at z = 0 (R_gap''(0) ∝ ln(k/Z_EPS) ≈ 17, R_gap''' ∝
//! 1/Z_EPS), and changes R_gap by at most Z_EPS/√A relative for `mclyman`
//! (2.3e-7 for A = 20 mm²) and k1·Z_EPS for `mclyman-fit` (1.4e-6 for
//! k1 = 1350 m⁻¹): far below any identified parameter's accuracy. A frozen
//! logarithm below a threshold would be cheaper but is not smooth, and
//! collocation solvers then fail to converge.

use crate::description::Gap;
use crate::sym::{Graph, Id, E};

use super::params::Params;
use super::table::Spline;

/// Vacuum permeability μ0 = 4π·10⁻⁷ H/m (the classical value the papers use).
pub const MU0: f64 = 4.0e-7 * std::f64::consts::PI;

/// Regularisation length of the McLyman logarithm [m] (see the module docs).
pub const Z_EPS: f64 = 1e-9;

/// Model-level names of subexpressions (see `Model::named`).
pub type Names = Vec<(&'static str, Id)>;

/// R_gap(z) as an expression of the position symbol `z`; the fringing
/// terms' names go to `names`.
pub fn reluctance(g: &mut Graph, params: &mut Params, gap: &Gap, z: Id, names: &mut Names) -> Id {
    match gap {
        Gap::Linear { slope, offset } => {
            let k = params.key(g, "gap.slope", *slope);
            let r0 = params.key(g, "gap.offset", *offset);
            g.with(|s| {
                let [k, r0, z] = s.exprs([k, r0, z]);
                (r0 + k * z).id()
            })
        }
        Gap::McLyman {
            area,
            winding_length,
        } => mclyman(g, params, *area, *winding_length, z, names),
        Gap::McLymanFit {
            r0,
            r0_prime,
            k1,
            k2,
        } => mclyman_fit(g, params, [*r0, *r0_prime, *k1, *k2], z, names),
        Gap::Table { z: zs, r, r_prime } => Spline::fit(zs, r, r_prime.as_deref()).expression(g, z),
    }
}

/// ln(k / (z + Z_EPS)): the regularised McLyman logarithm.
fn fringing_log<'s>(k: E<'s>, z: E<'s>, names: &mut Names) -> E<'s> {
    let z_reg = z + Z_EPS;
    let log = (k / z_reg).ln();
    names.extend([("z_reg", z_reg.id()), ("fringe_log", log.id())]);
    log
}

/// [PT 6]: R_gap = (z/(μ0·A)) / (1 + z/√A · ln(2·l_w/z)).
fn mclyman(
    g: &mut Graph,
    params: &mut Params,
    area: f64,
    winding_length: f64,
    z: Id,
    names: &mut Names,
) -> Id {
    let a = params.key(g, "gap.area", area);
    let lw = params.key(g, "gap.winding_length", winding_length);
    g.with(|s| {
        let [a, lw, z] = s.exprs([a, lw, z]);
        // μ0 made first: a node's place in the graph orders the generated code
        let mu0 = s.constant(MU0);
        let log = fringing_log(2.0 * lw, z, names);
        let den = 1.0 + z / a.sqrt() * log;
        names.push(("fringe_den", den.id()));
        (z / (mu0 * a) / den).id()
    })
}

/// jiles-atherton-actuator-model [JA 11]: R_gap = R_g0 + R'_g0·z / (1 + k1·z·ln(k2/z)).
fn mclyman_fit(
    g: &mut Graph,
    params: &mut Params,
    [r0, r0p, k1, k2]: [f64; 4],
    z: Id,
    names: &mut Names,
) -> Id {
    let r0 = params.key(g, "gap.r0", r0);
    let r0p = params.key(g, "gap.r0_prime", r0p);
    let k1 = params.key(g, "gap.k1", k1);
    let k2 = params.key(g, "gap.k2", k2);
    g.with(|s| {
        let [r0, r0p, k1, k2, z] = s.exprs([r0, r0p, k1, k2, z]);
        let log = fringing_log(k2, z, names);
        let den = 1.0 + k1 * z * log;
        names.push(("fringe_den", den.id()));
        (r0 + r0p * z / den).id()
    })
}
