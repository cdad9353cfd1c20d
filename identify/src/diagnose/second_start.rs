//! The hysteresis candidate's second start, from the fitted saturating
//! core: needed only where the own start does not beat that core by BIC.
//! `fit_all` spawns it as soon as the saturation fit ends (not after the
//! own start: the cores stay busy) and stops it as soon as the own start
//! beats the core; whether its result counts follows from the two BICs
//! alone, so the answer does not depend on which fit ended first. Where it
//! runs, it gives up early when it stays far above the core it started
//! from ([`giving_up`]): a rule on its own iterations, the same every run.

use crate::lm::{GiveUp, Stop};
use std::sync::Mutex;

use super::candidate::Candidate;

/// The second start is given up when, after this many iterations, …
pub(super) const GIVE_UP_AFTER: usize = 5;
/// … its objective is still more than this many times the saturating
/// core's it started from. (Measured on the benchmark's saturation record:
/// the second start ended 26–215 times above that core after 21–40
/// iterations, 1.9–2.6 s, the longest fit of the record.)
pub(super) const GIVE_UP_FACTOR: f64 = 10.0;

/// `seeded`, the start from a saturating core whose fit's objective (the
/// report's `cost`) is `saturation_cost`, with the give-up rule. (The two
/// objectives weigh the samples with the resistance each fit starts from:
/// close, against the factor of 10.) A start that gave up still counts as
/// the candidate's where its BIC is the better one: an upper bound of what
/// that start would reach.
pub(super) fn giving_up(seeded: Candidate, saturation_cost: f64) -> Candidate {
    Candidate {
        give_up: Some(GiveUp {
            after: GIVE_UP_AFTER,
            // the solver's ½‖r‖² is half the report's cost
            above: GIVE_UP_FACTOR * 0.5 * saturation_cost,
        }),
        ..seeded
    }
}

/// The BICs the second start depends on, each once fitted, and its stop.
#[derive(Debug, Default)]
pub(super) struct SecondStart {
    /// (own start, saturation fit)
    bics: Mutex<(Option<f64>, Option<f64>)>,
    pub stop: Stop,
}

impl SecondStart {
    /// Whether the own start's BIC does not beat the saturating core's (a
    /// failed own fit, BIC ∞ or NaN, does not).
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // deliberate: NaN is needed
    fn needed(own: f64, saturation: f64) -> bool {
        !(own < saturation)
    }

    /// The own start ended with `bic`: stops the second start if that is
    /// not needed.
    pub fn own_fitted(&self, bic: f64) {
        if let Ok(mut bics) = self.bics.lock() {
            bics.0 = Some(bic);
            if let (Some(own), Some(saturation)) = *bics {
                if !Self::needed(own, saturation) {
                    self.stop.raise();
                }
            }
        }
    }

    /// The saturation fit ended with `bic`: whether to spawn the second
    /// start (not where the own start has beaten it already).
    pub fn saturation_fitted(&self, bic: f64) -> bool {
        let Ok(mut bics) = self.bics.lock() else {
            return false;
        };
        bics.1 = Some(bic);
        bics.0.is_none_or(|own| Self::needed(own, bic))
    }

