//! The drift of the residual from cycle to cycle (a resistance that changes
//! as the coil warms).
//!
//! Cycles start at the voltage's rising edges (a Schmitt trigger at
//! 40 % / 60 % of the range) and run to the next one (the record's last cycle
//! counts when complete); the RMS residual of each cycle is fitted by a
//! least-squares line over the cycle index. The drift is significant when there
//! are at least 3 cycles, the line explains most of the cycle-to-cycle variation
//! (R² ≥ 0.5), and the fitted change over the record exceeds 10 % of the fitted
//! first value (white measurement noise moves a cycle's RMS by about
//! 1/√(2 · samples per cycle), far below that).

use std::fmt;

use super::stats::{median, pct, range};
use super::Sums;

/// Schmitt-trigger levels of the rising edges, as fractions of the range.
const EDGE_LOW: f64 = 0.4;
const EDGE_HIGH: f64 = 0.6;
/// Drift significance: minimum cycles, R² and relative change.
const DRIFT_MIN_CYCLES: usize = 3;
const DRIFT_MIN_R2: f64 = 0.5;
const DRIFT_MIN_CHANGE: f64 = 0.1;
/// The record's last cycle counts when it has this fraction of the median length.
const LAST_CYCLE_FRACTION: f64 = 0.95;

/// The trend of the residual from cycle to cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct Drift {
    /// (start [s], RMS residual [A]) of each cycle.
    pub cycles: Vec<(f64, f64)>,
    /// Least-squares slope of the cycle RMS over the cycle index [A / cycle].
    pub slope_per_cycle: f64,
    /// Fraction of the cycle-to-cycle variance the line explains.
    pub r_squared: f64,
    /// Fitted change over the record, relative to the fitted first cycle.
    pub relative_change: f64,
    /// At least 3 cycles, R² ≥ 0.5 and a change of at least 10 % (see the
    /// module documentation of `diagnose/localise/drift.rs`).
    pub significant: bool,
}

/// Indices of the voltage's rising edges (Schmitt trigger at 40 % / 60 %).
fn rising_edges(v: &[f64]) -> Vec<usize> {
    let (lo, hi) = range(v);
    let (low, high) = (lo + EDGE_LOW * (hi - lo), lo + EDGE_HIGH * (hi - lo));
    let mut is_high = v.first().is_some_and(|&x| x > high);
    let mut edges = Vec::new();
    for (k, &x) in v.iter().enumerate() {
        if !is_high && x > high {
            edges.push(k);
            is_high = true;
        } else if is_high && x < low {
            is_high = false;
        }
    }
    if hi > lo {
        edges
    } else {
        Vec::new()
    }
}

/// The per-cycle RMS residual and its least-squares trend.
pub(super) fn drift(t: &[f64], v: &[f64], sums: &Sums) -> Drift {
    let cycles: Vec<(f64, f64)> = cycle_bounds(v)
        .into_iter()
        .map(|(a, b)| {
            let count = sums.valid[a..b].iter().filter(|&&ok| ok).count().max(1);
            (
                t[a],
                (sums.r2[a..b].iter().sum::<f64>() / count as f64).sqrt(),
            )
        })
        .collect();
    let rms: Vec<f64> = cycles.iter().map(|c| c.1).collect();
    let (first, slope, r_squared) = line_fit(&rms);
    let mean = rms.iter().sum::<f64>() / rms.len().max(1) as f64;
    let base = if first > 0.0 { first } else { mean };
    let change = slope * rms.len().saturating_sub(1) as f64;
    let relative_change = if base > 0.0 { change / base } else { 0.0 };
    Drift {
        significant: rms.len() >= DRIFT_MIN_CYCLES
            && r_squared >= DRIFT_MIN_R2
            && relative_change.abs() >= DRIFT_MIN_CHANGE,
        cycles,
        slope_per_cycle: slope,
        r_squared,
        relative_change,
    }
}

/// Sample ranges [a, b) of the cycles: from each rising edge to the next; the
/// last one runs to the end when it is complete (at least 95 % of the median
/// cycle), since a truncated cycle's RMS is biased by the part it misses.
fn cycle_bounds(v: &[f64]) -> Vec<(usize, usize)> {
    let edges = rising_edges(v);
    let mut out: Vec<(usize, usize)> = edges.windows(2).map(|w| (w[0], w[1])).collect();
    let mut lengths: Vec<f64> = out.iter().map(|(a, b)| (b - a) as f64).collect();
    let full = median(&mut lengths).unwrap_or(0.0);
    if let Some(&last) = edges.last() {
        if (v.len() - last) as f64 >= LAST_CYCLE_FRACTION * full {
            out.push((last, v.len()));
        }
    }
    out
}

/// Least-squares line y_j ≈ a + b·j: (a, b, R²). R² is 0 for constant data.
fn line_fit(y: &[f64]) -> (f64, f64, f64) {
    let n = y.len() as f64;
    if y.len() < 2 {
        return (y.first().copied().unwrap_or(0.0), 0.0, 0.0);
    }
    let x_mean = (n - 1.0) / 2.0;
    let y_mean = y.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (j, &yj) in y.iter().enumerate() {
        let dx = j as f64 - x_mean;
        sxy += dx * (yj - y_mean);
        sxx += dx * dx;
        syy += (yj - y_mean).powi(2);
    }
    let b = sxy / sxx;
    let r2 = if syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        0.0
    };
    (y_mean - b * x_mean, b, r2)
}

impl fmt::Display for Drift {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.cycles.len();
        if n < DRIFT_MIN_CYCLES {
            return write!(f, "{n} voltage cycle(s): drift not assessed");
        }
        if self.significant {
            let verb = if self.relative_change > 0.0 {
                "grows"
            } else {
                "shrinks"
            };
            write!(
                f,
                "the residual {verb} by {} % over {n} cycles",
                pct(self.relative_change.abs())
            )
        } else {
            write!(
                f,
                "no drift of the residual over {n} cycles (fitted change {:+} %, R² {:.2})",
                pct(self.relative_change),
                self.r_squared
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::bench::{bench, run, CYCLES};
    use super::*;

    #[test]
    fn drifting_residual_is_significant() {
        let b = bench();
        // RMS per cycle ≈ 0.05·(1 + 0.25 c): +100 % over five cycles.
        let l = run(&b, |k| 0.05 * (1.0 + 0.25 * b.cycle[k] as f64));
        assert_eq!(l.drift.cycles.len(), CYCLES);
        assert!(l.drift.significant, "{}", l.drift);
        let expected = 0.25 * 4.0; // linear in c, noise adds ≈ 2 % in quadrature
        assert!(
            (l.drift.relative_change - expected).abs() < 0.05,
            "{}",
            l.drift
        );
        assert!(l.to_string().contains("grows by"));
    }

    #[test]
    fn line_fit_recovers_a_line() {
        let (a, b, r2) = line_fit(&[1.0, 3.0, 5.0, 7.0]);
        assert_eq!((a, b, r2), (1.0, 2.0, 1.0));
        assert_eq!(line_fit(&[2.0, 2.0, 2.0]).2, 0.0);
    }
}
