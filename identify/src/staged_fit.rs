//! A fit of several starts in two stages, for fits of a long record (the
//! diagnosis's ranking of candidates): every start is fitted on the
//! record's first pulses, and only the start that fits them best is then
//! fitted on all the samples, from its own start point.
//!
//! The starts are there to find the right basin of a non-convex objective;
//! on a record of repeated pulses the first ones tell the basins apart as
//! well as the whole record does, at a fraction of the replays. The second
//! stage is the very fit that start gets among all of them (the same
//! weights, point and tolerances, [`FitOptions::only_start`]): where the
//! first pulses pick the start that the whole record would pick, the result
//! is the one-stage fit's, bit for bit. (Continuing from the first stage's
//! optimum instead was tried: where the model is wrong its optimum on the
//! first pulses is not the whole record's, and the fit crawled from there,
//! e.g. fringing on a saturation record ran 40 more iterations.)
//!
//! The diagnosis's polish uses [`first_pulses`] too, and does continue from
//! the first stage's optimum (`diagnose/polish.rs`): it fits the named
//! cause, taken to be the right model there. Where it is not (an effect
//! outside the vocabulary named anyway), the continuation may take longer,
//! not end elsewhere: the second stage is a full fit on the whole record.

use crate::description::Description;
use crate::{fit, FitError, FitOptions, FitParam, FitReport, Measured};

/// The first stage fits about this share of the samples, …
const SHARE: f64 = 0.25;
/// … and at least this many voltage edges (the rise and the fall of two
/// pulses), ending before the next edge so that the last pulse's transient
/// is whole; …
const MIN_EDGES: usize = 4;
/// … only where that leaves at most half of the samples and at least this
/// many (a shorter record is fitted in one stage).
const MIN_SAMPLES: usize = 2000;

/// The number of samples of the first stage (None: one stage): the samples
/// before the first voltage edge at or after [`SHARE`] of the record that has
/// [`MIN_EDGES`] edges before it.
pub fn first_pulses(data: &Measured) -> Option<usize> {
    let n = data.len();
    let edges = data.edges.as_ref()?;
    let target = (n as f64 * SHARE) as usize;
    let end = (edges.iter().enumerate())
        .find(|(j, e)| *j >= MIN_EDGES && e.k >= target)
        .map(|(_, e)| e.k + 1)?;
    (end >= MIN_SAMPLES && 2 * end <= n).then_some(end)
}

/// [`crate::fit`] of `params` of `description` to `data` with
/// `options.starts` starts, raced on [`first_pulses`]: only the start that
/// fits those best is fitted on all of `data` (one stage where there is a
/// single start or the record is too short). Where either stage fails
/// (the first pulses cannot be fitted, or the winner cannot be fitted on
/// the whole record, where the one-stage fit would keep the next best
/// start), all the starts are fitted on the whole record as in one stage.
/// Iterations, replays and differenced Jacobians count every stage run.
pub fn fit_staged(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> Result<FitReport, FitError> {
    let first = race(description, data, params, options);
    after_race(description, data, params, options, first)
}

/// The first stage of [`fit_staged`]: every start fitted on the first
/// pulses (None: the fit has one stage).
pub fn race(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> Option<Result<FitReport, FitError>> {
    let end = (options.starts > 1 && options.only_start.is_none())
        .then(|| first_pulses(data))
        .flatten()?;
    Some(fit(description, &data.head(end), params, options, &|_| {}))
}

/// The rest of [`fit_staged`] after [`race`] gave `first`: the winner on
/// the whole record (`options` may differ from the race's, e.g. by a
/// give-up rule), or the one-stage fit where there was no race or a stage
/// failed.
pub fn after_race(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
    first: Option<Result<FitReport, FitError>>,
) -> Result<FitReport, FitError> {
    let one_stage = || fit(description, data, params, options, &|_| {});
    let Some(Ok(first)) = first else {
        return one_stage();
    };
    let only = FitOptions {
        only_start: Some(first.best_start),
        ..options.clone()
    };
    let mut whole = fit(description, data, params, &only, &|_| {}).or_else(|_| one_stage())?;
    whole.iterations += first.iterations;
    whole.simulations += first.simulations;
    whole.differenced_jacobians += first.differenced_jacobians;
    Ok(whole)
}
