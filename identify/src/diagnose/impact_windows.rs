//! What a whole-record error dilutes: the residual just after the model's
//! impacts. A bounce lasts a few milliseconds of a record of seconds, so a
//! model without it can sit within the noise floor on the whole record while
//! missing every bounce (blind class 3, a warming relay that bounces: its
//! drift alone left 1.13–1.19× the floor on fresh seeds 213 and 217). The
//! selection looks at these windows where the whole record counts as
//! explained, and measures an impact effect's gain on them.
//!
//! A window opens at each impact of a replay (free motion ending at a stop)
//! and lasts as long as the transit that led to it: the armature's own time
//! scale, long enough for the bounces that follow. (The localisation's
//! region after impacts, `localise::regions`, is 3 τ long: the current's
//! electrical recovery, which it names; here the bounces' flights.)

use std::ops::Range;

use crate::{Measured, SimOutputs};

use super::{Diagnosis, Gain};

/// Samples after each impact of `replay`, as long as the transit before it.
pub(super) fn windows(replay: &SimOutputs) -> Vec<Range<usize>> {
    let free = crate::sim::Mode::Free.number();
    let n = replay.mode.len();
    let mut windows = Vec::new();
    let mut transit = 0;
    for (k, &mode) in replay.mode.iter().enumerate() {
        if mode == free {
            transit += 1;
            continue;
        }
        if transit > 0 {
            windows.push(k..(k + transit).min(n));
        }
        transit = 0;
    }
    windows
}

/// The samples the `windows` cover, each once, from `from` on.
fn covered(windows: &[Range<usize>], from: usize, n: usize) -> Vec<usize> {
    let mut inside = vec![false; n];
    for w in windows {
        for k in w.clone().filter(|k| *k >= from) {
            inside[k] = true;
        }
    }
    (0..n).filter(|k| inside[*k]).collect()
}

/// The |φ̇|-weighted RMS of `model − measured` over `samples` [A] (None:
/// no weight there).
fn weighted_rms(
    model: &[f64],
    measured: &[f64],
    weights: &[f64],
    samples: &[usize],
) -> Option<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    for &k in samples {
        num += weights[k] * (model[k] - measured[k]).powi(2);
        den += weights[k];
    }
    (den > 0.0).then(|| (num / den).sqrt())
}

/// The noise floor of `step` in amperes: the wNRMSE floor times the
/// weighted RMS of the measured current it is relative to.
fn floor_amperes(step: &Diagnosis, data: &Measured) -> Option<f64> {
    let all: Vec<usize> = (0..data.i.len()).collect();
    let zeros = vec![0.0; data.i.len()];
    let rms = weighted_rms(&data.i, &zeros, &step.weights, &all)?;
    Some(step.noise_floor * rms).filter(|f| *f > 0.0)
}

/// How many noise floors `step`'s model leaves in the windows after its
/// impacts (0 where it has none, or they hold no weight).
pub(super) fn excess(step: &Diagnosis, data: &Measured) -> f64 {
    let samples = covered(&windows(&step.extended_replay), 0, data.i.len());
    let replay = &step.extended_replay;
    let error = weighted_rms(&replay.current, &data.i, &step.weights, &samples);
    match (error, floor_amperes(step, data)) {
        (Some(e), Some(floor)) => e / floor,
        _ => 0.0,
    }
}

/// The gain of `next` over `last` in the windows after `last`'s impacts:
/// over the whole record (None: no weight in them), and over those on the
/// part `next`'s fits did not see (None: no window, or no weight, there).
pub(super) fn gains(
    last: &Diagnosis,
    next: &Diagnosis,
    data: &Measured,
) -> (Option<Gain>, Option<Gain>) {
    let n = data.i.len();
    let windows = windows(&last.extended_replay);
    let gain = |samples: &[usize]| {
        let error = |r: &SimOutputs| weighted_rms(&r.current, &data.i, &last.weights, samples);
        Some(Gain::new(
            error(&last.extended_replay)?,
            error(&next.extended_replay)?,
        ))
    };
    let unseen = covered(&windows, next.fitted_samples, n);
    (gain(&covered(&windows, 0, n)), gain(&unseen))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn replay(mode: &[u8]) -> SimOutputs {
        SimOutputs {
            t: Vec::new(),
            current: Vec::new(),
            voltage: Vec::new(),
            z: Vec::new(),
            phi: Vec::new(),
            h_c: None,
            mode: mode.to_vec(),
        }
    }

    #[test]
    fn a_window_follows_each_impact_for_as_long_as_its_transit() {
        // stuck, a transit of 3 samples, stuck, a transit of 2, stuck
        let r = replay(&[1, 1, 2, 2, 2, 3, 3, 3, 3, 3, 2, 2, 1, 1]);
        assert_eq!(windows(&r), vec![5..8, 12..14]);
        assert_eq!(covered(&windows(&r), 6, 14), vec![6, 7, 12, 13]);
        // a window cut short by the record's end
        assert_eq!(windows(&replay(&[2, 2, 2, 1])), vec![3..4]);
    }

    #[test]
    fn a_still_armature_has_no_window() {
        assert!(windows(&replay(&[1, 1, 1])).is_empty());
        assert!(windows(&replay(&[2, 2, 2])).is_empty());
    }
}
