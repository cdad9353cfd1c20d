//! Summary statistics of a signal: its range, mean and deviation, median;
//! a share as the percentage the reports print.

/// Min and max of the finite values (0, 0 when there is none).
pub(super) fn range(x: &[f64]) -> (f64, f64) {
    let (lo, hi) = x
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if lo <= hi {
        (lo, hi)
    } else {
        (0.0, 0.0)
    }
}

/// Mean and (population) standard deviation.
pub(super) fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len().max(1) as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

/// The median (sorts `x`); `None` when empty.
pub(super) fn median(x: &mut [f64]) -> Option<f64> {
    x.sort_by(f64::total_cmp);
    match x.len() {
        0 => None,
        n if n % 2 == 1 => Some(x[n / 2]),
        n => Some(0.5 * (x[n / 2 - 1] + x[n / 2])),
    }
}

/// A fraction in whole percent.
pub(super) fn pct(x: f64) -> f64 {
    (100.0 * x).round()
}
