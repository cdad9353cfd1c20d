//! The regions of the record where a cause shows, and how much of the time
//! and of the residual each holds.
//!
//! - [`Region::AfterVoltageSteps`]: within 3 τ after a voltage step.
//! - [`Region::DuringMotion`]: the simulated mode is free motion (`moving`).
//! - [`Region::AfterImpacts`]: within 3 τ after a simulated impact (an impact
//!   stops the armature, the motional back-EMF vanishes and the current recovers
//!   with τ; a bounce is one more impact).
//! - [`Region::HighFlux`]: |φ_sim| > 70 % of max |φ_sim|.
//! - [`Region::Steady`]: none of the above.
//!
//! Shares are counted per sample (the spec guarantees uniform sampling, so a
//! sample stands for the same time everywhere). Regions overlap: each counts
//! every sample it contains, so the shares of different regions may add to
//! more than 1; `Steady` is the complement of the union of the others.
//!
//! Regions are ranked by their *excess*, residual share − time share: the part
//! of the residual a region holds beyond what its duration explains. Unlike the
//! concentration alone, the excess does not favour a small subset of the region
//! that really holds the residual. The top region is named as holding the
//! residual when its concentration (residual share / time share) is at least
//! 1.5 and its excess at least 15 %. Each region also reports its share of
//! Σ |φ̇| r², the numerator of the [JA 81] error the diagnosis ranks by.

use std::fmt;

use super::stats::range;
use super::{Signals, Sums};

/// Time constants after a step or an impact that belong to it.
const SETTLING_TAUS: f64 = 3.0;
/// Fraction of max |φ_sim| above which the flux is high.
const HIGH_FLUX: f64 = 0.7;
/// A region holds the residual when its concentration and excess reach these.
const DOMINANT_CONCENTRATION: f64 = 1.5;
const DOMINANT_EXCESS: f64 = 0.15;

/// A part of the record where a cause shows (defined in the module
/// documentation of `diagnose/localise/regions.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Region {
    AfterVoltageSteps,
    DuringMotion,
    AfterImpacts,
    HighFlux,
    Steady,
}

impl Region {
    /// The region in words, as it ends a sentence ("… falls after voltage steps").
    pub fn phrase(self) -> &'static str {
        match self {
            Region::AfterVoltageSteps => "after voltage steps",
            Region::DuringMotion => "during motion",
            Region::AfterImpacts => "after impacts",
            Region::HighFlux => "at high flux",
            Region::Steady => "in steady intervals",
        }
    }
}

impl fmt::Display for Region {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.phrase())
    }
}

/// How much of the time and of the residual one region holds.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionShare {
    pub region: Region,
    /// Fraction of the samples in the region.
    pub time_share: f64,
    /// Fraction of Σ r² in the region.
    pub residual_share: f64,
    /// Fraction of Σ |φ̇| r² in the region: its part of the numerator of [JA 81].
    pub weighted_share: f64,
    /// residual_share / time_share (1 for a residual spread evenly; 0 when empty).
    pub concentration: f64,
    /// The region as time intervals [s], first and last sample of each run.
    pub spans: Vec<(f64, f64)>,
}

impl RegionShare {
    /// The residual share beyond what the duration explains (the ranking key).
    pub fn excess(&self) -> f64 {
        self.residual_share - self.time_share
    }

    /// Whether the residual concentrates here (1.5 × its time share and 15 %
    /// of the residual beyond it).
    pub fn holds_residual(&self) -> bool {
        self.concentration >= DOMINANT_CONCENTRATION && self.excess() >= DOMINANT_EXCESS
    }
}

/// The mask of every region, `Steady` last (the complement of the others).
pub(super) fn region_masks(s: &Signals, step_times: &[f64], tau: f64) -> Vec<(Region, Vec<bool>)> {
    let width = SETTLING_TAUS * tau;
    let (_, phi_max) = range(&s.flux_simulated.iter().map(|p| p.abs()).collect::<Vec<_>>());
    let high: Vec<bool> = s
        .flux_simulated
        .iter()
        .map(|p| phi_max > 0.0 && p.abs() > HIGH_FLUX * phi_max)
        .collect();
    let mut masks = vec![
        (
            Region::AfterVoltageSteps,
            after_events(s.t, step_times, width),
        ),
        (Region::DuringMotion, s.moving.to_vec()),
        (Region::AfterImpacts, after_events(s.t, s.impacts, width)),
        (Region::HighFlux, high),
    ];
    let steady = (0..s.t.len())
        .map(|k| !masks.iter().any(|(_, m)| m[k]))
        .collect();
    masks.push((Region::Steady, steady));
    masks
}

