//! The emitted UKFs on a Jiles–Atherton core over 10⁶ samples (50 s at
//! 20 kHz), the runtime's `observe::Ukf` on the emitted model [JA 84–87]:
//!
//! - the Jiles–Atherton valve's (`reldesign_generated::jiles_atherton_valve::ukf`:
//!   the paper's Euler step, its core's clamp [JA 52]) on the valve;
//! - the sensorless design at 20 kHz (`tests/data/sensorless-ja-valve.toml`,
//!   emitted by `tests/build.rs`: the exponential flux step with 4 substeps,
//!   the reversal rule "reversible") on its plant, the perfect-tracking valve
//!   with the paper's Jiles–Atherton core (`tests/src/sensorless.rs`).
//!
//! The plant is the valve's hybrid model (the designer's simulator), driven
//! open loop by a one-second cycle repeated 50 times: rest, a 24 V pulse
//! that closes the valve, a −24 V pulse that pulls the flux down, the
//! opening and its bounces, a long rest at 0 V, a 6 V pulse too weak to move
//! the armature, and rest again; each cycle starts where the last one ended
//! (the core's remanence carries over). Most of the time the valve rests at
//! u = 0 with i ≈ 0, where the current [JA 41] sees the core's MMF
//! L_c·H_c + R_gap·φ but not φ and H_c apart: the two become nearly
//! collinear in the covariance (correlation → −1), which is what can break
//! a filter's algebra after many samples. The filter reads the applied
//! voltage and the current with the example's noise (σ_v = 15 mV,
//! σ_i = 1 mA, seeded).
//!
//! f64, in CI (10⁶ samples take about a second with the test profile's
//! opt-level 2): at every sample the posterior covariance is finite,
//! symmetric to 1e-12 of √(Pᵢᵢ·Pⱼⱼ) (in fact exactly) and has a Cholesky
//! factor (positive definite), the estimate is finite, and at rest (from
//! 100 ms into each cycle) |ẑ − z| ≤ 1 µm; the filter never repairs a
//! factorisation, restarts or skips a sample; no variance peaks above
//! twice its peak in the first cycle (no drift: the cycles' peaks stay
//! within −25 %/+15 % of the first's).
//!
//! f32 passes the same checks on the example's filter, which estimates the
//! coil resistance too ([z, z_prev, φ, H_c, R]). On the paper's four states
//! it did not (commit d05d4e5): at rest the φ–H_c block lost positive
//! definiteness in f32 (correlation computed beyond −1) and the repairs
//! cascaded, about 55 a second, with 2–4 garbage estimates per cycle.

use designer::description::{parse_file, Description};
use designer::model::{Model, ModelPlant};
use designer::random::SplitMix64;
use designer::replay::rest_state;
use designer::sim::{simulate, Mode, Options, PiecewiseLinear, State};
use reldesign_generated::jiles_atherton_valve::ukf;
use reldesign_tests::sensorless::mismatched_plant;
use support::example_path;

/// The sensorless design at 20 kHz, emitted by `tests/build.rs`.
#[allow(dead_code)] // the test uses the filters only
mod sensorless_ja_valve {
    include!(concat!(env!("OUT_DIR"), "/sensorless_ja_valve.rs"));
}

/// T_s [s] of both filters.
const T_S: f64 = ukf::f64::T_S;
/// Samples per cycle: 1 s at T_s = 50 µs.
const CYCLE: usize = 20_000;
/// The filter's states [z, z_prev, φ, H_c, R].
const N: usize = 5;
/// From this sample of a cycle on (100 ms) the valve rests at z_max.
const REST: usize = 2_000;
/// Cycles of the runs: 10⁶ samples.
const CYCLES: usize = 50;

/// One cycle of the plant: the input u held over the sample ending at each
/// t_k (what the filter reads as applied), the true current at t_k and the
/// true position.
struct Cycle {
    u: Vec<f64>,
    i: Vec<f64>,
    z: Vec<f64>,
}

/// The plant simulated cycle after cycle, each from the state the last
/// ended in.
struct Plant {
    model: Model,
    state: State,
}

impl Plant {
    fn new(d: &Description) -> Plant {
        let model = Model::build(d);
        let state = rest_state(&model);
        Plant { model, state }
    }

    fn z_max(&self) -> f64 {
        self.model.description.mechanics.z_max
    }

    fn cycle(&mut self) -> Cycle {
        // switching just after a sample: the input at t_k is the one held
        // over the sample ending there, and the current at t_k the one
        // before the switch
        let k = |t: f64| (t / T_S).round() * T_S * (1.0 + 1e-9);
        let input = PiecewiseLinear::steps(&[
            (0.0, 0.0),
            (k(20e-3), 24.0),
            (k(26e-3), 0.0),
            (k(30e-3), -24.0),
            (k(30.4e-3), 0.0),
            (k(500e-3), 6.0),
            (k(503e-3), 0.0),
        ])
        .unwrap();
        let times: Vec<f64> = (1..=CYCLE).map(|k| k as f64 * T_S).collect();
        let plant = ModelPlant::new(&mut self.model);
        let opts = Options {
            rtol: 1e-10,
            ..Options::default()
        };
        let tr = simulate(&plant, &input, self.state, Mode::StuckMax, &times, &opts)
            .unwrap_or_else(|e| panic!("{e}"));
        let (i, _) = plant.currents_and_voltages(&tr.t, &tr.x, &tr.u);
        let z = tr.component(0);
        assert!(
            z.iter().any(|&z| z == 0.0),
            "the 24 V pulse closes the valve"
        );
        let z_max = self.z_max();
        assert!(
            z[REST..].iter().all(|&z| z == z_max),
            "the valve rests open from 100 ms on"
        );
        self.state = *tr.x.last().unwrap();
        Cycle { u: tr.u, i, z }
    }
}

