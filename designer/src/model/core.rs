//! Iron-path models: the core's magnetomotive force MMF_core, its stored
//! energy, and for the Jiles–Atherton core the dynamics of the field H_c.
//!
//! - linear: MMF = R_core0·φ
//! - saturating (Fröhlich–Kennelly, perfect-tracking-soft-landing [PT 7]):
//!   MMF = R_core0·φ / (1 − |φ|/φ_sat)
//! - jiles-atherton (inverse JA of Sadowski et al., jiles-atherton-actuator-
//!   model [JA 21–33] with the clamp [JA 52]): MMF = H_c·l_c, and dH_c/dt follows
//!   from dφ/dt through the inverse differential permeability.

use crate::description::{Core, JilesAtherton};
use crate::sym::{Graph, Id};

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
            g.mul(r0, phi)
        }
        Core::Saturating { r0, phi_sat } => {
            let r0 = params.key(g, "core.r0", *r0);
            let ps = params.key(g, "core.phi_sat", *phi_sat);
            // [PT 7] R_core = R_core0 / (1 − |φ|/φ_sat)
            let abs = g.abs(phi);
            let frac = g.div(abs, ps);
            let one = g.one();
            let den = g.sub(one, frac);
            let num = g.mul(r0, phi);
            g.div(num, den)
        }
        Core::JilesAtherton(ja) => {
            let hc = hc.expect("the Jiles–Atherton core has the state H_c");
            let lc = params.key(g, "core.length", ja.length);
            // [JA 15] ∫_core H dl = H_c·l_c
            g.mul(hc, lc)
        }
    }
}

/// Energy stored in the core, W_core(φ) = ∫₀^φ R_core(φ')·φ' dφ' (not defined
/// for the hysteretic core, whose energy is path dependent).
pub fn stored_energy(g: &mut Graph, params: &Params, core: &Core, phi: Id) -> Option<Id> {
    let r0 = params.symbol("R_core0")?;
    match core {
        Core::Linear { .. } => {
            let phi2 = g.powi(phi, 2);
            let half = g.mul(r0, phi2);
            Some(g.scale(0.5, half))
        }
        Core::Saturating { .. } => {
            // R0·φs²·(−u − ln(1 − u)), u = |φ|/φs
            let ps = params.symbol("phi_sat")?;
            let abs = g.abs(phi);
            let u = g.div(abs, ps);
            let one = g.one();
            let one_minus = g.sub(one, u);
            let ln = g.ln(one_minus);
            let sum = g.add(u, ln);
            let ps2 = g.powi(ps, 2);
            let coef = g.mul(r0, ps2);
            let w = g.mul(coef, sum);
            Some(g.neg(w))
        }
        Core::JilesAtherton(_) => None,
    }
}

/// The Langevin function L(x) = coth x − 1/x and its derivative
/// L'(x) = 1 − coth² x + 1/x² (ERRATA: the paper's [JA 22] prints (B_e/b)²),
/// with Taylor series near 0.
fn langevin(g: &mut Graph, x: Id) -> (Id, Id) {
    let coth = g.coth(x);
    let inv = g.recip(x);
    let l_exact = g.sub(coth, inv);
    let coth2 = g.powi(coth, 2);
    let inv2 = g.powi(x, -2);
    let one = g.one();
    let t = g.sub(one, coth2);
    let dl_exact = g.add(t, inv2);
    // L = x/3 − x³/45 + 2x⁵/945 − x⁷/4725 + 2x⁹/93555
    let l_series = odd_series(
        g,
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
        g,
        x,
        &[
            1.0 / 3.0,
            -1.0 / 15.0,
            2.0 / 189.0,
            -1.0 / 675.0,
            2.0 / 10395.0,
        ],
    );
    let abs = g.abs(x);
    let threshold = g.constant(-LANGEVIN_SERIES_BELOW);
    let cond = g.add(abs, threshold);
    (
        g.select(cond, l_exact, l_series),
        g.select(cond, dl_exact, dl_series),
    )
}

/// Σ c_k·x^(2k) in Horner form in x².
fn even_series(g: &mut Graph, x: Id, c: &[f64]) -> Id {
    let x2 = g.powi(x, 2);
    let last = g.constant(c[c.len() - 1]);
    c[..c.len() - 1].iter().rev().fold(last, |acc, &ck| {
        let p = g.mul(acc, x2);
        let ck = g.constant(ck);
        g.add(p, ck)
    })
}

/// Σ c_k·x^(2k+1).
fn odd_series(g: &mut Graph, x: Id, c: &[f64]) -> Id {
    let even = even_series(g, x, c);
    g.mul(x, even)
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
    let mu0 = g.constant(MU0);
    let one = g.one();
    // [JA 32] B_c = φ/A_c, M_c = B_c/μ0 − H_c
    let bc = g.div(phi, ac);
    let bc_mu = g.div(bc, mu0);
    let mc = g.sub(bc_mu, hc);
    // [JA 23] B_e = μ0·(H_c + α·M_c)
    let amc = g.mul(alpha, mc);
    let h_eff = g.add(hc, amc);
    let be = g.mul(mu0, h_eff);
    // [JA 21], [JA 22] M_an and dM_an/dB_e
    let x = g.div(be, b);
    let (l, dl) = langevin(g, x);
    let m_an = g.mul(m_sat, l);
    let ms_b = g.div(m_sat, b);
    let dman = g.mul(ms_b, dl);
    // [JA 27] M_irr = (M_c − c·M_an)/(1 − c)
    let c_man = g.mul(c, m_an);
    let num = g.sub(mc, c_man);
    let one_minus_c = g.sub(one, c);
    let m_irr = g.div(num, one_minus_c);
    // [JA 26] dM_irr/dB_e = δ·(M_an − M_irr)/(μ0·κ), δ = sgn(dB_c/dt) = sgn(φ̇)
    let delta = g.sign(phi_dot);
    let diff = g.sub(m_an, m_irr);
    let mu_kappa = g.mul(mu0, kappa);
    let ratio = g.div(diff, mu_kappa);
    let dmirr = g.mul(delta, ratio);
    // [JA 29] dM_c/dB_e = (1 − c)·dM_irr/dB_e + c·dM_an/dB_e
    let t1 = g.mul(one_minus_c, dmirr);
    let t2 = g.mul(c, dman);
    let dmc = g.add(t1, t2);
    // [JA 30] with the clamp [JA 52]: dB_c/dB_e = max(1 + μ0(1 − α)·dM_c/dB_e, ε)
    let one_minus_alpha = g.sub(one, alpha);
    let k = g.mul(mu0, one_minus_alpha);
    let kd = g.mul(k, dmc);
    let raw = g.add(one, kd);
    let dbc = g.max(raw, eps);
    // [JA 28], [JA 31] dH_c/dB_c = 1/μ0 − dM_c/dB_e / dB_c/dB_e
    let inv_mu0 = g.recip(mu0);
    let dmc_dbc = g.div(dmc, dbc);
    let dh_db = g.sub(inv_mu0, dmc_dbc);
    // [JA 33]
    let rate = g.div(phi_dot, ac);
    g.mul(dh_db, rate)
}