/// Samples within [e, e + width] of any event time e.
fn after_events(t: &[f64], events: &[f64], width: f64) -> Vec<bool> {
    let mut mask = vec![false; t.len()];
    for &e in events.iter().filter(|e| e.is_finite()) {
        let first = t.partition_point(|&x| x < e);
        let last = t.partition_point(|&x| x <= e + width);
        mask[first..last.max(first)].fill(true);
    }
    mask
}

/// The shares of one region.
pub(super) fn share(region: Region, mask: &[bool], sums: &Sums, t: &[f64]) -> RegionShare {
    let in_region = |k: &usize| mask[*k] && sums.valid[*k];
    let idx: Vec<usize> = (0..mask.len()).filter(in_region).collect();
    let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
    let time_share = ratio(idx.len() as f64, sums.count as f64);
    let residual_share = ratio(idx.iter().map(|&k| sums.r2[k]).sum(), sums.total_r2);
    RegionShare {
        region,
        time_share,
        residual_share,
        weighted_share: ratio(idx.iter().map(|&k| sums.wr2[k]).sum(), sums.total_wr2),
        concentration: ratio(residual_share, time_share),
        spans: spans(t, mask),
    }
}

/// The runs of `mask` as (first, last) sample times.
fn spans(t: &[f64], mask: &[bool]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut start = None;
    for (k, &m) in mask.iter().enumerate() {
        match (m, start) {
            (true, None) => start = Some(k),
            (false, Some(a)) => {
                out.push((t[a], t[k - 1]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(a) = start {
        out.push((t[a], t[mask.len() - 1]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::bench::{bench, run, top, CYCLES, DT, FIRST_RISE, MOTION, TAU};
    use super::*;

    #[test]
    fn residual_after_steps_is_named() {
        let b = bench();
        let l = run(&b, |k| 0.3 * (-b.since_step[k] / (0.3 * TAU)).exp());
        assert_eq!(top(&l), Region::AfterVoltageSteps, "{l}");
        assert!(l.to_string().contains("after voltage steps"));
        // 0.3 A is far beyond what a step's timing explains (≈ 25 mA here).
        assert!(!l.is_edge_timing(), "{l}");
    }

    #[test]
    fn residual_after_impacts_is_named() {
        let b = bench();
        let l = run(&b, |k| {
            let since = b.since_rise[k] - MOTION.1;
            let ring = (2.0 * std::f64::consts::PI * since / 0.5e-3).sin();
            if (0.0..1e-3).contains(&since) {
                0.2 * ring
            } else {
                0.0
            }
        });
        assert_eq!(top(&l), Region::AfterImpacts, "{l}");
        let marked = l.marked_windows();
        let impacts = marked.iter().filter(|m| m.2 == "after impacts").count();
        assert_eq!(impacts, CYCLES, "one span per impact: {marked:?}");
        assert!(marked.iter().any(|m| m.2 == "largest residual"));
        assert!(
            l.worst
                .iter()
                .all(|w| w.region == Some(Region::AfterImpacts)),
            "{l}"
        );
    }

    #[test]
    fn residual_during_motion_is_named() {
        let b = bench();
        let l = run(&b, |k| if b.moving[k] { 0.1 } else { 0.0 });
        assert_eq!(top(&l), Region::DuringMotion, "{l}");
    }

    #[test]
    fn residual_at_high_flux_is_named() {
        let b = bench();
        let l = run(&b, |k| 0.1 * (b.flux[k] / 2e-4).powi(6));
        assert_eq!(top(&l), Region::HighFlux, "{l}");
    }

    #[test]
    fn steady_residual_is_named() {
        let b = bench();
        let l = run(&b, |k| if b.since_rise[k] >= 15e-3 { 0.1 } else { 0.0 });
        assert_eq!(top(&l), Region::Steady, "{l}");
    }

    #[test]
    fn white_noise_is_spread_and_does_not_drift() {
        let l = run(&bench(), |_| 0.0);
        for r in &l.regions {
            assert!((r.concentration - 1.0).abs() < 0.2, "{r:?}");
            assert!((r.weighted_share - r.residual_share).abs() < 1e-12);
        }
        assert!(l.dominant().is_none(), "{l}");
        assert!(!l.drift.significant, "{}", l.drift);
        assert!(l.to_string().contains("spread"));
    }

    #[test]
    fn steady_is_the_complement_of_the_other_regions() {
        let l = run(&bench(), |_| 0.0);
        let steady = l
            .regions
            .iter()
            .find(|r| r.region == Region::Steady)
            .unwrap();
        assert!(steady.time_share > 0.0 && steady.time_share < 1.0);
        // 13–20 ms after the first rise: past the falling step's 3 τ and
        // outside every other region.
        let expected = (FIRST_RISE + 13e-3, FIRST_RISE + 20e-3 - DT);
        assert!(
            steady
                .spans
                .iter()
                .any(|&(a, b)| (a - expected.0).abs() < 2e-4 && (b - expected.1).abs() < 1e-9),
            "{:?}",
            steady.spans
        );
    }
}
