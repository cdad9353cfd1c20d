//! The ranking's fits, in two waves.
//!
//! 1. The first wave fits every candidate that is fitted in one stage (the
//!    hysteresis candidate's own start, `none`, eddy currents, a drifting
//!    resistance) and the saturating core, and races the other candidates'
//!    starts on the record's first pulses ([`crate::staged_fit::race`]). In
//!    a later step every candidate but the hysteresis one also starts from
//!    the earlier causes' own starting points, and is raced too.
//! 2. Once every fit of the first wave has ended, the second fits each
//!    race's winner on the whole record, given up ([`GiveUp`]) where after
//!    [`GIVE_UP_AFTER`] iterations its objective is still
//!    [`GIVE_UP_FACTOR`] times the first wave's best.
//!
//! Beside them, the hysteresis candidate is fitted from the fitted
//! saturating core too, where its own start does not beat that core
//! ([`SecondStart`], [`Waves::seed_second`]).
//!
//! Why: a wrong model's fit on the whole record crawls (Gauss–Newton on a
//! large residual converges linearly). Fringing on the hysteresis
//! benchmark record ran its 40 iterations (0.75 s) to an objective 130
//! times the Jiles–Atherton fit's, gaining 0.02 % an iteration. A fit given
//! up counts with the BIC it reached, an upper bound of its own. The
//! winner starts again from its own start point (the one-stage fit's, see
//! `staged_fit`), so the rule is measured, not a bound: a true cause whose
//! start is far off could in principle stay 10 times above after 5
//! iterations; on every matrix (diagnose, confusion, both outside the
//! vocabulary, self-consistency) every answer and value is the same.
//!
//! The give-up rule depends on the first wave's results alone, not on which
//! fit ended first; the second start counts by the two BICs alone. So the
//! same record gives the same answer, bit for bit, on any number of threads.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use super::candidate::{self, Candidate};
use super::second_start::{self, SecondStart, GIVE_UP_AFTER, GIVE_UP_FACTOR};
use super::{Cause, Scored};
use crate::description::Description;
use crate::lm::{GiveUp, Stop};
use crate::{FitError, FitReport};

/// A race's result (None: the candidate is fitted in one stage).
pub(super) type Race = Option<Result<FitReport, FitError>>;

/// How the ranking fits a candidate.
pub(super) struct Fits<'a> {
    /// The first stage: its starts raced on the first pulses.
    pub race: &'a (dyn Fn(&Candidate) -> Race + Sync),
    /// The candidate's fit after its race, stopped by the flag where one is
    /// given.
    pub fit: &'a (dyn Fn(&Candidate, Race, Option<&Stop>) -> Scored + Sync),
}

