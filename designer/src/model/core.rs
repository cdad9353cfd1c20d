//! Iron-path models: the core's magnetomotive force MMF_core, its stored
//! energy, and for the Jiles–Atherton core the dynamics of the field H_c.
//!
//! - linear: MMF = R_core0·φ
//! - saturating (Fröhlich–Kennelly, perfect-tracking-soft-landing [PT 7]):
//!   MMF = R_core0·φ / (1 − |φ|/φ_sat)
//! - jiles-atherton (inverse JA of Sadowski et al., jiles-atherton-actuator-
//!   model [JA 21–33] with the clamp [JA 52]): MMF = H_c·l_c, and dH_c/dt follows
//!   from dφ/dt through the inverse differential permeability; with
//!   `core.reversal = "reversible"` the irreversible magnetisation does not
//!   move against the field's direction just after a reversal (no red
//!   region for the clamp to act on).

use crate::description::{Core, JilesAtherton, Reversal};
use crate::sym::{Graph, Id, E};

use super::gap::MU0;
use super::params::Params;

/// Below this |B_e/b| the Langevin function and its derivative use their
/// Taylor series (the closed forms cancel catastrophically near 0).
pub const LANGEVIN_SERIES_BELOW: f64 = 0.1;

/// MMF_core as an expression of φ (and H_c for Jiles–Atherton).
pub fn mmf(g: &mut Graph, params: &mut Params, core: &Core, phi: Id, hc: Option<Id>) -> Id {
    match core {
        Core::Linear { r0 } => {
            let r0 = params.key(g, "core.r0", *r0);
            g.with(|s| (s.expr(r0) * s.expr(phi)).id())
        }
        Core::Saturating { r0, phi_sat } => {
            let r0 = params.key(g, "core.r0", *r0);
            let phi_sat = params.key(g, "core.phi_sat", *phi_sat);
            g.with(|s| {
                let [r0, phi_sat, phi] = s.exprs([r0, phi_sat, phi]);
                // [PT 7] R_core = R_core0 / (1 − |φ|/φ_sat)
                let den = 1.0 - phi.abs() / phi_sat;
                (r0 * phi / den).id()
            })
        }
        Core::JilesAtherton(ja) => {
            let hc = hc.expect("the Jiles–Atherton core has the state H_c");
            let lc = params.key(g, "core.length", ja.length);
            // [JA 15] ∫_core H dl = H_c·l_c
            g.with(|s| (s.expr(hc) * s.expr(lc)).id())
        }
    }
}

/// Energy stored in the core, W_core(φ) = ∫₀^φ R_core(φ')·φ' dφ' (not defined
/// for the hysteretic core, whose energy is path dependent).
pub fn stored_energy(g: &mut Graph, params: &Params, core: &Core, phi: Id) -> Option<Id> {
    let r0 = params.symbol("R_core0")?;
    match core {
        Core::Linear { .. } => Some(g.with(|s| {
            let [r0, phi] = s.exprs([r0, phi]);
            // ½·R0·φ²
            (0.5 * (r0 * phi.powi(2))).id()
        })),
        Core::Saturating { .. } => {
            let phi_sat = params.symbol("phi_sat")?;
            Some(g.with(|s| {
                let [r0, phi_sat, phi] = s.exprs([r0, phi_sat, phi]);
                // R0·φs²·(−u − ln(1 − u)), u = |φ|/φs
                let u = phi.abs() / phi_sat;
                let sum = u + (1.0 - u).ln();
                (-(r0 * phi_sat.powi(2) * sum)).id()
            }))
        }
        Core::JilesAtherton(_) => None,
    }
}

/// The Langevin function L(x) = coth x − 1/x and its derivative
/// L'(x) = 1 − coth² x + 1/x² (ERRATA: the paper's [JA 22] prints (B_e/b)²),
/// with Taylor series near 0.
fn langevin(x: E<'_>) -> (E<'_>, E<'_>) {
    let coth = x.coth();
    let l_exact = coth - x.recip();
    let coth2 = coth.powi(2);
    let inv2 = x.powi(-2);
    let dl_exact = 1.0 - coth2 + inv2;
    // L = x/3 − x³/45 + 2x⁵/945 − x⁷/4725 + 2x⁹/93555
    let l_series = odd_series(
        x,
        &[
            1.0 / 3.0,
            -1.0 / 45.0,
            2.0 / 945.0,
            -1.0 / 4725.0,
            2.0 / 93555.0,
        ],
    );
    // L' = 1/3 − x²/15 + 2x⁴/189 − x⁶/675 + 2x⁸/10395
    let dl_series = even_series(
        x,
        &[
            1.0 / 3.0,
            -1.0 / 15.0,
            2.0 / 189.0,
            -1.0 / 675.0,
            2.0 / 10395.0,
        ],
    );
    // |x| − 0.1 ≥ 0 selects the closed forms; written |x| + (−0.1) so that
    // the graph holds the one constant −0.1 (a subtraction interns 0.1 too)
    let cond = x.abs() + -LANGEVIN_SERIES_BELOW;
    (
        cond.if_nonneg(l_exact, l_series),
        cond.if_nonneg(dl_exact, dl_series),
    )
}

