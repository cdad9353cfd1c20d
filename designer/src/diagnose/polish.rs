//! The named cause, polished: its fit alternated with the placement of the
//! record's voltage edges by its own model.
//!
//! The ranking fits every candidate on the edges the baseline placed (the
//! same nuisance for all, so their errors compare). The named cause's values
//! are what a test engineer reads, with standard errors: fitted on the
//! baseline's placement and at the ranking's loose tolerances they sit
//! further from the truth than their standard errors say (on the
//! hidden-effect records 0.2–0.7 % off on noise-free data). Placing the edges
//! with the named model and fitting again, three times, takes them to within
//! 0.04 % there.

use super::candidate::Candidate;
use super::Cause;
use crate::identify::{self, FitOptions, FitReport, Measured};

/// Rounds of (place the edges with the model, fit the model on them).
const ROUNDS: usize = 3;

/// The named candidate and the record's edges placed by it, alternated
/// [`ROUNDS`] times from the ranking's fit (the edges are a nuisance
/// of the data that the model's values move, and the values move with the
/// edges). Returns the polished fit (None: the ranking's stands) and the
/// record with the last edges.
pub(super) fn with_edges(
    candidate: Option<&Candidate>,
    fit: &FitReport,
    data: &Measured,
    fitted_samples: usize,
    options: &FitOptions,
) -> (Option<FitReport>, Measured) {
    let mut named: Option<FitReport> = None;
    let mut own = data.clone();
    for _ in 0..ROUNDS {
        let current = named.as_ref().unwrap_or(fit);
        own.edges = Some(identify::edges::located(&current.description, data));
        match polish(candidate, current, &own.head(fitted_samples), options) {
            Some(p) => named = Some(p),
            None => break,
        }
    }
    (named, own)
}

/// The polish's integration tolerance, stopping rule, iterations and
/// integration steps: tighter than the ranking's fits (ftol 1e-5, replays at
/// 1e-8), which stop where the named values still move by more than their
/// standard errors.
const RTOL: f64 = 1e-10;
const FTOL: f64 = 1e-10;
const ITERATIONS: usize = 100;
const STEPS_PER_SAMPLE: usize = 200;

/// The named candidate fitted again from `fit`'s optimum on `own` (the
/// fitted samples with the edges its model placed), at the tolerances
/// above. Not for the Jiles–Atherton core (finite-difference Jacobian:
/// seconds per fit). None: nothing better.
fn polish(
    candidate: Option<&Candidate>,
    fit: &FitReport,
    own: &Measured,
    options: &FitOptions,
) -> Option<FitReport> {
    let c = candidate.filter(|c| c.cause != Cause::Hysteresis)?;
    let options = FitOptions {
        starts: 1,
        rtol: RTOL,
        ftol: FTOL,
        max_iterations: ITERATIONS,
        max_steps_per_sample: STEPS_PER_SAMPLE,
        ..options.clone()
    };
    identify::fit(&fit.description, own, &c.params, &options, &|_| {})
        .ok()
        .filter(|p| p.wnrmse_current.is_finite())
}
