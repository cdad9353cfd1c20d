//! Where the current residual of a replay concentrates.
//!
//! `reldesign diagnose` replays the measured voltage through the model; this
//! module says *where in time* the simulated current departs from the measured
//! one, in the terms each cause is recognised by: right after voltage steps
//! (eddy currents), during motion (fringing), after impacts (bouncing), at high
//! flux (saturation, hysteresis), in steady intervals, and as a growth from
//! cycle to cycle (resistance drift). It reads plain slices only, so it depends
//! on nothing but the data and the replay.
//!
//! Definitions (the residual is r = i_sim − i_meas, sample by sample):
//! - **voltage step**: sample k with |v_k − v_{k−3}| > 20 % of the voltage range
//!   (max v − min v); a run of such samples is one step, at its first sample
//!   (the lag of 3 samples lets a step slew over a few samples).
//! - **electrical time constant τ**: for each step, the time the measured current
//!   takes to cover 1 − 1/e of its way to the value it settles at before the next
//!   step (the mean of the segment's last quarter); the median over the steps
//!   whose excursion stands above 5 × the noise of that last quarter. Without
//!   such a step, τ is 1 % of the record.
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
//! more than 1; `Steady` is the complement of the union of the others. Samples
//! whose residual is not finite are left out of every sum.
//!
//! Regions are ranked by their *excess*, residual share − time share: the part
//! of the residual a region holds beyond what its duration explains. Unlike the
//! concentration alone, the excess does not favour a small subset of the region
//! that really holds the residual. The top region is named as holding the
//! residual when its concentration (residual share / time share) is at least
//! 1.5 and its excess at least 15 %. Each region also reports its share of
//! Σ |φ̇| r², the numerator of the [JA 81] error the diagnosis ranks by.
//!
//! **Edge timing**: a voltage step falls anywhere inside its sample interval;
//! where the replay places it off by δ, the current right after it is off by
//! about the current's slope change × δ, at most half a sample's worth:
//! ½·|(i_{k+1} − i_k) − (i_{k−1} − i_{k−2})| for the step's first sample k.
//! A step is *within timing* when the residual over its first
//! [`TIMING_SAMPLES`] samples stays below that bound plus 3 σ of the current
//! noise ([`super::rank::noise_std`]: the median absolute second difference).
//! When the residual concentrates after the steps and at least 80 % of them
//! are within timing, the report says the error is edge timing, not a cause.
//!
//! **Drift**: cycles start at the voltage's rising edges (a Schmitt trigger at
//! 40 % / 60 % of the range) and run to the next one (the record's last cycle
//! counts when complete); the RMS residual of each cycle is fitted by a
//! least-squares line over the cycle index. The drift is significant when there
//! are at least 3 cycles, the line explains most of the cycle-to-cycle variation
//! (R² ≥ 0.5), and the fitted change over the record exceeds 10 % of the fitted
//! first value (white measurement noise moves a cycle's RMS by about
//! 1/√(2 · samples per cycle), far below that).

use std::fmt;

/// Threshold of a voltage step, as a fraction of the voltage range.
const STEP_FRACTION: f64 = 0.2;
/// Samples over which a step may slew and still count as one step.
const STEP_LAG: usize = 3;
/// A step's current excursion must exceed this many noise deviations to time τ.
const STEP_SNR: f64 = 5.0;
/// τ when no step settles visibly, as a fraction of the record's duration.
const FALLBACK_TAU_FRACTION: f64 = 0.01;
/// Time constants after a step or an impact that belong to it.
const SETTLING_TAUS: f64 = 3.0;
/// Fraction of max |φ_sim| above which the flux is high.
const HIGH_FLUX: f64 = 0.7;
/// Schmitt-trigger levels of the rising edges, as fractions of the range.
const EDGE_LOW: f64 = 0.4;
const EDGE_HIGH: f64 = 0.6;
/// Drift significance: minimum cycles, R² and relative change.
const DRIFT_MIN_CYCLES: usize = 3;
const DRIFT_MIN_R2: f64 = 0.5;
const DRIFT_MIN_CHANGE: f64 = 0.1;
/// The record's last cycle counts when it has this fraction of the median length.
const LAST_CYCLE_FRACTION: f64 = 0.95;
/// A region holds the residual when its concentration and excess reach these.
const DOMINANT_CONCENTRATION: f64 = 1.5;
const DOMINANT_EXCESS: f64 = 0.15;
/// Samples after a step whose residual edge timing may explain.
const TIMING_SAMPLES: usize = 3;
/// Fraction of the steps within timing for the report to blame the timing.
const TIMING_SHARE: f64 = 0.8;
/// The record is cut into this many windows; the worst few are reported.
const WINDOWS: usize = 50;
const WORST: usize = 3;

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

