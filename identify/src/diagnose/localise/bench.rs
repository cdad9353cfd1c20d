//! The test bench of the localisation's tests: a square-wave drive into a
//! first-order coil with motion and impacts, and a residual planted on it.

use super::{localise, Localisation, Region, Signals};

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

pub(super) const DT: f64 = 25e-6; // 40 kHz
const PERIOD: f64 = 20e-3;
pub(super) const FIRST_RISE: f64 = 5e-3;
const ON: f64 = 10e-3;
pub(super) const TAU: f64 = 1e-3;
pub(super) const CYCLES: usize = 5;
pub(super) const MOTION: (f64, f64) = (2e-3, 4e-3);

/// Five full cycles of a 0/24 V square wave (on 10 ms of every 20 ms, first
/// rise at 5 ms) into a first-order coil (τ = 1 ms, R = 12 Ω), with motion
/// 2–4 ms and an impact 4 ms after each rising edge.
pub(super) struct Bench {
    pub(super) t: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) i: Vec<f64>,
    /// Time since the last rising edge (infinite before the first).
    pub(super) since_rise: Vec<f64>,
    /// Time since the last voltage step (infinite before the first).
    pub(super) since_step: Vec<f64>,
    /// Index of the current cycle (0 before the first edge).
    pub(super) cycle: Vec<usize>,
    pub(super) moving: Vec<bool>,
    pub(super) impacts: Vec<f64>,
    pub(super) flux: Vec<f64>,
}

/// Time since the last event at or before `t`.
fn since(t: f64, events: &[f64]) -> f64 {
    events
        .iter()
        .rfind(|&&e| e <= t + 1e-12)
        .map_or(f64::INFINITY, |e| t - e)
}

pub(super) fn bench() -> Bench {
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
pub(super) fn run(b: &Bench, planted: impl Fn(usize) -> f64) -> Localisation {
    run_with_noise(b, planted, 0.01)
}

pub(super) fn run_with_noise(
    b: &Bench,
    planted: impl Fn(usize) -> f64,
    sigma: f64,
) -> Localisation {
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
pub(super) fn top(l: &Localisation) -> Region {
    assert!(!l.drift.significant, "{}", l.drift);
    l.dominant().map(|r| r.region).expect("a dominant region")
}
