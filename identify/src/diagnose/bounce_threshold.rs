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
//! So v_ε is tried at the geometric mean of each two neighbouring levels of
//! the fitted model's impact speeds (one replay each); the best is kept
//! where it lowers the current's error, and the fit runs again from there.
//! Scanned, that relay is named `bouncing + resistance-drift` at 1.16× the
//! floor.

use rayon::prelude::*;

use crate::description::Description;
use crate::em_fit::{replay, Setup};
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

/// `report` (a fit that fits the restitution of `params` on `data`), or its
/// fit again from the best bounce threshold where that is better.
pub(super) fn scanned(
    report: FitReport,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> FitReport {
    better_threshold(&report, data, params, options)
        .and_then(|start| {
            let once = FitOptions {
                starts: 1,
                also_from: Vec::new(),
                ..options.clone()
            };
            fit(&start, data, params, &once, &|_| {}).ok()
        })
        .filter(|refit| refit.wnrmse_current < report.wnrmse_current)
        .unwrap_or(report)
}

/// The fitted model with the threshold that lowers its current's error
/// most, if one does.
fn better_threshold(
    report: &FitReport,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> Option<Description> {
    let fitted = &report.description;
    let setup = Setup::new(fitted, data, params, options).ok()?;
    let run = replay(fitted, data, &setup.objective.budget).ok()?;
    let thresholds = between_levels(impact_speeds(&run.trajectory.events)?);
    let error = |d: &Description| {
        setup
            .objective
            .errors(d, data)
            .map_or(f64::INFINITY, |e| e.current)
    };
    let with_threshold = |v_eps: f64| {
        let mut d = fitted.clone();
        d.mechanics.bounce_threshold = v_eps;
        d
    };
    // in parallel, reduced in order: the same choice on any number of threads
    let tried: Vec<(f64, Description)> = (thresholds.par_iter())
        .map(|&v| {
            let d = with_threshold(v);
            (error(&d), d)
        })
        .collect();
    let own = error(fitted);
    let (best, d) =
        tried.into_iter().fold(
            None,
            |best: Option<(f64, Description)>, (e, d)| match best {
                Some((b, _)) if b <= e => best,
                _ => Some((e, d)),
            },
        )?;
    (best < own).then_some(d)
}

/// |v| before each impact where the model bounces at least once, sorted;
/// `None` where no impact bounces (nothing for the threshold to decide).
fn impact_speeds(events: &[crate::sim::Event]) -> Option<Vec<f64>> {
    let mut bounced = false;
    let mut speeds: Vec<f64> = events
        .iter()
        .filter_map(|e| match e.kind {
            EventKind::Impact {
                v_before, v_after, ..
            } => {
                bounced |= v_after != 0.0;
                Some(v_before.abs())
            }
            _ => None,
        })
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    speeds.sort_by(f64::total_cmp);
    bounced.then_some(speeds)
}

/// The geometric mean of each two neighbouring levels of `speeds` (sorted),
/// levels being runs of speeds within [`SAME_LEVEL`] of each other.
fn between_levels(speeds: Vec<f64>) -> Vec<f64> {
    let mut levels: Vec<f64> = Vec::new();
    for v in speeds {
        match levels.last() {
            Some(&last) if v <= SAME_LEVEL * last => {}
            _ => levels.push(v),
        }
    }
    levels.windows(2).map(|w| (w[0] * w[1]).sqrt()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_fall_between_the_levels_of_the_impact_speeds() {
        // two cycles of a bounce sequence at γ = 0.6, the second 2 % slower
        let cycle = [0.5, 0.3, 0.18, 0.108];
        let speeds: Vec<f64> = (cycle.iter().chain(cycle.iter()))
            .enumerate()
            .map(|(k, v)| if k < 4 { *v } else { 0.98 * v })
            .collect();
        let mut sorted = speeds.clone();
        sorted.sort_by(f64::total_cmp);
        let between = between_levels(sorted);
        assert_eq!(between.len(), 3, "{between:?}");
        for (t, w) in between.iter().zip([[0.108, 0.18], [0.18, 0.3], [0.3, 0.5]]) {
            assert!(*t > w[0] && *t < 0.98 * w[1], "{t} between {w:?}");
        }
    }

    #[test]
    fn no_bounce_nothing_to_scan() {
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
        assert_eq!(impact_speeds(&[impact(0.0)]), None);
        assert_eq!(
            impact_speeds(&[impact(0.2), impact(0.0)]),
            Some(vec![0.4, 0.4])
        );
    }
}
