//! The bounce threshold v_ε (`mechanics.bounce_threshold`) of a fit that
//! fits the restitution γ, by a scan after it.
//!
//! An impact slower than v_ε sticks, a faster one bounces back at γ·v: the
//! current's error is a step function of v_ε, with steps where v_ε crosses
//! one of the model's own impact speeds, and no gradient for the fit, which
//! fits γ (and what the step refits) with the description's v_ε held. On a
//! warming relay of the blind classes (seed 4) γ and the drift came out
//! within 0.1 % of the truth and the record was still left at 3.84× the
//! noise floor: with the description's v_ε of 1 mm/s the model bounced on
//! where the relay, whose v_ε is 47 mm/s, sticks (the truth's own values
//! with v_ε anywhere between its last two bounce speeds, 39 and 63 mm/s,
//! leave 1.00×; 0–10 mm/s, 2.5×; 70 mm/s, 3.8×).
//!
//! So after every ranking fit that fits γ, v_ε is tried at 0 and between each
//! two neighbouring levels of the fitted model's impact speeds (one replay
//! each); the best is kept where it lowers the current's error [JA 81], the
//! fit runs again from there, and the candidate counts v_ε as one more
//! parameter in its BIC.
//! Scanned, that relay is named `bouncing + resistance-drift` at 1.16× the
//! floor.

use rayon::prelude::*;

use crate::description::Description;
use crate::em_fit::{outputs, replay, Setup};
use crate::sim::EventKind;
use crate::{fit, FitOptions, FitParam, FitReport, Measured};

/// Impact speeds closer than this ratio are one level (the same bounce of
/// successive cycles).
const SAME_LEVEL: f64 = 1.05;

/// Whether a fit of `params` fits the restitution: the bouncing candidate,
/// and a later step's candidate that refits it (`earlier_parameters`),
/// where the other cause is modelled too (on the warming relay the scan
/// after the bouncing candidate's own fit gains nothing: the drift left
/// out dominates its error).
pub(super) fn fits_restitution(params: &[FitParam]) -> bool {
    params.iter().any(|p| p.path == RESTITUTION)
}

const RESTITUTION: &str = "mechanics.restitution";

/// `report` (a ranking fit of `params` on `data` from `start`, that fits
/// the restitution), or, where the best bounce threshold lowers its error,
/// the better of its fit again from there and the scanned threshold alone
/// (a refit that fails or gains nothing does not drop it); whether v_ε
/// moved (it is then one more parameter). A moved v_ε is stated in the
/// report's `scanned_threshold`.
///
/// Every error here is measured as the ranking measures `report`'s: [JA 81]
/// with the |φ̇| weights of `start`'s resistance, so that the refit's error
/// stands beside the other candidates'.
pub(super) fn scanned(
    report: FitReport,
    start: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> (FitReport, bool) {
    let Ok(setup) = Setup::new(start, data, params, options) else {
        return (report, false);
    };
    let Some(scan) = better_threshold(&report.description, &setup, data) else {
        return (report, false);
    };
    // a report with its errors replayed, the scan stated, and the replay's
    // cost (the sum of its squared residuals)
    let measured = |mut r: FitReport| {
        let d = &r.description;
        let out = outputs(d, &replay(d, data, &setup.objective.budget).ok()?);
        let errors = setup.objective.errors_of(d, &out);
        let cost = (setup.objective.residuals_of(d, &out).iter())
            .map(|e| e * e)
            .sum();
        r.wnrmse_current = errors.current;
        r.wnrmse_flux = errors.flux;
        r.nrmse_position = errors.position;
        r.scanned_threshold = Some(scan.interval);
        Some((r, cost))
    };
    let once = FitOptions {
        starts: 1,
        also_from: Vec::new(),
        ..options.clone()
    };
    let refit = fit(&scan.description, data, params, &once, &|_| {})
        .ok()
        .and_then(|mut refit| {
            refit.iterations += report.iterations;
            refit.simulations += report.simulations;
            measured(refit).map(|(refit, _)| refit)
        });
    // the fitted values with the scanned threshold: its cost replayed too
    // (a give-up bar downstream), its sensitivity the fit's at the
    // threshold before
    let held = measured(FitReport {
        description: scan.description.clone(),
        ..report.clone()
    })
    .map(|(held, cost)| FitReport { cost, ..held });
    let best = [refit, held]
        .into_iter()
        .flatten()
        .min_by(|a, b| a.wnrmse_current.total_cmp(&b.wnrmse_current));
    match best {
        Some(best) if best.wnrmse_current < report.wnrmse_current => (best, true),
        _ => (report, false),
    }
}

/// A bounce threshold the scan chose: the fitted description with it, and
/// the interval of thresholds that give the same replay of that description
/// (a refit from it may move its impacts a little).
struct Scan {
    description: Description,
    interval: [f64; 2],
}

/// `fitted` with the threshold that lowers its current's error most, if
/// one does.
fn better_threshold(fitted: &Description, setup: &Setup, data: &Measured) -> Option<Scan> {
    let run = replay(fitted, data, &setup.objective.budget).ok()?;
    let own = setup
        .objective
        .errors_of(fitted, &outputs(fitted, &run))
        .current;
    let thresholds = candidates(impact_speeds(&run.trajectory.events)?);
    let with_threshold = |v_eps: f64| {
        let mut d = fitted.clone();
        d.mechanics.bounce_threshold = v_eps;
        d
    };
    // in parallel, collected in order: the same choice on any number of threads
    let tried: Vec<(f64, Threshold)> = (thresholds.par_iter())
        .map(|t| {
            let e = setup.objective.errors(&with_threshold(t.value), data);
            (e.map_or(f64::INFINITY, |e| e.current), *t)
        })
        .collect();
    // the first of equal errors
    let (best, t) = (tried.into_iter())
        .filter(|(e, _)| e.is_finite())
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    (best < own).then(|| Scan {
        description: with_threshold(t.value),
        interval: t.interval,
    })
}

/// `fit`, stating the scan of `earlier` (the same step's fit before a
/// polish or a joint fit, which hold v_ε where the scan put it) where its
/// own fit scanned nothing.
pub(super) fn keeping_scan(fit: FitReport, earlier: Option<&FitReport>) -> FitReport {
    FitReport {
        scanned_threshold: (fit.scanned_threshold).or(earlier.and_then(|f| f.scanned_threshold)),
        ..fit
    }
}

/// |v| before each impact of the replay, sorted (`None` without impacts).
fn impact_speeds(events: &[crate::sim::Event]) -> Option<Vec<f64>> {
    let mut speeds: Vec<f64> = events
        .iter()
        .filter_map(|e| match e.kind {
            EventKind::Impact { v_before, .. } => Some(v_before.abs()),
            _ => None,
        })
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    speeds.sort_by(f64::total_cmp);
    (!speeds.is_empty()).then_some(speeds)
}

/// One threshold to try, and the interval of thresholds that replay the
/// same as it (every impact of the model on the same side of v_ε).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Threshold {
    value: f64,
    interval: [f64; 2],
}