/// The emitted filter in either float, seen in f64.
trait Filter {
    /// The estimate [z, v, a, φ, H_c] after the sample (u, i).
    fn step(&mut self, u: f64, i: f64) -> [f64; 5];
    fn covariance(&self) -> [[f64; N]; N];
    /// (repairs and restarts, skipped updates).
    fn counts(&self) -> (u32, u32);
}

macro_rules! filter {
    ($filter:ty, $f:ty) => {
        impl Filter for $filter {
            fn step(&mut self, u: f64, i: f64) -> [f64; 5] {
                // the f32 filter reads the samples as its ADC would
                #[allow(clippy::unnecessary_cast)]
                let e = <$filter>::step(self, u as $f, i as $f);
                let hc = e.hc.unwrap_or(<$f>::NAN);
                [e.z, e.v, e.a, e.phi, hc].map(f64::from)
            }
            fn covariance(&self) -> [[f64; N]; N] {
                <$filter>::covariance(self).map(|row| row.map(f64::from))
            }
            fn counts(&self) -> (u32, u32) {
                (self.repairs(), self.skipped())
            }
        }
    };
}
filter!(ukf::f64::Filter, f64);
filter!(ukf::f32::Filter, f32);
filter!(sensorless_ja_valve::ukf::f64::Filter, f64);
filter!(sensorless_ja_valve::ukf::f32::Filter, f32);

/// Lower Cholesky factor exists (P is positive definite).
fn positive_definite(p: &[[f64; N]; N]) -> bool {
    let mut l = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..=i {
            let mut s = p[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            if i == j {
                if !(s > 0.0) {
                    return false;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    true
}

/// The largest |Pᵢⱼ − Pⱼᵢ| / √(Pᵢᵢ·Pⱼⱼ).
fn asymmetry(p: &[[f64; N]; N]) -> f64 {
    let mut worst = 0.0f64;
    for i in 0..N {
        for j in 0..i {
            worst = worst.max((p[i][j] - p[j][i]).abs() / (p[i][i] * p[j][j]).sqrt());
        }
    }
    worst
}

/// Runs `filter` over [`CYCLES`] cycles of `plant` and checks it at every
/// sample (see the module docs).
fn long_run(mut filter: impl Filter, plant: &Description) {
    let mut plant = Plant::new(plant);
    let mut noise = SplitMix64::new(0x4A_11FE);
    let (sigma_v, sigma_i) = (15e-3, 1e-3);
    let (mut worst_asym, mut worst_rest) = (0.0f64, 0.0f64);
    let mut first_peak = [0.0f64; N];
    for c in 0..CYCLES {
        let cycle = plant.cycle();
        let mut peak = [0.0f64; N];
        for k in 0..CYCLE {
            let u = cycle.u[k] + sigma_v * noise.normal();
            let i = cycle.i[k] + sigma_i * noise.normal();
            let e = filter.step(u, i);
            let p = filter.covariance();
            let at = || {
                format!(
                    "cycle {c}, sample {k} ({:?}): {e:?}, P = {p:?}",
                    filter.counts()
                )
            };
            assert!(p.iter().flatten().all(|x| x.is_finite()), "{}", at());
            let asym = asymmetry(&p);
            worst_asym = worst_asym.max(asym);
            assert!(asym <= 1e-12, "asymmetry {asym:e} at {}", at());
            assert!(positive_definite(&p), "not positive definite at {}", at());
            assert!(e.iter().all(|x| x.is_finite()), "{}", at());
            if k >= REST {
                let dz = (e[0] - cycle.z[k]).abs();
                worst_rest = worst_rest.max(dz);
                assert!(dz <= 1e-6, "|ẑ − z| = {dz:e} m at rest at {}", at());
            }
            for (m, i) in peak.iter_mut().zip(0..N) {
                *m = m.max(p[i][i]);
            }
        }
        assert_eq!(filter.counts(), (0, 0), "repairs, skipped after cycle {c}");
        if c == 0 {
            first_peak = peak;
        }
        for ((name, now), first) in ["z", "z_prev", "φ", "H_c", "R"]
            .iter()
            .zip(peak)
            .zip(first_peak)
        {
            assert!(
                now <= 2.0 * first,
                "cycle {c}: the variance of {name} peaks at {now:e}, in the first at {first:e}"
            );
        }
    }
    eprintln!(
        "{} samples: asymmetry <= {worst_asym:e}, |ẑ − z| at rest <= {worst_rest:e} m, \
         peak variances in the first cycle {first_peak:?}",
        CYCLES * CYCLE
    );
}

fn ja_valve() -> Description {
    parse_file(&example_path("jiles-atherton-valve.toml")).unwrap()
}

#[test]
fn the_f64_ukf_stays_positive_definite_over_1e6_samples() {
    long_run(ukf::f64::Filter::new(), &ja_valve());
}

#[test]
fn the_f32_ukf_stays_positive_definite_over_1e6_samples() {
    long_run(ukf::f32::Filter::new(), &ja_valve());
}

#[test]
fn the_exponential_step_f64_ukf_stays_positive_definite_over_1e6_samples() {
    assert_eq!(sensorless_ja_valve::ukf::f64::T_S, T_S);
    let filter = sensorless_ja_valve::ukf::f64::Filter::new();
    long_run(filter, &mismatched_plant(1.0, 1.0));
}

#[test]
fn the_exponential_step_f32_ukf_stays_positive_definite_over_1e6_samples() {
    let filter = sensorless_ja_valve::ukf::f32::Filter::new();
    long_run(filter, &mismatched_plant(1.0, 1.0));
}
