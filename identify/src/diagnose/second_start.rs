//! The hysteresis candidate's second start, from the fitted saturating
//! core: needed only where the own start does not beat that core by BIC.
//! `waves::fit_all` holds it from the end of the saturation fit until the
//! own start has ended (then spawns it if needed) or until no other fit of
//! the first wave is left (then spawns it, and stops it as soon as the own
//! start beats the core); whether its result counts follows from the two
//! BICs alone, so the answer does not depend on which fit ended first.
//! Where it runs, it gives up early when it stays far above the core it
//! started from ([`giving_up`]): a rule on its own iterations, the same
//! every run.
//!
//! Where the own start beat the saturating core, the second start used to
//! run its 40 iterations (2–3.5 s, the longest fit of a 40 000-sample
//! record); on the confusion matrix's 105 records it then found a better
//! Jiles–Atherton fit in 25 of 65 rankings, which changed no answer: a
//! measured rule, not a bound.

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

    #[test]
    fn without_a_saturation_fit_there_is_no_second_start() {
        let s = SecondStart::default();
        s.own_fitted(f64::INFINITY);
        assert!(!s.counts() && !s.stop.raised());
    }
}