/// Σ c_k·x^(2k) in Horner form in x².
fn even_series<'s>(x: E<'s>, c: &[f64]) -> E<'s> {
    let x2 = x.powi(2);
    let last = x.scope().constant(c[c.len() - 1]);
    c[..c.len() - 1]
        .iter()
        .rev()
        .fold(last, |acc, &ck| acc * x2 + ck)
}

/// Σ c_k·x^(2k+1).
fn odd_series<'s>(x: E<'s>, c: &[f64]) -> E<'s> {
    x * even_series(x, c)
}

/// [JA 33] dH_c/dt = dH_c/dB_c(φ, H_c, φ̇) · φ̇ / A_c.
pub fn ja_field_rate(
    g: &mut Graph,
    params: &mut Params,
    ja: &JilesAtherton,
    phi: Id,
    hc: Id,
    phi_dot: Id,
) -> Id {
    let ac = params.key(g, "core.area", ja.area);
    let m_sat = params.key(g, "core.m_sat", ja.m_sat);
    let b = params.key(g, "core.b", ja.b);
    let c = params.key(g, "core.c", ja.c);
    let kappa = params.key(g, "core.kappa", ja.kappa);
    let alpha = params.key(g, "core.alpha", ja.alpha);
    let eps = params.key(g, "core.epsilon", ja.epsilon);
    g.with(|s| {
        let [phi, hc, phi_dot] = s.exprs([phi, hc, phi_dot]);
        let [ac, m_sat, b, c, kappa, alpha, eps] = s.exprs([ac, m_sat, b, c, kappa, alpha, eps]);
        // μ0 and 1 made first: a node's place in the graph orders the
        // generated code
        let (mu0, _one) = (s.constant(MU0), s.constant(1.0));
        // [JA 32] B_c = φ/A_c, M_c = B_c/μ0 − H_c
        let bc = phi / ac;
        let mc = bc / mu0 - hc;
        // [JA 23] B_e = μ0·(H_c + α·M_c)
        let be = mu0 * (hc + alpha * mc);
        // [JA 21], [JA 22] M_an and dM_an/dB_e
        let (l, dl) = langevin(be / b);
        let m_an = m_sat * l;
        let dman = m_sat / b * dl;
        // [JA 27] M_irr = (M_c − c·M_an)/(1 − c)
        let m_irr = (mc - c * m_an) / (1.0 - c);
        // [JA 26] dM_irr/dB_e = δ·(M_an − M_irr)/(μ0·κ), δ = sgn(dB_c/dt) = sgn(φ̇)
        let delta = phi_dot.sign();
        let dmirr = match ja.reversal {
            Reversal::Clamp => delta * ((m_an - m_irr) / (mu0 * kappa)),
            // max(δ·(M_an − M_irr), 0)/(μ0·κ): no irreversible change against δ
            Reversal::Reversible => (delta * (m_an - m_irr)).max(0.0) / (mu0 * kappa),
        };
        // [JA 29] dM_c/dB_e = (1 − c)·dM_irr/dB_e + c·dM_an/dB_e
        let dmc = (1.0 - c) * dmirr + c * dman;
        // [JA 30] with the clamp [JA 52]: dB_c/dB_e = max(1 + μ0(1 − α)·dM_c/dB_e, ε)
        let dbc = (1.0 + mu0 * (1.0 - alpha) * dmc).max(eps);
        // [JA 28], [JA 31] dH_c/dB_c = 1/μ0 − dM_c/dB_e / dB_c/dB_e
        let dh_db = mu0.recip() - dmc / dbc;
        // [JA 33]
        (dh_db * (phi_dot / ac)).id()
    })
}
