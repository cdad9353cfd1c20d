//! Where the current residual of a replay concentrates.
//!
//! `reldesign diagnose` replays the measured voltage through the model; this
//! module says *where in time* the simulated current departs from the measured
//! one, in the terms each cause is recognised by: right after voltage steps
//! (eddy currents), during motion (fringing), after impacts (bouncing), at high
//! flux (saturation, hysteresis), in steady intervals, and as a growth from
//! cycle to cycle (resistance drift). It reads plain slices only, so it depends
//! on nothing but the data and the replay. The residual is r = i_sim − i_meas,
//! sample by sample; samples whose residual is not finite are left out of
//! every sum.
//!
//! - `steps.rs`: the voltage steps and the electrical time constant τ;
//! - `regions.rs`: the regions, their shares of time and residual, the ranking;
//! - `windows.rs`: the stretches of the record with the largest residual;
//! - `timing.rs`: whether the edges' timing explains the residual after steps;
//! - `drift.rs`: the growth of the residual from cycle to cycle;
//! - `position.rs`: the simulated position against a measured one;
//! - `report.rs`: the [`Localisation`] and how it reads;
//! - `stats.rs`: range, mean, deviation and median of a signal; a share in
//!   whole percent.

mod drift;
mod position;
mod regions;
mod report;
mod stats;
mod steps;
mod timing;
mod windows;

#[cfg(test)]
mod bench;

pub use drift::Drift;
pub use position::PositionError;
pub use regions::{Region, RegionShare};
pub use report::Localisation;
pub use timing::EdgeTiming;
pub use windows::Window;

use drift::drift;
use position::position_error;
use regions::{region_masks, share};
use steps::{electrical_tau, voltage_steps};
use timing::edge_timing;
use windows::worst_windows;

/// The replay and the measurement, sample by sample (every per-sample slice
/// has the length of `t`; `impacts` is a list of times).
#[derive(Debug, Clone, Copy)]
pub struct Signals<'a> {
    /// Measured time [s], strictly increasing.
    pub t: &'a [f64],
    /// Measured coil voltage [V].
    pub v: &'a [f64],
    /// Measured coil current [A].
    pub i_measured: &'a [f64],
    /// Simulated coil current [A].
    pub i_simulated: &'a [f64],
    /// |φ̇| estimated from the data: the weights of [JA 81].
    pub weight: &'a [f64],
    /// Simulated position (gap length) [m].
    pub z_simulated: &'a [f64],
    /// Whether the simulated mode is free motion.
    pub moving: &'a [bool],
    /// Simulated impact times [s].
    pub impacts: &'a [f64],
    /// Simulated flux φ [Wb].
    pub flux_simulated: &'a [f64],
    /// Measured position [m], when the record has a `z` column.
    pub z_measured: Option<&'a [f64]>,
}

/// Localise the current residual of a replay.
///
/// Per-sample slices of different lengths (a replay that stopped early) are
/// read up to the shortest one; [`Localisation::samples`] says how many.
pub fn localise(s: &Signals) -> Localisation {
    let s = &common_length(s);
    let r: Vec<f64> = s
        .i_simulated
        .iter()
        .zip(s.i_measured)
        .map(|(a, b)| a - b)
        .collect();
    let valid: Vec<bool> = r.iter().map(|x| x.is_finite()).collect();
    let steps = voltage_steps(s.v);
    let tau = electrical_tau(s.t, s.i_measured, &steps);
    let step_times: Vec<f64> = steps.iter().map(|&k| s.t[k]).collect();
    let masks = region_masks(s, &step_times, tau);
    let sums = Sums::new(&r, s.weight, &valid);
    let mut regions: Vec<RegionShare> = masks
        .iter()
        .map(|(region, mask)| share(*region, mask, &sums, s.t))
        .collect();
    regions.sort_by(|a, b| b.excess().total_cmp(&a.excess()));
    let worst = worst_windows(s.t, &sums, &regions, &masks);
    Localisation {
        edge_timing: edge_timing(s.i_measured, &r, &steps),
        drift: drift(s.t, s.v, &sums),
        rms: (sums.total_r2 / sums.count.max(1) as f64).sqrt(),
        position: s.z_measured.map(|z| position_error(s.z_simulated, z)),
        regions,
        worst,
        tau,
        steps: step_times,
        samples: s.t.len(),
    }
}

/// The signals cut to the length of the shortest per-sample slice.
fn common_length<'a>(s: &Signals<'a>) -> Signals<'a> {
    let n = [
        s.t.len(),
        s.v.len(),
        s.i_measured.len(),
        s.i_simulated.len(),
        s.weight.len(),
        s.z_simulated.len(),
        s.moving.len(),
        s.flux_simulated.len(),
        s.z_measured.map_or(usize::MAX, <[f64]>::len),
    ]
    .into_iter()
    .min()
    .unwrap_or(0);
    Signals {
        t: &s.t[..n],
        v: &s.v[..n],
        i_measured: &s.i_measured[..n],
        i_simulated: &s.i_simulated[..n],
        weight: &s.weight[..n],
        z_simulated: &s.z_simulated[..n],
        moving: &s.moving[..n],
        impacts: s.impacts,
        flux_simulated: &s.flux_simulated[..n],
        z_measured: s.z_measured.map(|z| &z[..n]),
    }
}

/// Per-sample squared residuals and their totals.
struct Sums {
    /// r², 0 where the residual is not finite.
    r2: Vec<f64>,
    /// |φ̇| r², 0 where either is not finite.
    wr2: Vec<f64>,
    valid: Vec<bool>,
    total_r2: f64,
    total_wr2: f64,
    count: usize,
}

impl Sums {
    fn new(r: &[f64], w: &[f64], valid: &[bool]) -> Sums {
        let r2: Vec<f64> = r
            .iter()
            .zip(valid)
            .map(|(x, &ok)| if ok { x * x } else { 0.0 })
            .collect();
        let wr2: Vec<f64> = r2
            .iter()
            .zip(w)
            .map(|(e, w)| if w.is_finite() { w.abs() * e } else { 0.0 })
            .collect();
        Sums {
            total_r2: r2.iter().sum(),
            total_wr2: wr2.iter().sum(),
            count: valid.iter().filter(|&&ok| ok).count(),
            r2,
            wr2,
            valid: valid.to_vec(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::bench::bench;
    use super::*;

    #[test]
    fn a_short_replay_is_read_up_to_its_end() {
        let b = bench();
        let n = b.t.len();
        let ones = vec![1.0; n];
        let short = &b.i[..n / 2];
        let l = localise(&Signals {
            t: &b.t,
            v: &b.v,
            i_measured: &b.i,
            i_simulated: short,
            weight: &ones,
            z_simulated: &ones,
            moving: &b.moving,
            impacts: &b.impacts,
            flux_simulated: &b.flux,
            z_measured: None,
        });
        assert_eq!((l.samples, l.rms), (n / 2, 0.0));
        assert!(l.dominant().is_none());
        let empty = localise(&Signals {
            i_simulated: &[],
            ..Signals {
                t: &b.t,
                v: &b.v,
                i_measured: &b.i,
                i_simulated: short,
                weight: &ones,
                z_simulated: &ones,
                moving: &b.moving,
                impacts: &b.impacts,
                flux_simulated: &b.flux,
                z_measured: Some(&ones),
            }
        });
        assert_eq!(empty.samples, 0);
        assert!(empty.to_string().contains("drift not assessed"));
    }
}
