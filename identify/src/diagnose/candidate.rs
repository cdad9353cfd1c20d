//! One candidate explanation per cause: the baseline extended by one entry of
//! the vocabulary, with starting values, and the parameters to fit — the
//! extension's own and the few baseline parameters it interacts with.
//!
//! Every candidate refits the coil resistance: it sets the steady-state current
//! and would otherwise absorb part of any effect in an unfair way. The `none`
//! candidate refits only the resistance, so the ranking compares each
//! extension with the best the baseline itself can do.

use crate::description::{Core, Description, Gap, JilesAtherton, Reversal};
use crate::lm::GiveUp;
use crate::model::MU0;
use crate::FitParam;

use super::Cause;

/// What the data tells about the scale of the experiment (for starting values).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scales {
    /// Peak |φ| of the baseline's replay [Wb].
    pub peak_flux: f64,
    /// Duration of the record [s].
    pub duration: f64,
}

/// A cause, its extended description at the starting point, and what to fit.
#[derive(Debug, Clone)]
pub struct Candidate {
    pub cause: Cause,
    pub start: Description,
    pub params: Vec<FitParam>,
    /// Starts of the multi-start fit (1 = the starting point only).
    pub starts: usize,
    /// Other starting points among the `starts`, before the drawn ones.
    pub also_from: Vec<Description>,
    /// Where a start is given up ([`GiveUp`]; the second hysteresis start).
    pub give_up: Option<GiveUp>,
}

/// Why a cause cannot extend this baseline (it is already in the model).
#[derive(Debug, Clone, PartialEq)]
pub struct NotApplicable {
    pub cause: Cause,
    pub reason: String,
}

/// The candidate of `cause` for `baseline`, or why there is none.
pub fn candidate(
    baseline: &Description,
    cause: Cause,
    scales: Scales,
) -> Result<Candidate, NotApplicable> {
    let mut start = baseline.clone();
    let mut params = vec![resistance(baseline)];
    let mut starts = 1;
    let mut also_from = Vec::new();
    let not = |reason: &str| NotApplicable {
        cause,
        reason: reason.to_owned(),
    };
    match cause {
        Cause::None => {}
        Cause::Unexplained => return Err(not("`unexplained` is an answer, not an extension")),
        Cause::EddyCurrents => {
            if baseline.coil.eddy > 0.0 {
                return Err(not("coil.eddy is already > 0"));
            }
            // k_e comparable with N²/R doubles the electrical time constant.
            let n2_r = baseline.coil.turns.powi(2) / baseline.coil.resistance;
            start.coil.eddy = 0.1 * n2_r;
            params.push(param("coil.eddy", 1e-4 * n2_r, 10.0 * n2_r));
        }
        Cause::Saturation => {
            let Core::Linear { r0 } = baseline.core else {
                return Err(not("core.model is not \"linear\""));
            };
            // The flux never reaches φ_sat (R_core grows without bound), so
            // φ_sat may lie below the linear model's peak flux.
            let phi_sat = 1.5 * scales.peak_flux;
            start.core = Core::Saturating { r0, phi_sat };
            params.push(param("core.r0", 0.1 * r0, 10.0 * r0));
            params.push(param(
                "core.phi_sat",
                0.1 * scales.peak_flux,
                50.0 * scales.peak_flux,
            ));
            starts = 3;
        }
        Cause::Hysteresis => {
            if matches!(baseline.core, Core::JilesAtherton(_)) {
                return Err(not("core.model is already \"jiles-atherton\""));
            }
            let area = pole_area(baseline);
            // The record's peak flux density at 60 % of saturation.
            let b_sat = (scales.peak_flux / area).max(1e-3) / 0.6;
            let ja = jiles_atherton(area, linear_r0(baseline), b_sat);
            start.core = Core::JilesAtherton(ja.clone());
            params.extend(hysteresis_params(&ja));
            starts = 1;
        }
        Cause::Fringing => {
            let Gap::Linear { slope, offset } = baseline.gap else {
                return Err(not("gap.model is not \"linear\""));
            };
            // McLyman's small-gap slope 1/(μ0·A) equals the linear slope; the
            // linear offset moves into the core (R_core + R_gap stays put at z = 0).
            let area = 1.0 / (MU0 * slope);
            let winding_length = 20.0 * baseline.mechanics.z_max.max(1e-4);
            start.gap = Gap::McLyman {
                area,
                winding_length,
            };
            // (and the core as it was: where the linear gap was drawn
            // through a fringing gap's curve, its offset is the line's, not
            // a reluctance at z = 0, and the shifted core led the fit to the
            // winding length's bound, 6.8× the floor left, on a generated
            // relay of the blind class 4)
            let unshifted = start.clone();
            shift_core_reluctance(&mut start, offset);
            if start.core != unshifted.core {
                also_from.push(unshifted);
            }
            params.push(param("gap.area", 0.05 * area, 20.0 * area));
            params.push(param(
                "gap.winding_length",
                0.5 * baseline.mechanics.z_max.max(1e-5),
                1.0,
            ));
            params.push(core_reluctance_param(&start));
            starts = 3 + also_from.len();
        }
        Cause::ResistanceDrift => {
            if baseline.coil.resistance_drift != 0.0 {
                return Err(not("coil.resistance_drift is already ≠ 0"));
            }
            // Up to the resistance itself over the record (far beyond self-heating).
            let bound = baseline.coil.resistance / scales.duration.max(1e-6);
            start.coil.resistance_drift = 0.0;
            params.push(param("coil.resistance_drift", -bound, bound));
        }
        Cause::Bouncing => {
            if baseline.mechanics.restitution > 0.0 {
                return Err(not("mechanics.restitution is already > 0"));
            }
            start.mechanics.restitution = 0.5;
            params.push(param("mechanics.restitution", 0.0, 0.95));
            starts = 4;
        }
    }
    Ok(Candidate {
        cause,
        start,
        params,
        starts,
        also_from,
        give_up: None,
    })
}