/// Every candidate of `others` fitted and scored, and the hysteresis
/// candidate (`hysteresis`) from its own start and, where that does not
/// beat the fitted saturating core by BIC, from that core too (the
/// saturation fit finds the flux scale reliably, the Jiles–Atherton
/// objective has local minima); the better hysteresis start is kept (the
/// own one on a tie). The order of the result is not meaningful.
pub(super) fn fit_all(
    baseline: &Description,
    others: &[Candidate],
    hysteresis: Option<&Candidate>,
    fits: &Fits,
) -> Vec<Scored> {
    let waves = Waves {
        baseline,
        others,
        hysteresis: hysteresis.is_some(),
        fits,
        first_left: AtomicUsize::new(others.len() + usize::from(hysteresis.is_some())),
        others_left: AtomicUsize::new(others.len()),
        held: Mutex::new(Held::default()),
        scored: Mutex::new(Vec::new()),
        raced: Mutex::new(Vec::new()),
        starts: Mutex::new(Vec::new()),
        second: SecondStart::default(),
    };
    // The order of the spawns: rayon runs a scope's spawns last-first on
    // the spawning thread and first-first on a thread that steals them. So
    // the saturation fit goes first (stolen at once: the second start
    // depends on it), the own hysteresis start last (run at once here), and
    // the others between by their number of starts × parameters, cheapest
    // first: the costliest run here next, while the other threads take the
    // cheap ones.
    let mut order: Vec<usize> = (0..others.len()).collect();
    order.sort_by_key(|&k| {
        let c = &others[k];
        (c.cause != Cause::Saturation, c.starts * c.params.len())
    });
    rayon::scope(|s| {
        let waves = &waves;
        for k in order {
            s.spawn(move |s| waves.first(s, k));
        }
        if let Some(own) = hysteresis {
            s.spawn(move |s| waves.own(s, own));
        }
    });
    let mut scored = waves.scored.into_inner().unwrap_or_default();
    scored.sort_by_key(|(k, _)| *k);
    let mut ranking: Vec<Scored> = scored.into_iter().map(|(_, s)| s).collect();
    let mut starts = waves.starts.into_inner().unwrap_or_default();
    starts.retain(|(k, _)| *k == 0 || waves.second.counts());
    starts.sort_by_key(|(k, _)| *k);
    let best = (starts.into_iter().map(|(_, s)| s)).reduce(|best, s| {
        match s.bic.total_cmp(&best.bic).is_lt() {
            true => s,
            false => best,
        }
    });
    ranking.extend(best);
    ranking
}

/// The ranking's fits as they end.
struct Waves<'a> {
    baseline: &'a Description,
    others: &'a [Candidate],
    /// Whether there is a hysteresis candidate.
    hysteresis: bool,
    fits: &'a Fits<'a>,
    /// Fits of the first wave not ended yet, …
    first_left: AtomicUsize,
    /// … of them of `others`.
    others_left: AtomicUsize,
    /// The second start while it waits ([`Waves::seed_second`]).
    held: Mutex<Held>,
    /// (index in `others`, fit)
    scored: Mutex<Vec<(usize, Scored)>>,
    /// The first wave's races, waiting for the second.
    raced: Mutex<Vec<(usize, Race)>>,
    /// The hysteresis candidate's starts: (0, own), (1, from the core).
    starts: Mutex<Vec<(usize, Scored)>>,
    second: SecondStart,
}

impl<'a> Waves<'a> {
    /// Candidate `k`'s first wave: fitted (one stage, or the saturating
    /// core), or raced.
    fn first(&'a self, s: &rayon::Scope<'a>, k: usize) {
        let c = &self.others[k];
        match (self.fits.race)(c) {
            Some(race) if c.cause != Cause::Saturation => push(&self.raced, (k, Some(race))),
            race => {
                let result = (self.fits.fit)(c, race, None);
                if c.cause == Cause::Saturation {
                    self.seed_second(s, &result);
                }
                push(&self.scored, (k, result));
            }
        }
        if self.others_left.fetch_sub(1, Ordering::SeqCst) == 1 {
            // the own start still runs (else it took the second start):
            // the second start now, stopped if the own start beats the core
            let held = self.held.lock().ok().and_then(|mut h| h.seeded.take());
            if let Some(seeded) = held {
                self.spawn_second(s, seeded);
            }
        }
        self.first_ended(s);
    }

    /// The hysteresis candidate's own start.
    fn own(&'a self, s: &rayon::Scope<'a>, own: &Candidate) {
        let result = (self.fits.fit)(own, None, None);
        self.second.own_fitted(result.bic);
        push(&self.starts, (0, result));
        let held = self.held.lock().ok().and_then(|mut h| {
            h.own_ended = true;
            h.seeded.take()
        });
        if let Some(seeded) = held.filter(|_| self.second.counts()) {
            self.spawn_second(s, seeded);
        }
        self.first_ended(s);
    }

