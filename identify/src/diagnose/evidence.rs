//! What a record shows of a cause: whether it contains what the effect
//! needs to show (a λ–i loop, motion, an impact), and whether the fitted
//! effect parameter stands clear of its null value, or, for a cause whose
//! null is another model (a Jiles–Atherton core, fringing), whether its
//! effect stands clear of zero on the held-out end. A cause is named only
//! where both hold; the report says, per named cause, why it is identified.

use super::{impacts, peak_abs, Cause, Diagnosis, FittedParameter};
use crate::description::{Core, Description};
use crate::{FitReport, Measured, SimOutputs};

/// How often the flux turns (φ̇ changes sign) while |φ| is above 10 % of its
/// peak: a hysteresis loop shows only where the flux reverses at non-zero
/// flux. Counted on the baseline's replay (noise-free), turns closer than 1 %
/// of the peak to the last extremum ignored.
fn flux_reversals(phi: &[f64]) -> usize {
    let peak = peak_abs(phi);
    let Some(&first) = phi.first() else {
        return 0;
    };
    if !(peak > 0.0) {
        return 0;
    }
    let tol = 0.01 * peak;
    let (mut turns, mut direction, mut extreme) = (0, 0i8, first);
    for &p in phi {
        let turned = match direction {
            0 => {
                if (p - extreme).abs() >= tol {
                    direction = if p > extreme { 1 } else { -1 };
                    extreme = p;
                }
                false
            }
            1 if p > extreme => {
                extreme = p;
                false
            }
            -1 if p < extreme => {
                extreme = p;
                false
            }
            _ => (p - extreme).abs() >= tol,
        };
        if turned {
            if extreme.abs() > 0.1 * peak {
                turns += 1;
            }
            direction = -direction;
            extreme = p;
        }
    }
    turns
}

/// Fraction of the stroke the armature must cover for the gap to be seen at
/// more than one length.
const MOTION_FRACTION: f64 = 0.1;

/// What the record must contain for `cause` to show, if it lacks it
/// (decided from the data's own signals where it has them, else from the
/// baseline's replay of them): a hysteresis needs flux reversals at non-zero
/// flux (a λ–i loop), fringing a gap seen at several lengths (motion), a
/// bounce an impact.
pub(super) fn record_lacks(
    cause: Cause,
    replay: &SimOutputs,
    data: &Measured,
    baseline: &Description,
) -> Option<String> {
    let m = &baseline.mechanics;
    let stroke = m.z_max - m.z_min;
    let z = data.z.as_deref().unwrap_or(&replay.z);
    match cause {
        Cause::Hysteresis if flux_reversals(&replay.phi) == 0 => Some(
            "the record's flux never reverses at non-zero flux: there is no λ–i loop to tell a \
             hysteretic core from a single-valued one"
                .to_string(),
        ),
        Cause::Fringing if span(z) < MOTION_FRACTION * stroke => Some(format!(
            "the armature moves over {:.1} % of the stroke only: the gap is seen at one length, \
             where fringing is a change of the linear gap",
            100.0 * span(z) / stroke
        )),
        Cause::Bouncing if impacts(replay, m.z_min, m.z_max).is_empty() => Some(
            "the armature reaches no stop in the record: there is no impact to bounce".to_string(),
        ),
        _ => None,
    }
}

/// max − min of the finite values.
fn span(x: &[f64]) -> f64 {
    let (lo, hi) = x
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi >= lo {
        hi - lo
    } else {
        0.0
    }
}

/// The parameter whose null value means "no such effect", per cause: a loop
/// width κ = 0 is no hysteresis, k_e = 0 no eddy currents, dR/dt = 0 no drift,
/// γ = 0 no bounce, 1/φ_sat = 0 no saturation (same relative error as φ_sat).
pub fn effect_parameter(cause: Cause) -> Option<&'static str> {
    match cause {
        Cause::Hysteresis => Some("core.kappa"),
        Cause::EddyCurrents => Some("coil.eddy"),
        Cause::ResistanceDrift => Some("coil.resistance_drift"),
        Cause::Bouncing => Some("mechanics.restitution"),
        Cause::Saturation => Some("core.phi_sat"),
        Cause::Fringing | Cause::None | Cause::Unexplained => None,
    }
}

/// Standard errors within which the effect parameter must stay clear of its
/// null value (≈ a 95 % confidence interval).
pub const IDENTIFIED_Z: f64 = 2.0;