/// Whether a fitted `value` of `range` ended within 0.1 % of the range
/// from one of its bounds: the data want it beyond what the fit allows.
pub fn on_bound(value: f64, range: &FitParam) -> bool {
    let near = |b: f64| (value - b).abs() <= 1e-3 * (range.upper - range.lower);
    near(range.lower) || near(range.upper)
}

fn param(path: &str, lower: f64, upper: f64) -> FitParam {
    FitParam {
        path: path.to_owned(),
        lower,
        upper,
    }
}

/// R within ±30 % of the description's value.
fn resistance(d: &Description) -> FitParam {
    let r = d.coil.resistance;
    param("coil.resistance", 0.7 * r, 1.3 * r)
}

/// Adds `offset` [H⁻¹] to the core's reluctance at φ = 0 (linear/saturating).
fn shift_core_reluctance(d: &mut Description, offset: f64) {
    match &mut d.core {
        Core::Linear { r0 } | Core::Saturating { r0, .. } => *r0 = (*r0 + offset).max(1.0),
        Core::JilesAtherton(_) => {}
    }
}

/// The core's φ = 0 reluctance as a fit parameter, when the core has one.
fn core_reluctance_param(d: &Description) -> FitParam {
    match d.core {
        Core::Linear { r0 } | Core::Saturating { r0, .. } => param("core.r0", 0.05 * r0, 20.0 * r0),
        // A Jiles–Atherton core: its length sets the reluctance.
        Core::JilesAtherton(ref ja) => param("core.length", 0.05 * ja.length, 20.0 * ja.length),
    }
}

/// The hysteresis candidate started from a fitted saturating core instead:
/// the Jiles–Atherton saturation flux density μ0·M_sat is φ_sat/A_c and the
/// initial reluctance is the fitted r0. Jiles–Atherton fits are not convex;
/// the saturation fit is cheap and finds the flux scale reliably.
pub fn hysteresis_from_saturation(
    baseline: &Description,
    saturating: &Description,
) -> Option<Candidate> {
    let Core::Saturating { r0, phi_sat } = saturating.core else {
        return None;
    };
    let area = pole_area(baseline);
    let ja = jiles_atherton(area, r0, phi_sat / area);
    let mut start = baseline.clone();
    start.coil.resistance = saturating.coil.resistance;
    start.core = Core::JilesAtherton(ja.clone());
    let mut params = vec![resistance(baseline)];
    params.extend(hysteresis_params(&ja));
    Some(Candidate {
        cause: Cause::Hysteresis,
        start,
        params,
        starts: 1,
        also_from: Vec::new(),
        give_up: None,
    })
}

/// The fitted Jiles–Atherton parameters around `ja` (α stays: the path
/// length l_c takes its part of the reduced model's α*, [JA 60]).
fn hysteresis_params(ja: &JilesAtherton) -> [FitParam; 5] {
    [
        param("core.m_sat", 0.05 * ja.m_sat, 20.0 * ja.m_sat),
        param("core.b", 0.02 * ja.b, 50.0 * ja.b),
        param("core.c", 0.02, 0.98),
        param("core.kappa", 0.02 * ja.kappa, 50.0 * ja.kappa),
        param("core.length", 0.05 * ja.length, 20.0 * ja.length),
    ]
}

/// The pole area: the gap's (A = 1/(μ0·slope) for a linear gap), else 10 mm².
fn pole_area(d: &Description) -> f64 {
    match d.gap {
        Gap::Linear { slope, .. } if slope > 0.0 => 1.0 / (MU0 * slope),
        Gap::McLyman { area, .. } => area,
        _ => 1e-5,
    }
}

/// The core's reluctance at φ = 0 of a linear or saturating core.
fn linear_r0(d: &Description) -> f64 {
    match d.core {
        Core::Linear { r0 } | Core::Saturating { r0, .. } => r0,
        Core::JilesAtherton(_) => 1e6,
    }
}

/// A Jiles–Atherton core of pole area `area`, initial reluctance `r0` and
/// saturation flux density `b_sat` = μ0·M_sat [T].
///
/// The material's shape parameters (c, κ, α, and b relative to μ0·M_sat) are
/// those the JA paper fitted for a valve's steel ([JA Table 2]); the path length
/// makes the initial reluctance l_c/(μ0·μ_i·A_c) equal to `r0`.
fn jiles_atherton(area: f64, r0: f64, b_sat: f64) -> JilesAtherton {
    // [JA Table 2]: μ0·M_sat = 1.822 T, b = 2.45 mT, c = 0.736, κ = 943 A/m, α = 3.66e-3.
    let m_sat = b_sat / MU0;
    let b = 2.45e-3 * b_sat / 1.822;
    let (c, kappa, alpha) = (0.736, 943.0, 3.66e-3);
    // Initial (anhysteretic, mean-field) relative permeability 1 + χ,
    // χ = χ_an / (1 − α·χ_an) with χ_an = μ0·M_sat/(3b).
    let chi_an = MU0 * m_sat / (3.0 * b);
    let chi = chi_an / (1.0 - alpha * chi_an).max(0.05);
    let length = r0 * MU0 * (1.0 + chi) * area;
    JilesAtherton {
        length,
        area,
        m_sat,
        b,
        c,
        kappa,
        alpha,
        epsilon: 1e-3,
        reversal: Reversal::Clamp,
    }
}
