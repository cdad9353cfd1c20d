//! The voltage steps of a record and the electrical time constant τ the
//! current settles with after them: the width of the regions after steps
//! and after impacts.
//!
//! - **voltage step**: sample k with |v_k − v_{k−3}| > 20 % of the voltage range
//!   (max v − min v); a run of such samples is one step, at its first sample
//!   (the lag of 3 samples lets a step slew over a few samples).
//! - **electrical time constant τ**: for each step, the time the measured current
//!   takes to cover 1 − 1/e of its way to the value it settles at before the next
//!   step (the mean of the segment's last quarter); the median over the steps
//!   whose excursion stands above 5 × the noise of that last quarter. Without
//!   such a step, τ is 1 % of the record.

use super::stats::{mean_sd, median, range};

/// Threshold of a voltage step, as a fraction of the voltage range.
const STEP_FRACTION: f64 = 0.2;
/// Samples over which a step may slew and still count as one step.
const STEP_LAG: usize = 3;
/// A step's current excursion must exceed this many noise deviations to time τ.
const STEP_SNR: f64 = 5.0;
/// τ when no step settles visibly, as a fraction of the record's duration.
const FALLBACK_TAU_FRACTION: f64 = 0.01;

/// Indices of the voltage steps (first sample of each run over the threshold).
pub(super) fn voltage_steps(v: &[f64]) -> Vec<usize> {
    let (lo, hi) = range(v);
    let threshold = STEP_FRACTION * (hi - lo);
    let over = |k: usize| k >= 1 && (v[k] - v[k.saturating_sub(STEP_LAG)]).abs() > threshold;
    (1..v.len())
        .filter(|&k| threshold > 0.0 && over(k) && !over(k - 1))
        .collect()
}

/// The median settling time constant over the steps, or the fallback.
pub(super) fn electrical_tau(t: &[f64], i: &[f64], steps: &[usize]) -> f64 {
    let mut taus: Vec<f64> = steps
        .iter()
        .enumerate()
        .filter_map(|(j, &k0)| {
            let end = steps.get(j + 1).copied().unwrap_or(t.len());
            settling_time(&t[k0..end], &i[k0..end])
        })
        .collect();
    let duration = t.last().zip(t.first()).map_or(0.0, |(b, a)| b - a);
    let dt = if t.len() > 1 {
        duration / (t.len() - 1) as f64
    } else {
        0.0
    };
    median(&mut taus)
        .unwrap_or(FALLBACK_TAU_FRACTION * duration)
        .max(dt)
}

/// Time for the current to cover 1 − 1/e of its way to the segment's final
/// value, when the excursion stands out of the noise.
fn settling_time(t: &[f64], i: &[f64]) -> Option<f64> {
    let n = t.len();
    if n < 8 {
        return None;
    }
    let tail_start = n - n / 4;
    let (mean, sd) = mean_sd(&i[tail_start..]);
    let d0 = (i[0] - mean).abs();
    if d0.is_nan() || d0 <= STEP_SNR * sd {
        return None;
    }
    let k = i[..tail_start]
        .iter()
        .position(|x| (x - mean).abs() <= d0 / std::f64::consts::E)?;
    Some(t[k] - t[0])
}

#[cfg(test)]
mod tests {
    use super::super::bench::{bench, run, CYCLES, TAU};

    #[test]
    fn time_constant_is_read_from_the_current() {
        let l = run(&bench(), |_| 0.0);
        assert!((l.tau - TAU).abs() < 0.05 * TAU, "tau = {}", l.tau);
        assert_eq!(l.steps.len(), 2 * CYCLES);
    }
}
