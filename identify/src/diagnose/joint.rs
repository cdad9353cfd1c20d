//! The named causes fitted together. Forward selection fits each cause on
//! top of the ones before with those held: a first cause fitted alone
//! absorbs part of the second's effect and stays there (a McLyman gap
//! fitted before the eddy currents it cannot represent ends 2× off, and the
//! pair leaves up to 49× the noise floor). Every named cause's parameters are
//! therefore fitted once more, all at once, from the selection's values, on
//! the record's edges as the whole model places them ([`super::polish`]).
//! A resistance drift named first is fitted again the same way, alone, before
//! the next step (`Path::from`): on the whole fitted part, where a drift
//! shows.

use super::candidate::Candidate;
use super::{polish, Cause, Diagnosis, Gain};
use crate::{FitOptions, FitParam, Measured};

/// Refits every named cause of `steps` jointly and, where that lowers the
/// error on the whole record, makes it the last step's model: its fit (with
/// every cause's values and standard errors, so the last step's
/// `named_fit` then covers every cause while its `named_candidate` stays its
/// own), its replay and its gain over the model before it. The
/// Jiles–Atherton core is left as selected (its Jacobian is by finite
/// differences: seconds per iteration). Whether the joint fit was taken.
///
/// A resistance drift is fitted together on the `whole_fitted_part` of the
/// record (all but its held-out end), not on the head the ranking's fits
/// see: a drift grows with time, and on a warming relay that bounces (blind
/// class 3, fresh seed 209) fitted on the first 12 000 of 60 001 samples it
/// stopped 4 % short of the truth and left 2.03× the floor, above the pair's
/// 2×.
pub(super) fn refit(
    steps: &mut [Diagnosis],
    data: &Measured,
    options: &FitOptions,
    whole_fitted_part: usize,
) -> bool {
    if steps.iter().any(|s| s.cause == Cause::Hysteresis) {
        return false;
    }
    let params = every_parameter(steps);
    let drifts = steps.iter().any(|s| s.cause == Cause::ResistanceDrift);
    let Some(last) = steps.last_mut() else {
        return false;
    };
    if params.is_empty() {
        return false;
    }
    let candidate = Candidate {
        cause: last.cause,
        start: last.extended.clone(),
        params,
        starts: 1,
        also_from: Vec::new(),
        give_up: None,
    };
    let data = Measured {
        edges: Some(last.edges.clone()),
        ..data.clone()
    };
    let k = match drifts {
        true => whole_fitted_part.max(last.fitted_samples),
        false => last.fitted_samples,
    };
    let Ok(start) = crate::fit(
        &candidate.start,
        &data.head(k),
        &candidate.params,
        &FitOptions {
            starts: 1,
            ..options.clone()
        },
        &|_| {},
    ) else {
        return false;
    };
    let located = crate::edges::located(&start.description, &data);
    let polished = polish::with_edges(Some(&candidate), &start, (&data, located), k, options);
    let own = polish::placed(polished.own, polished.fit.as_ref());
    let linearisation = polished.linearisation;
    let fit = polished.fit.unwrap_or(start);
    // (the fits saw the fitted part only: the rest may not replay)
    let Ok(replay) = crate::simulate_outputs(&fit.description, &own) else {
        return false;
    };
    let error = crate::wnrmse(&replay.current, &data.i, &last.weights);
    if !(error < last.whole.extended_wnrmse) {
        return false;
    }
    let linearisation = linearisation.as_ref();
    last.propagated =
        polish::propagated(Some(&candidate), &fit, &own.head(k), linearisation, options);
    last.whole = Gain::new(last.whole.baseline_wnrmse, error);
    last.held_out = (k < data.t.len()).then(|| {
        let base = &last.baseline_replay.current[k..];
        Gain::new(
            crate::wnrmse(base, &data.i[k..], &last.weights[k..]),
            crate::wnrmse(&replay.current[k..], &data.i[k..], &last.weights[k..]),
        )
    });
    // what the last model was fitted on: its held-out end is the rest
    last.fitted_samples = k;
    last.extended = fit.description.clone();
    last.extended_replay = replay;
    last.named_fit = Some(super::bounce_threshold::keeping_scan(
        fit,
        last.named_fit.as_ref(),
    ));
    true
}

/// Every named cause's fitted parameters, a later step's bounds replacing
/// an earlier one's for a key they share (the resistance).
pub(super) fn every_parameter(steps: &[Diagnosis]) -> Vec<FitParam> {
    let mut params: Vec<FitParam> = Vec::new();
    for c in steps.iter().filter_map(|s| s.named_candidate.as_ref()) {
        for p in &c.params {
            params.retain(|q| q.path != p.path);
            params.push(p.clone());
        }
    }
    params
}