    /// Whether the second start's result counts, once every fit has ended.
    pub fn counts(&self) -> bool {
        match self.bics.lock().map(|b| *b) {
            Ok((Some(own), Some(saturation))) => Self::needed(own, saturation),
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (own BIC, saturation BIC, own ends first): spawned, stopped, counts.
    fn run(own: f64, saturation: f64, own_first: bool) -> (bool, bool, bool) {
        let s = SecondStart::default();
        let spawned = match own_first {
            true => {
                s.own_fitted(own);
                s.saturation_fitted(saturation)
            }
            false => {
                let spawned = s.saturation_fitted(saturation);
                s.own_fitted(own);
                spawned
            }
        };
        (spawned, s.stop.raised(), s.counts())
    }

    #[test]
    fn the_second_start_counts_where_the_own_start_does_not_beat_the_core() {
        // own beats the core: never spawned after it, stopped before it
        assert_eq!(run(-200.0, -100.0, true), (false, false, false));
        assert_eq!(run(-200.0, -100.0, false), (true, true, false));
        // own does not: spawned, never stopped, counts, in either order
        for own_first in [true, false] {
            assert_eq!(run(-100.0, -200.0, own_first), (true, false, true));
            assert_eq!(run(-100.0, -100.0, own_first), (true, false, true));
            assert_eq!(run(f64::INFINITY, -100.0, own_first), (true, false, true));
            assert_eq!(run(f64::NAN, -100.0, own_first), (true, false, true));
        }
    }

    /// `fit_all` with stub fits whose BICs are given and whose order is
    /// forced, on 4 threads (a stub waits for another fit).
    mod fit_all {
        use super::super::super::candidate::Candidate;
        use super::super::super::{fit_all, Cause, Scored};
        use crate::description::{parse_file, Core, Description};
        use crate::lm::{GiveUp, Status, Stop};
        use crate::{FitReport, Sensitivities, Sensitivity};
        use nalgebra::DMatrix;
        use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
        use std::time::{Duration, Instant};

        fn baseline() -> Description {
            let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/semera-valve.toml");
            parse_file(std::path::Path::new(path)).expect("the example parses")
        }

        fn scored(cause: Cause, bic: f64, description: Description) -> Scored {
            let names = ["coil.resistance".to_string()];
            let sensitivity =
                Sensitivity::from_jacobian(&names, &DMatrix::zeros(1, 1), &[1.0], &[0.0]);
            let report = FitReport {
                description,
                values: Vec::new(),
                wnrmse_current: 0.0,
                wnrmse_flux: None,
                nrmse_position: None,
                // an objective the second start's give-up rule can be checked by
                cost: bic.abs(),
                iterations: 0,
                simulations: 0,
                sensitivities: Sensitivities::Analytic,
                differenced_jacobians: 0,
                status: Status::CostConverged,
                best_start: 0,
                sensitivity,
            };
            Scored {
                cause,
                fit: Ok(report),
                parameters: 1,
                wnrmse_fit: 0.0,
                bic,
            }
        }

        fn wait_for(what: &str, done: impl Fn() -> bool) {
            let start = Instant::now();
            while !done() {
                assert!(start.elapsed() < Duration::from_secs(10), "never: {what}");
                std::thread::sleep(Duration::from_millis(1));
            }
        }

        /// How a stubbed run went.
        struct Run {
            /// The hysteresis candidate's BIC in the ranking.
            hysteresis: f64,
            seeded_calls: usize,
            stopped: bool,
        }

        /// BICs of the own start, the saturation fit and the second start;
        /// `own_waits_for_seeded`: the own fit ends only once the second
        /// start runs (else the saturation fit ends only after the own).
        fn run(own: f64, saturation: f64, seeded: f64, own_waits_for_seeded: bool) -> Run {
            let base = baseline();
            let mut saturated = base.clone();
            saturated.core = Core::Saturating {
                r0: 3.25e6,
                phi_sat: 2e-5,
            };
            let candidate = |cause| Candidate {
                cause,
                start: base.clone(),
                params: Vec::new(),
                starts: 1,
                give_up: None,
            };
            let (own_done, seeded_calls, stopped) = (
                AtomicBool::new(false),
                AtomicUsize::new(0),
                AtomicBool::new(false),
            );
            let fit = |c: &Candidate, stop: Option<&Stop>| match (c.cause, stop) {
                (Cause::Hysteresis, None) => {
                    if own_waits_for_seeded {
                        wait_for("the second start", || {
                            seeded_calls.load(Ordering::SeqCst) > 0
                        });
                    }
                    own_done.store(true, Ordering::SeqCst);
                    scored(Cause::Hysteresis, own, c.start.clone())
                }
                (Cause::Hysteresis, Some(stop)) => {
                    // given up above 10× the saturating core's objective after 5 iterations
                    let give_up = GiveUp {
                        after: 5,
                        above: 5.0 * saturation.abs(),
                    };
                    assert_eq!(c.give_up, Some(give_up));
                    seeded_calls.fetch_add(1, Ordering::SeqCst);
                    if own >= saturation {
                        // needed: runs to its end
                        stopped.store(stop.raised(), Ordering::SeqCst);
                    } else {
                        wait_for("the stop", || stop.raised());
                        stopped.store(true, Ordering::SeqCst);
                    }
                    scored(Cause::Hysteresis, seeded, c.start.clone())
                }
                _ => {
                    if !own_waits_for_seeded {
                        wait_for("the own start", || own_done.load(Ordering::SeqCst));
                    }
                    scored(c.cause, saturation, saturated.clone())
                }
            };
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(4)
                .build()
                .unwrap();
            let ranking = pool.install(|| {
                fit_all(
                    &base,
                    &[candidate(Cause::Saturation)],
                    Some(&candidate(Cause::Hysteresis)),
                    &fit,
                )
            });
            let hysteresis = ranking
                .iter()
                .find(|s| s.cause == Cause::Hysteresis)
                .map(|s| s.bic)
                .expect("the hysteresis candidate is ranked");
            Run {
                hysteresis,
                seeded_calls: seeded_calls.into_inner(),
                stopped: stopped.into_inner(),
            }
        }

        #[test]
        fn a_second_start_the_own_start_makes_needless_is_stopped_and_dropped() {
            // spawned before the own start ends, better than it, yet dropped
            let r = run(-200.0, -100.0, -300.0, true);
            assert_eq!((r.hysteresis, r.seeded_calls, r.stopped), (-200.0, 1, true));
            // the own start first: whether spawned or not, dropped
            let r = run(-200.0, -100.0, -300.0, false);
            assert_eq!(r.hysteresis, -200.0);
        }

        #[test]
        fn a_needed_second_start_runs_to_its_end_and_the_better_start_counts() {
            for own_waits_for_seeded in [true, false] {
                let r = run(-100.0, -200.0, -300.0, own_waits_for_seeded);
                assert_eq!(
                    (r.hysteresis, r.seeded_calls, r.stopped),
                    (-300.0, 1, false)
                );
                let r = run(-100.0, -200.0, -50.0, own_waits_for_seeded);
                assert_eq!(
                    (r.hysteresis, r.seeded_calls, r.stopped),
                    (-100.0, 1, false)
                );
            }
        }
    }

    #[test]
    fn without_a_saturation_fit_there_is_no_second_start() {
        let s = SecondStart::default();
        s.own_fitted(f64::INFINITY);
        assert!(!s.counts() && !s.stop.raised());
    }
}