/// The thresholds to try for impacts at `speeds` (sorted): 0 (every impact
/// bounces: where the model's v_ε is above all of them, γ has no effect),
/// and between each two neighbouring levels, √(fastest of the slower
/// level · slowest of the faster), levels being runs of speeds within
/// [`SAME_LEVEL`] of their neighbour.
fn candidates(speeds: Vec<f64>) -> Vec<Threshold> {
    // (slowest, fastest) of each level
    let mut levels: Vec<(f64, f64)> = Vec::new();
    for v in speeds {
        match levels.last_mut() {
            Some((_, fastest)) if v <= SAME_LEVEL * *fastest => *fastest = v,
            _ => levels.push((v, v)),
        }
    }
    let slowest = levels.first().map_or(0.0, |l| l.0);
    let between = levels.windows(2).map(|w| Threshold {
        value: (w[0].1 * w[1].0).sqrt(),
        interval: [w[0].1, w[1].0],
    });
    std::iter::once(Threshold {
        value: 0.0,
        interval: [0.0, slowest],
    })
    .chain(between)
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_fall_between_the_levels_of_the_impact_speeds() {
        // two cycles of a bounce sequence at γ = 0.6, the second 2 % slower
        let cycle = [0.5, 0.3, 0.18, 0.108];
        let mut speeds: Vec<f64> = (cycle.iter().chain(cycle.iter()))
            .enumerate()
            .map(|(k, v)| if k < 4 { *v } else { 0.98 * v })
            .collect();
        speeds.sort_by(f64::total_cmp);
        let tried = candidates(speeds);
        assert_eq!(tried.len(), 4, "{tried:?}");
        assert_eq!(tried[0].value, 0.0);
        assert_eq!(tried[0].interval, [0.0, 0.98 * 0.108]);
        for (t, w) in tried[1..]
            .iter()
            .zip([[0.108, 0.18], [0.18, 0.3], [0.3, 0.5]])
        {
            assert!(
                t.value > w[0] && t.value < 0.98 * w[1],
                "{t:?} between {w:?}"
            );
            // the interval: from the slower level's fastest to the faster's slowest
            assert_eq!(t.interval, [w[0], 0.98 * w[1]], "{t:?}");
        }
    }

    #[test]
    fn a_level_stands_for_all_its_speeds() {
        // a level spread over 5–10 % (a warming coil's cycles): the point
        // tried lies above its fastest speed, not inside it
        let tried = candidates(vec![0.100, 0.104, 0.108, 0.2]);
        assert!(tried[1].value > 0.108 && tried[1].value < 0.2, "{tried:?}");
        assert_eq!(tried[1].interval, [0.108, 0.2]);
    }

    #[test]
    fn no_impact_nothing_to_scan() {
        use crate::sim::{Event, Limit, Mode};
        let impact = |v_after| Event {
            t: 0.0,
            kind: EventKind::Impact {
                limit: Limit::Min,
                v_before: -0.4,
                v_after,
                zeno: false,
            },
            mode_after: Mode::Free,
        };
        assert_eq!(impact_speeds(&[]), None);
        assert_eq!(impact_speeds(&[impact(0.0)]), Some(vec![0.4]));
        assert_eq!(
            impact_speeds(&[impact(0.2), impact(0.0)]),
            Some(vec![0.4, 0.4])
        );
    }
}