/// Why the record does not identify `cause`'s effect, if it does not: the
/// effect parameter lies within `IDENTIFIED_Z` standard errors of its null
/// value (linearised at the optimum, from the fit's Jacobian).
pub(super) fn unidentified(cause: Cause, fit: &FitReport) -> Option<String> {
    let key = effect_parameter(cause)?;
    let j = fit.values.iter().position(|(k, _)| k == key)?;
    let value = fit.values[j].1;
    let rel = fit.sensitivity.relative_std_errors.get(j).copied()?;
    if rel.is_finite() && IDENTIFIED_Z * rel < 1.0 {
        return None;
    }
    let null = if cause == Cause::Saturation {
        "φ_sat = ∞ (no saturation)"
    } else {
        "0 (no such effect)"
    };
    Some(format!(
        "{key} = {value:.4e} ± {:.2e}: its {IDENTIFIED_Z}-standard-error interval holds {null}",
        value.abs() * rel
    ))
}

/// Whether `cause`'s "no such effect" on `baseline` is another model rather
/// than a value of its parameters. Fringing has no parameter whose value
/// removes it. A Jiles–Atherton core with κ → 0 is a single-valued
/// (anhysteretic) core: the null of a description whose core is linear,
/// where a saturating core fits as well (κ's distance from 0 then tells a
/// loop from a saturation); but κ → 0 does not turn it into a description's
/// saturating core. Such a cause is identified by its effect on data its fit
/// did not see ([`held_out_effect`]), not by a parameter's distance from a
/// null.
pub fn null_is_another_model(cause: Cause, baseline: &Description) -> bool {
    match cause {
        Cause::Fringing => true,
        Cause::Hysteresis => !matches!(baseline.core, Core::Linear { .. }),
        _ => false,
    }
}

/// By how much the extended model beats the baseline on the held-out
/// samples, in BIC units: n·ln(e_b²/e_x²) − p·ln n with e the |φ̇|-weighted
/// errors there, p the extension's `parameters` and n the held-out
/// samples' effective count over the integrated autocorrelation time of the
/// extended model's residual (a correlated residual counts as fewer
/// independent samples). The likelihood ratio of the ranking, on data no fit
/// saw: positive where the extension is worth its parameters there.
///
/// `None` where the end cannot decide it: where even a model at the noise
/// `floor` would not be worth its parameters over those n samples (an end
/// that shows the baseline's miss at little more than the noise, measured
/// on the SEMERA fringing records of the examples' matrix: 1.4–2× the floor,
/// n = 4–7 against 4 parameters).
pub fn held_out_effect(
    baseline: &[f64],
    extended: &[f64],
    measured: &[f64],
    weights: &[f64],
    parameters: usize,
    floor: f64,
) -> Option<f64> {
    let error = |model: &[f64]| crate::wnrmse(model, measured, weights);
    let residual: Vec<f64> = (extended.iter().zip(measured).zip(weights))
        .map(|((x, m), w)| w.sqrt() * (x - m))
        .collect();
    let tau = super::integrated_autocorrelation(&residual).max(1.0);
    let n = super::rank::effective_samples(weights) / tau;
    let bic = super::rank::bic;
    let baseline_bic = bic(error(baseline), 0, n);
    let power = baseline_bic - bic(floor, parameters, n);
    (power > 0.0).then(|| baseline_bic - bic(error(extended), parameters, n))
}

/// Why the held-out end does not identify `cause`, if it does not: its
/// model is not worth its parameters there ([`held_out_effect`]).
pub(super) fn effect_unseen(cause: Cause, evidence: f64) -> Option<String> {
    (!(evidence > 0.0)).then(|| {
        format!(
            "on the held-out end the {cause} model is not worth its parameters ({evidence:.1} \
             BIC units; the residual's correlation counted)"
        )
    })
}

/// Why the record identifies the cause `step` named: what the record shows
/// of the effect, and how far its effect parameter stands from its null
/// value in the standard errors of `parameters` (the reported ones).
pub fn why_identified(
    step: &Diagnosis,
    parameters: &[FittedParameter],
    data: &Measured,
    baseline: &Description,
) -> String {
    let shows = record_shows(step, data, baseline);
    match effect_clearance(step.cause, parameters) {
        Some(clear) => format!("{shows}; {clear}"),
        None => shows,
    }
}