/// A part of the record where a cause shows (see the module documentation).
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
    /// See the module documentation.
    pub significant: bool,
}

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

/// The simulated position against the measured one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionError {
    /// RMS of z_sim − z_meas [m].
    pub rms: f64,
    /// Range of the simulated position [m] (the stroke when the armature moves).
    pub stroke: f64,
}

/// How many voltage steps have a residual within what their timing explains.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeTiming {
    /// Steps with samples on both sides to judge.
    pub steps: usize,
    /// Steps whose residual stays within the edge-timing bound.
    pub within: usize,
}

impl EdgeTiming {
    /// Whether at least 80 % of the steps are within timing.
    pub fn explains(&self) -> bool {
        self.steps > 0 && self.within as f64 >= TIMING_SHARE * self.steps as f64
    }
}

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
    /// timing explains it (see the module documentation).
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

/// Min and max of the finite values (0, 0 when there is none).
fn range(x: &[f64]) -> (f64, f64) {
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

/// Indices of the voltage steps (first sample of each run over the threshold).
fn voltage_steps(v: &[f64]) -> Vec<usize> {
    let (lo, hi) = range(v);
    let threshold = STEP_FRACTION * (hi - lo);
    let over = |k: usize| k >= 1 && (v[k] - v[k.saturating_sub(STEP_LAG)]).abs() > threshold;
    (1..v.len())
        .filter(|&k| threshold > 0.0 && over(k) && !over(k - 1))
        .collect()
}

/// The median settling time constant over the steps, or the fallback.
fn electrical_tau(t: &[f64], i: &[f64], steps: &[usize]) -> f64 {
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

fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len().max(1) as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

fn median(x: &mut [f64]) -> Option<f64> {
    x.sort_by(f64::total_cmp);
    match x.len() {
        0 => None,
        n if n % 2 == 1 => Some(x[n / 2]),
        n => Some(0.5 * (x[n / 2 - 1] + x[n / 2])),
    }
}

/// The mask of every region, `Steady` last (the complement of the others).
fn region_masks(s: &Signals, step_times: &[f64], tau: f64) -> Vec<(Region, Vec<bool>)> {
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
fn share(region: Region, mask: &[bool], sums: &Sums, t: &[f64]) -> RegionShare {
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

/// The `WORST` windows with the largest Σ r², adjacent ones merged.
fn worst_windows(
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

/// The steps (first samples after each) whose residual stays within the
/// edge-timing bound (see the module documentation).
fn edge_timing(i: &[f64], r: &[f64], steps: &[usize]) -> EdgeTiming {
    let sigma = super::rank::noise_std(i);
    let judged: Vec<bool> = steps
        .iter()
        .filter(|&&k| k >= 2 && k + TIMING_SAMPLES < i.len())
        .map(|&k| {
            let bound = 0.5 * ((i[k + 1] - i[k]) - (i[k - 1] - i[k - 2])).abs() + 3.0 * sigma;
            r[k..k + TIMING_SAMPLES]
                .iter()
                .all(|x| x.is_finite() && x.abs() <= bound)
        })
        .collect();
    EdgeTiming {
        steps: judged.len(),
        within: judged.iter().filter(|&&b| b).count(),
    }
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
fn drift(t: &[f64], v: &[f64], sums: &Sums) -> Drift {
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

fn position_error(z_sim: &[f64], z_meas: &[f64]) -> PositionError {
    let d: Vec<f64> = z_sim
        .iter()
        .zip(z_meas)
        .map(|(a, b)| a - b)
        .filter(|d| d.is_finite())
        .collect();
    let (lo, hi) = range(z_sim);
    PositionError {
        rms: (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt(),
        stroke: hi - lo,
    }
}

fn pct(x: f64) -> f64 {
    (100.0 * x).round()
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
    use super::*;

    /// A deterministic Gaussian noise source (xorshift + Box–Muller).
    struct Noise(u64);

    impl Noise {
        fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        fn gauss(&mut self) -> f64 {
            let (u, v) = (self.uniform(), self.uniform());
            (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
        }
    }

    const DT: f64 = 25e-6; // 40 kHz
    const PERIOD: f64 = 20e-3;
    const FIRST_RISE: f64 = 5e-3;
    const ON: f64 = 10e-3;
    const TAU: f64 = 1e-3;
    const CYCLES: usize = 5;
    const MOTION: (f64, f64) = (2e-3, 4e-3);

    /// Five full cycles of a 0/24 V square wave (on 10 ms of every 20 ms, first
    /// rise at 5 ms) into a first-order coil (τ = 1 ms, R = 12 Ω), with motion
    /// 2–4 ms and an impact 4 ms after each rising edge.
    struct Bench {
        t: Vec<f64>,
        v: Vec<f64>,
        i: Vec<f64>,
        /// Time since the last rising edge (infinite before the first).
        since_rise: Vec<f64>,
        /// Time since the last voltage step (infinite before the first).
        since_step: Vec<f64>,
        /// Index of the current cycle (0 before the first edge).
        cycle: Vec<usize>,
        moving: Vec<bool>,
        impacts: Vec<f64>,
        flux: Vec<f64>,
    }

    /// Time since the last event at or before `t`.
    fn since(t: f64, events: &[f64]) -> f64 {
        events
            .iter()
            .rfind(|&&e| e <= t + 1e-12)
            .map_or(f64::INFINITY, |e| t - e)
    }

    fn bench() -> Bench {
        let n = ((FIRST_RISE + CYCLES as f64 * PERIOD) / DT).round() as usize;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
        let rises: Vec<f64> = (0..CYCLES)
            .map(|c| FIRST_RISE + c as f64 * PERIOD)
            .collect();
        let mut steps: Vec<f64> = rises.iter().flat_map(|&r| [r, r + ON]).collect();
        steps.retain(|&s| s < t[n - 1]);
        let since_rise: Vec<f64> = t.iter().map(|&x| since(x, &rises)).collect();
        let v: Vec<f64> = since_rise
            .iter()
            .map(|&s| if s < ON { 24.0 } else { 0.0 })
            .collect();
        // Exact discretisation of L di/dt = v − R i under a zero-order hold.
        let decay = (-DT / TAU).exp();
        let mut i = vec![0.0; n];
        for k in 1..n {
            i[k] = v[k] / 12.0 + (i[k - 1] - v[k] / 12.0) * decay;
        }
        Bench {
            since_step: t.iter().map(|&x| since(x, &steps)).collect(),
            cycle: t
                .iter()
                .map(|&x| rises.iter().filter(|&&r| r <= x).count().max(1) - 1)
                .collect(),
            moving: since_rise
                .iter()
                .map(|&s| s >= MOTION.0 && s < MOTION.1)
                .collect(),
            impacts: rises.iter().map(|r| r + MOTION.1).collect(),
            flux: i.iter().map(|x| 1e-4 * x).collect(),
            t,
            v,
            i,
            since_rise,
        }
    }

    /// Localise `i_sim = i + planted + white noise` (σ = 10 mA), weight 1
    /// everywhere.
    fn run(b: &Bench, planted: impl Fn(usize) -> f64) -> Localisation {
        run_with_noise(b, planted, 0.01)
    }

    fn run_with_noise(b: &Bench, planted: impl Fn(usize) -> f64, sigma: f64) -> Localisation {
        let mut noise = Noise(0x9E37_79B9_7F4A_7C15);
        let i_sim: Vec<f64> = (0..b.t.len())
            .map(|k| b.i[k] + planted(k) + sigma * noise.gauss())
            .collect();
        let ones = vec![1.0; b.t.len()];
        let zeros = vec![0.0; b.t.len()];
        localise(&Signals {
            t: &b.t,
            v: &b.v,
            i_measured: &b.i,
            i_simulated: &i_sim,
            weight: &ones,
            z_simulated: &zeros,
            moving: &b.moving,
            impacts: &b.impacts,
            flux_simulated: &b.flux,
            z_measured: None,
        })
    }

    /// The dominant region; a residual planted alike in every cycle must not drift.
    fn top(l: &Localisation) -> Region {
        assert!(!l.drift.significant, "{}", l.drift);
        l.dominant().map(|r| r.region).expect("a dominant region")
    }

    #[test]
    fn time_constant_is_read_from_the_current() {
        let l = run(&bench(), |_| 0.0);
        assert!((l.tau - TAU).abs() < 0.05 * TAU, "tau = {}", l.tau);
        assert_eq!(l.steps.len(), 2 * CYCLES);
    }

    #[test]
    fn residual_after_steps_is_named() {
        let b = bench();
        let l = run(&b, |k| 0.3 * (-b.since_step[k] / (0.3 * TAU)).exp());
        assert_eq!(top(&l), Region::AfterVoltageSteps, "{l}");
        assert!(l.to_string().contains("after voltage steps"));
        // 0.3 A is far beyond what a step's timing explains (≈ 25 mA here).
        assert!(!l.is_edge_timing(), "{l}");
    }

    /// A replay whose steps are 0.4 sample late: the current lags by the
    /// slope change × 0.4·Δ after each step, decaying with τ.
    #[test]
    fn residual_of_steps_placed_off_their_instant_is_edge_timing() {
        let b = bench();
        // Slope change at a step: ±(24 V / 12 Ω)/τ.
        let lag = 0.4 * DT * 2.0 / TAU;
        let l = run_with_noise(
            &b,
            |k| {
                let sign = if b.v[k] > 12.0 { -1.0 } else { 1.0 };
                sign * lag * (-b.since_step[k] / TAU).exp()
            },
            0.002,
        );
        assert_eq!(top(&l), Region::AfterVoltageSteps, "{l}");
        assert!(l.is_edge_timing(), "{:?}\n{l}", l.edge_timing);
        assert!(l.to_string().contains("edge timing"), "{l}");
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

    #[test]
    fn line_fit_recovers_a_line() {
        let (a, b, r2) = line_fit(&[1.0, 3.0, 5.0, 7.0]);
        assert_eq!((a, b, r2), (1.0, 2.0, 1.0));
        assert_eq!(line_fit(&[2.0, 2.0, 2.0]).2, 0.0);
    }

    #[test]
    fn measured_position_is_compared() {
        let b = bench();
        let n = b.t.len();
        let z_sim: Vec<f64> = (0..n)
            .map(|k| if b.moving[k] { 1e-4 } else { 5e-4 })
            .collect();
        let z_meas: Vec<f64> = z_sim.iter().map(|z| z + 2e-5).collect();
        let ones = vec![1.0; n];
        let l = localise(&Signals {
            t: &b.t,
            v: &b.v,
            i_measured: &b.i,
            i_simulated: &b.i,
            weight: &ones,
            z_simulated: &z_sim,
            moving: &b.moving,
            impacts: &b.impacts,
            flux_simulated: &b.flux,
            z_measured: Some(&z_meas),
        });
        let p = l.position.unwrap();
        assert!((p.rms - 2e-5).abs() < 1e-12 && (p.stroke - 4e-4).abs() < 1e-12);
        assert!(l.to_string().contains("5 % of the stroke"), "{l}");
    }
}
