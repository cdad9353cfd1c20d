//! The stretches of the record with the largest residual: the record cut
//! into 50 windows, the worst 3 reported (adjacent ones merged), each with
//! the region that holds most of its residual.

use super::regions::{Region, RegionShare};
use super::Sums;

/// The record is cut into this many windows; the worst few are reported.
const WINDOWS: usize = 50;
const WORST: usize = 3;

/// A stretch of the record with the largest residual.
#[derive(Debug, Clone, PartialEq)]
pub struct Window {
    /// First and last sample time [s].
    pub start: f64,
    pub end: f64,
    /// RMS residual in the window [A].
    pub rms: f64,
    /// Fraction of Σ r² in the window.
    pub residual_share: f64,
    /// The highest-ranked region holding at least half of the window's residual.
    pub region: Option<Region>,
}

/// The `WORST` windows with the largest Σ r², adjacent ones merged.
pub(super) fn worst_windows(
    t: &[f64],
    sums: &Sums,
    ranked: &[RegionShare],
    masks: &[(Region, Vec<bool>)],
) -> Vec<Window> {
    let n = t.len();
    let m = WINDOWS.min(n);
    let bounds: Vec<usize> = (0..=m).map(|j| j * n / m.max(1)).collect();
    let energy = |j: usize| sums.r2[bounds[j]..bounds[j + 1]].iter().sum::<f64>();
    let mut order: Vec<usize> = (0..m).filter(|&j| energy(j) > 0.0).collect();
    order.sort_by(|&a, &b| energy(b).total_cmp(&energy(a)));
    order.truncate(WORST);
    order.sort_unstable();
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for j in order {
        match runs.last_mut() {
            Some((_, last)) if *last + 1 == j => *last = j,
            _ => runs.push((j, j)),
        }
    }
    runs.into_iter()
        .map(|(a, b)| window(t, sums, bounds[a], bounds[b + 1], ranked, masks))
        .collect()
}

/// One worst window over samples [a, b).
fn window(
    t: &[f64],
    sums: &Sums,
    a: usize,
    b: usize,
    ranked: &[RegionShare],
    masks: &[(Region, Vec<bool>)],
) -> Window {
    let e: f64 = sums.r2[a..b].iter().sum();
    let count = sums.valid[a..b].iter().filter(|&&ok| ok).count().max(1);
    let held = |region: Region| {
        let mask = masks.iter().find(|(r, _)| *r == region).map(|(_, m)| m);
        mask.map_or(0.0, |m| (a..b).filter(|&k| m[k]).map(|k| sums.r2[k]).sum())
    };
    Window {
        start: t[a],
        end: t[b - 1],
        rms: (e / count as f64).sqrt(),
        residual_share: if sums.total_r2 > 0.0 {
            e / sums.total_r2
        } else {
            0.0
        },
        region: ranked
            .iter()
            .map(|r| r.region)
            .find(|&r| held(r) >= 0.5 * e),
    }
}