    /// A first-wave fit ended; after the last, the second wave.
    fn first_ended(&'a self, s: &rayon::Scope<'a>) {
        if self.first_left.fetch_sub(1, Ordering::SeqCst) != 1 {
            return;
        }
        let best_cost = self.first_best_cost();
        let mut raced = take(&self.raced);
        raced.sort_by_key(|(k, _)| (self.others[*k].starts * self.others[*k].params.len(), *k));
        for (k, race) in raced {
            s.spawn(move |_| {
                let c = giving_up(&self.others[k], best_cost);
                push(&self.scored, (k, (self.fits.fit)(&c, race, None)));
            });
        }
    }

    /// The first wave's best objective (the report's cost): every fit of
    /// `others` kept so far, which once the first wave has ended are its
    /// fits, and the own hysteresis start (not the second start, which may
    /// or may not have ended).
    fn first_best_cost(&self) -> f64 {
        let best = |fits: &Mutex<Vec<(usize, Scored)>>, own_only: bool| {
            let fits = fits.lock();
            let kept = fits.iter().flat_map(|v| v.iter());
            let first = kept.filter(|(k, _)| !own_only || *k == 0);
            let costs = first.filter_map(|(_, s)| s.fit.as_ref().ok().map(|r| r.cost));
            costs.fold(f64::INFINITY, f64::min)
        };
        best(&self.scored, false).min(best(&self.starts, true))
    }

    /// The second start from the fitted saturating core, where the own
    /// start has not beaten the core already: spawned at once where the own
    /// start has ended, else held until it ends (and spawned if needed) or
    /// until every other fit of the first wave has ended (spawned then, and
    /// stopped if the own start beats the core: the thread would idle).
    /// Spawned at once, it took a core from the first wave's other fits,
    /// only to be stopped on the hysteresis benchmark record (0.24 s).
    fn seed_second(&'a self, s: &rayon::Scope<'a>, saturation: &Scored) {
        let seeded = (self.hysteresis)
            .then(|| saturation.fit.as_ref().ok())
            .flatten()
            .and_then(|f| {
                let seeded = candidate::hysteresis_from_saturation(self.baseline, &f.description);
                seeded.map(|c| second_start::giving_up(c, f.cost))
            })
            .filter(|_| self.second.saturation_fitted(saturation.bic));
        let now = seeded.and_then(|seeded| {
            let mut held = self.held.lock().ok()?;
            match held.own_ended {
                true => Some(seeded),
                false => {
                    held.seeded = Some(seeded);
                    None
                }
            }
        });
        if let Some(seeded) = now {
            self.spawn_second(s, seeded);
        }
    }

    fn spawn_second(&'a self, s: &rayon::Scope<'a>, seeded: Candidate) {
        s.spawn(move |_| {
            // (stopped while it waited for a thread: not fitted)
            if !self.second.stop.raised() {
                let result = (self.fits.fit)(&seeded, None, Some(&self.second.stop));
                push(&self.starts, (1, result));
            }
        });
    }
}

/// The second start held back, and whether the own start has ended.
#[derive(Default)]
struct Held {
    own_ended: bool,
    seeded: Option<Candidate>,
}

fn push<T>(to: &Mutex<Vec<T>>, item: T) {
    if let Ok(mut v) = to.lock() {
        v.push(item);
    }
}

fn take<T>(from: &Mutex<Vec<T>>) -> Vec<T> {
    from.lock()
        .map(|mut v| std::mem::take(&mut *v))
        .unwrap_or_default()
}

/// `c` with the second wave's give-up rule against the first wave's best
/// objective `best_cost` (the report's cost; none where no fit of the first
/// wave succeeded).
fn giving_up(c: &Candidate, best_cost: f64) -> Candidate {
    Candidate {
        give_up: best_cost.is_finite().then_some(GiveUp {
            after: GIVE_UP_AFTER,
            // the solver's ½‖r‖² is half the report's cost
            above: GIVE_UP_FACTOR * 0.5 * best_cost,
        }),
        ..c.clone()
    }
}

