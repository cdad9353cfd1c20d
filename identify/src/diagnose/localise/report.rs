//! The localisation: what it holds (regions, windows, drift, timing,
//! position) and how it reads, in a few sentences for `reldesign diagnose`.

use std::fmt;

use super::drift::Drift;
use super::position::PositionError;
use super::regions::{Region, RegionShare};
use super::stats::pct;
use super::timing::EdgeTiming;
use super::windows::Window;

/// Where the current residual concentrates.
#[derive(Debug, Clone, PartialEq)]
pub struct Localisation {
    /// All five regions, ranked by excess (residual share − time share).
    pub regions: Vec<RegionShare>,
    pub drift: Drift,
    /// The worst windows (1/50 of the record each, adjacent ones merged), in time order.
    pub worst: Vec<Window>,
    /// RMS of the current residual [A].
    pub rms: f64,
    /// Electrical time constant estimated from the data [s].
    pub tau: f64,
    /// Voltage step times [s].
    pub steps: Vec<f64>,
    /// The steps' residuals against what their timing can explain.
    pub edge_timing: EdgeTiming,
    /// Present when the record has a measured position.
    pub position: Option<PositionError>,
    /// Samples read (the length of the shortest per-sample slice).
    pub samples: usize,
}

impl Localisation {
    /// The top region when it holds the residual (see [`RegionShare::holds_residual`]).
    pub fn dominant(&self) -> Option<&RegionShare> {
        self.regions.first().filter(|r| r.holds_residual())
    }

    /// Whether the residual concentrates after the voltage steps and their
    /// timing explains it (see [`EdgeTiming`]).
    pub fn is_edge_timing(&self) -> bool {
        self.dominant()
            .is_some_and(|r| r.region == Region::AfterVoltageSteps)
            && self.edge_timing.explains()
    }

    /// The stretches to mark on a residual plot, as (start [s], end [s], label):
    /// the spans of the dominant region, labelled with the region, then the
    /// worst windows, labelled "largest residual".
    pub fn marked_windows(&self) -> Vec<(f64, f64, String)> {
        let region = self.dominant().into_iter().flat_map(|r| {
            r.spans
                .iter()
                .map(|&(a, b)| (a, b, r.region.phrase().to_string()))
        });
        let worst = self
            .worst
            .iter()
            .map(|w| (w.start, w.end, "largest residual".to_string()));
        region.chain(worst).collect()
    }
}

impl fmt::Display for Localisation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "current residual: {:.4} A RMS", self.rms)?;
        match self.dominant() {
            Some(r) => writeln!(
                f,
                "{} % of the residual falls in {} % of the time, {} ({:.1}× its share; τ ≈ {:.2} ms from the data)",
                pct(r.residual_share),
                pct(r.time_share),
                r.region,
                r.concentration,
                self.tau * 1e3
            )?,
            None => writeln!(
                f,
                "the residual is spread over the record: no region holds it beyond its share of the time"
            )?,
        }
        let list: Vec<String> = self
            .regions
            .iter()
            .map(|r| {
                format!(
                    "{} {} %/{} %",
                    r.region,
                    pct(r.residual_share),
                    pct(r.time_share)
                )
            })
            .collect();
        writeln!(
            f,
            "regions (residual/time; regions overlap): {}",
            list.join(", ")
        )?;
        if self.is_edge_timing() {
            writeln!(
                f,
                "edge timing: after {} of {} voltage steps the residual stays within what half a sample of \
                 volt-seconds explains (a step placed off its instant between samples), not a cause of the model",
                self.edge_timing.within, self.edge_timing.steps
            )?;
        }
        self.fmt_worst(f)?;
        writeln!(f, "{}", self.drift)?;
        if let Some(p) = self.position {
            let of_stroke = if p.stroke > 0.0 {
                p.rms / p.stroke
            } else {
                0.0
            };
            writeln!(
                f,
                "position: off by {:.0} µm RMS ({} % of the stroke)",
                p.rms * 1e6,
                pct(of_stroke)
            )?;
        }
        Ok(())
    }
}

impl Localisation {
    fn fmt_worst(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.worst.is_empty() {
            return Ok(());
        }
        let list: Vec<String> = self
            .worst
            .iter()
            .map(|w| {
                let place = w.region.map_or(String::new(), |r| format!("{r}, "));
                format!(
                    "{:.1}–{:.1} ms ({place}{} % of the residual)",
                    w.start * 1e3,
                    w.end * 1e3,
                    pct(w.residual_share)
                )
            })
            .collect();
        writeln!(f, "worst: {}", list.join("; "))
    }
}