/// Whether the reported values still identify `cause`: its effect parameter
/// more than [`IDENTIFIED_Z`] standard errors from "no effect" (None: the
/// cause has no such parameter, e.g. fringing, or it is not reported). The
/// ranking checked the same on its fit; the values reported come after the
/// polish and the joint fit, with widened standard errors.
pub fn identified(cause: Cause, parameters: &[FittedParameter]) -> Option<bool> {
    let key = effect_parameter(cause)?;
    let p = parameters.iter().find(|p| p.path == key)?;
    Some(p.value.abs() > IDENTIFIED_Z * p.std_error)
}

/// What the record shows of `step.cause`'s effect.
fn record_shows(step: &Diagnosis, data: &Measured, baseline: &Description) -> String {
    let replay = &step.baseline_replay;
    let m = &baseline.mechanics;
    let z = data.z.as_deref().unwrap_or(&replay.z);
    let stroke = (m.z_max - m.z_min).max(f64::MIN_POSITIVE);
    match step.cause {
        Cause::Hysteresis => format!(
            "the flux reverses at non-zero flux {} times (a λ–i loop)",
            flux_reversals(&replay.phi)
        ),
        Cause::Fringing => format!(
            "the armature moves over {:.0} % of the stroke (the gap is seen at every length)",
            100.0 * span(z) / stroke
        ),
        Cause::Bouncing => format!(
            "the armature reaches a stop {} times",
            impacts(replay, m.z_min, m.z_max).len()
        ),
        Cause::EddyCurrents => format!(
            "{} voltage steps, each followed by the current's transient",
            if step.edges.is_empty() {
                voltage_steps(&data.v)
            } else {
                step.edges.len()
            }
        ),
        Cause::Saturation => match step.extended.core {
            Core::Saturating { phi_sat, .. } => format!(
                "the flux reaches {:.0} % of the fitted φ_sat",
                100.0 * peak_abs(&step.extended_replay.phi) / phi_sat
            ),
            _ => "the flux reaches the core's saturation".to_owned(),
        },
        Cause::ResistanceDrift => format!(
            "the record lasts {:.3} s over {} voltage steps (the current's level from step to step)",
            data.t.last().copied().unwrap_or(0.0) - data.t.first().copied().unwrap_or(0.0),
            voltage_steps(&data.v)
        ),
        Cause::None | Cause::Unexplained => String::new(),
    }
}

/// Steps of the voltage larger than half its range between two samples.
fn voltage_steps(v: &[f64]) -> usize {
    let range = span(v);
    v.windows(2)
        .filter(|w| (w[1] - w[0]).abs() > 0.5 * range)
        .count()
}

/// How many standard errors the effect parameter stands from "no such
/// effect" (None where the cause has no such parameter, or it is not
/// among `parameters`).
fn effect_clearance(cause: Cause, parameters: &[FittedParameter]) -> Option<String> {
    let key = effect_parameter(cause)?;
    let p = parameters.iter().find(|p| p.path == key)?;
    if !(p.std_error > 0.0) {
        return None;
    }
    // 1/φ_sat = 0 is no saturation: the same relative error as φ_sat
    let distance = p.value.abs() / p.std_error;
    let null = if cause == Cause::Saturation {
        "∞ (no saturation)"
    } else {
        "0 (no such effect)"
    };
    Some(format!(
        "{key} = {:.4e} ± {:.2e} stands {distance:.0} standard errors from {null}",
        p.value, p.std_error
    ))
}

#[cfg(test)]
mod reversal_tests {
    use super::flux_reversals;

    #[test]
    fn reversals_count_turns_at_non_zero_flux_only() {
        let step: Vec<f64> = (0..100).map(|k| 1.0 - (-(k as f64) / 10.0).exp()).collect();
        assert_eq!(flux_reversals(&step), 0, "a step response never turns");
        // a triangle wave between 0 and 1: turns at 1 count, turns at 0 do not
        let triangle: Vec<f64> = (0..400)
            .map(|k| {
                let x = (k % 100) as f64 / 100.0;
                if (k / 100) % 2 == 0 {
                    x
                } else {
                    1.0 - x
                }
            })
            .collect();
        assert_eq!(
            flux_reversals(&triangle),
            2,
            "two turns at the top, none at zero flux"
        );
        // a triangle between −1 and 1 turns at non-zero flux every time
        let bipolar: Vec<f64> = triangle.iter().map(|x| 2.0 * x - 1.0).collect();
        assert_eq!(flux_reversals(&bipolar), 3);
        assert_eq!(flux_reversals(&[]), 0);
    }
}