#[cfg(test)]
/// `fit_all` with stub fits whose BICs are given and whose order is
/// forced, on 4 threads (a stub waits for another fit).
mod tests {
    use super::super::candidate::Candidate;
    use super::super::{Cause, Scored};
    use super::{fit_all, Fits, Race};
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

    /// A candidate of `cause` on `base` with `starts` starts (no
    /// parameters: the stubs fit none).
    fn candidate(base: &Description, cause: Cause, starts: usize) -> Candidate {
        Candidate {
            cause,
            start: base.clone(),
            params: Vec::new(),
            starts,
            also_from: Vec::new(),
            give_up: None,
        }
    }

    /// `fit_all` of `others` and the own hysteresis start `own` by the
    /// stubs `fits`, on `threads` threads.
    fn ranked(
        threads: usize,
        base: &Description,
        others: &[Candidate],
        own: &Candidate,
        fits: &Fits,
    ) -> Vec<Scored> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| fit_all(base, others, Some(own), fits))
    }

    /// A fit report whose objective is `cost`.
    fn report(cost: f64, description: Description) -> FitReport {
        let names = ["coil.resistance".to_string()];
        let sensitivity = Sensitivity::from_jacobian(&names, &DMatrix::zeros(1, 1), &[1.0], &[0.0]);
        FitReport {
            description,
            values: Vec::new(),
            wnrmse_current: 0.0,
            wnrmse_flux: None,
            nrmse_position: None,
            cost,
            iterations: 0,
            simulations: 0,
            sensitivities: Sensitivities::Analytic,
            differenced_jacobians: 0,
            status: Status::CostConverged,
            best_start: 0,
            sensitivity,
            scanned_threshold: None,
        }
    }

    /// A fit scored `bic`, its objective |bic| (for the give-up rules).
    fn scored(cause: Cause, bic: f64, description: Description) -> Scored {
        Scored {
            cause,
            fit: Ok(report(bic.abs(), description)),
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
        let (own_done, seeded_calls, stopped) = (
            AtomicBool::new(false),
            AtomicUsize::new(0),
            AtomicBool::new(false),
        );
        let fit = |c: &Candidate, _: Race, stop: Option<&Stop>| match (c.cause, stop) {
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
        let fits = Fits {
            race: &|_| None,
            fit: &fit,
        };
        let others = [candidate(&base, Cause::Saturation, 1)];
        let ranking = ranked(
            4,
            &base,
            &others,
            &candidate(&base, Cause::Hysteresis, 1),
            &fits,
        );
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

    /// The first wave's BICs (objectives their magnitudes): `none` −100,
    /// eddy currents −300, the own hysteresis start −50; fringing and
    /// bouncing raced, then fitted in the second wave.
    fn waves(threads: usize, first_fails: bool) -> (Vec<(Cause, f64)>, Vec<Option<GiveUp>>) {
        let base = baseline();
        let others = [
            candidate(&base, Cause::Fringing, 3),
            candidate(&base, Cause::None, 1),
            candidate(&base, Cause::Bouncing, 4),
            candidate(&base, Cause::EddyCurrents, 1),
        ];
        let own = candidate(&base, Cause::Hysteresis, 1);
        let first_ended = AtomicUsize::new(0);
        let given_up = std::sync::Mutex::new(Vec::new());
        let race = |c: &Candidate| (c.starts > 1).then(|| Ok(report(1.0, c.start.clone())));
        let fit = |c: &Candidate, race: Race, stop: Option<&Stop>| {
            assert!(stop.is_none());
            let bic = match c.cause {
                Cause::Fringing | Cause::Bouncing => {
                    assert_eq!(
                        first_ended.load(Ordering::SeqCst),
                        3,
                        "before the first wave ended"
                    );
                    assert!(matches!(race, Some(Ok(_))));
                    given_up.lock().unwrap().push(c.give_up);
                    return scored(c.cause, -20.0, c.start.clone());
                }
                Cause::None => -100.0,
                Cause::EddyCurrents => -300.0,
                _ => -50.0,
            };
            assert!(race.is_none() && c.give_up.is_none());
            // the first wave's fits end slowly: the second waits for all
            std::thread::sleep(Duration::from_millis(20));
            first_ended.fetch_add(1, Ordering::SeqCst);
            match first_fails {
                true => Scored {
                    fit: Err("failed".into()),
                    ..scored(c.cause, f64::INFINITY, c.start.clone())
                },
                false => scored(c.cause, bic, c.start.clone()),
            }
        };
        let fits = Fits {
            race: &race,
            fit: &fit,
        };
        let ranking = ranked(threads, &base, &others, &own, &fits);
        let bics = ranking.iter().map(|s| (s.cause, s.bic)).collect();
        (bics, given_up.into_inner().unwrap())
    }

    #[test]
    fn raced_candidates_are_fitted_after_the_first_wave_given_up_against_its_best() {
        let give_up = Some(GiveUp {
            after: 5,
            // 10 × the own start's objective 50, halved (the solver's ½‖r‖²)
            above: 250.0,
        });
        let (one, given_up) = waves(1, false);
        assert_eq!(given_up, vec![give_up; 2]);
        let (four, given_up) = waves(4, false);
        assert_eq!(given_up, vec![give_up; 2]);
        // every candidate once, in the same order whatever the threads
        assert_eq!(one, four);
        let mut causes: Vec<Cause> = one.iter().map(|(c, _)| *c).collect();
        causes.sort();
        let mut all = vec![
            Cause::Fringing,
            Cause::None,
            Cause::Bouncing,
            Cause::EddyCurrents,
            Cause::Hysteresis,
        ];
        all.sort();
        assert_eq!(causes, all);
    }

    #[test]
    fn without_a_first_wave_fit_nothing_is_given_up() {
        let (_, given_up) = waves(2, true);
        assert_eq!(given_up, vec![None; 2]);
    }

    /// Saturation ends first, then the own start (beating the core), and
    /// only then `none`: the second start, held while `none` ran, is never
    /// fitted; where the own start does not beat the core it is, once.
    #[test]
    fn a_held_second_start_runs_only_where_the_own_start_needs_it() {
        for (own, calls) in [(-200.0, 0), (-50.0, 1)] {
            let base = baseline();
            let (saturated, own_done) = (AtomicBool::new(false), AtomicBool::new(false));
            let seeded_calls = AtomicUsize::new(0);
            let fit = |c: &Candidate, _: Race, stop: Option<&Stop>| {
                let bic = match (c.cause, stop) {
                    (Cause::Saturation, _) => {
                        saturated.store(true, Ordering::SeqCst);
                        -100.0
                    }
                    (Cause::Hysteresis, None) => {
                        wait_for("the saturation fit", || saturated.load(Ordering::SeqCst));
                        own_done.store(true, Ordering::SeqCst);
                        own
                    }
                    (Cause::Hysteresis, Some(_)) => {
                        seeded_calls.fetch_add(1, Ordering::SeqCst);
                        -300.0
                    }
                    _ => {
                        wait_for("the own start", || own_done.load(Ordering::SeqCst));
                        -10.0
                    }
                };
                scored(c.cause, bic, c.start.clone())
            };
            let fits = Fits {
                race: &|_| None,
                fit: &fit,
            };
            let others = [
                candidate(&base, Cause::Saturation, 1),
                candidate(&base, Cause::None, 1),
            ];
            let own_candidate = candidate(&base, Cause::Hysteresis, 1);
            let ranking = ranked(4, &base, &others, &own_candidate, &fits);
            assert_eq!(seeded_calls.into_inner(), calls, "own BIC {own}");
            let hysteresis = ranking.iter().find(|s| s.cause == Cause::Hysteresis);
            let want = if calls == 0 { own } else { -300.0 };
            assert_eq!(hysteresis.map(|s| s.bic), Some(want));
        }
    }
}
