//! Sensorless soft landing (issue: observers §3): the generated observer and
//! the generated feedback-linearizing controller, measuring only the coil
//! voltage and current, against a plant that differs from the design model:
//! a Jiles–Atherton core where the design assumed the saturating one, and
//! ±10 % on k_s and R. Compared with the sensor-based controller on the same
//! plant and with uncontrolled 24 V / 0 V switching (the papers' baseline).
//!
//! The design is `tests/data/sensorless-valve.toml`: the example's valve and
//! trajectories with a slower tracking loop (2.5 ms settling instead of 1 ms).
//! With the example's 1 ms loop the observer's velocity, a difference quotient
//! of estimated positions [JA 84–85], drives u into the ±24 V limits and the
//! loop oscillates (measured); the slower loop is the sensorless design.

use designer::description::Description;
use designer::model::{Model, ModelPlant};
use designer::observe::discrete::{DiscreteModel, ResistanceSettings};
use designer::sim::{simulate_sampled, Event, Limit, Measurement, Mode, Options, State};
/// The sensorless design: `tests/data/sensorless-valve.toml` (the
/// perfect-tracking valve with a 2.5 ms settling time and EKF/UKF at 10 µs),
/// emitted by `tests/build.rs` through `reldesign_build::compile`.
#[allow(dead_code)] // the test uses the f64 code; the f32 code is checked elsewhere
mod sensorless_valve {
    include!(concat!(env!("OUT_DIR"), "/sensorless_valve.rs"));
}
use reldesign_generated::perfect_tracking_valve::f64 as example64;
use reldesign_tests::sensorless::mismatched_plant;
use reldesign_tests::{impacts, root, Rng};
use sensorless_valve::f64 as c64;

/// The first impact speed at `destination` within (after, before), NaN if
/// none, and the number of bounces there.
fn landing(events: &[Event], destination: Limit, after: f64, before: f64) -> (f64, usize) {
    let mut first = f64::NAN;
    let mut bounces = 0;
    for (v_before, v_after) in impacts(events, destination, after, before) {
        if first.is_nan() {
            first = v_before;
        }
        bounces += usize::from(v_after != 0.0);
    }
    (first, bounces)
}

/// Length of each half of the cycle: closing on [0, HALF), opening on [HALF, 2·HALF).
const HALF: f64 = 10e-3;

/// How the coil is driven.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Drive {
    /// 24 V until HALF, then 0 V.
    Uncontrolled,
    /// The example's generated controller (1 ms settling) on the true (z, v, φ).
    SensorBased,
    /// The generated controller on the estimate of an observer fed with the
    /// noisy coil voltage and current only.
    Sensorless(Filter),
}

/// The observer of a sensorless loop.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Filter {
    /// The generated f64 EKF of the sensorless design (T_s = 10 µs).
    GeneratedEkf,
    /// The generated f64 UKF of the sensorless design (T_s = 10 µs).
    GeneratedUkf,
    /// The designer's f64 reference UKF, for sample periods other than the
    /// example's (the generated f64 UKF agrees with it to 1e-13,
    /// `codegen/tests/observer.rs`).
    ReferenceUkf,
}

/// Measurement noise of the semera paper's study: σ_v = 15 mV, σ_i = 1 mA.
const SIGMA_V: f64 = 15e-3;
const SIGMA_I: f64 = 1e-3;

/// An observer: (measured voltage held over the last sample, measured
/// current now) → estimated (z, v, φ).
type Observer = Box<dyn FnMut(f64, f64) -> [f64; 3]>;

fn observer(filter: Filter, ts: f64) -> Observer {
    use sensorless_valve::{ekf, ukf};
    match filter {
        Filter::GeneratedEkf => {
            assert_eq!(ts, ekf::f64::T_S, "the generated filter's sample period");
            let mut f = ekf::f64::Filter::new();
            Box::new(move |u, i| {
                let e = f.step(u, i);
                [e.z, e.v, e.phi]
            })
        }
        Filter::GeneratedUkf => {
            assert_eq!(ts, ukf::f64::T_S, "the generated filter's sample period");
            let mut f = ukf::f64::Filter::new();
            Box::new(move |u, i| {
                let e = f.step(u, i);
                [e.z, e.v, e.phi]
            })
        }
        Filter::ReferenceUkf => {
            let d =
                designer::description::parse_file(&root().join("tests/data/sensorless-valve.toml"))
                    .unwrap_or_else(|e| panic!("{e}"));
            let o = d.observer.as_ref().expect("[observer]");
            // the example's process noise, scaled ∝ T_s as it was tuned
            let r = ts / o.sample_period;
            let mut settings = designer::observe::discrete::KalmanSettings::from_observer(o)
                .expect("[observer.kalman]");
            settings.sample_period = ts;
            settings.process_z *= r;
            settings.process_phi *= r;
            let model = Model::build(&d);
            let resistance = ResistanceSettings::from_observer(o);
            let dm = DiscreteModel::with_resistance(&model, &settings, resistance)
                .expect("filter settings");
            let mut f = designer::observe::ukf::Ukf::new(&dm);
            Box::new(move |u, i| {
                let e = f.step(u, i);
                [e.z, e.v, e.phi]
            })
        }
    }
}

/// Gaussian noise (Box–Muller on the tests' SplitMix64).
struct Noise(Rng);

impl Noise {
    fn sample(&mut self, sigma: f64) -> f64 {
        let u1 = self.0.uniform(f64::MIN_POSITIVE, 1.0);
        let u2 = self.0.uniform(0.0, 1.0);
        sigma * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Landing speeds of one closing-and-opening cycle.
#[derive(Debug, Clone, Copy)]
struct Cycle {
    closing: f64,
    opening: f64,
    bounces: usize,
}

/// The noise seed of the CI tests; the report adds [`MORE_SEEDS`].
const SEED: u64 = 0x5e9507;
const MORE_SEEDS: [u64; 4] = [1, 2, 3, 4];

/// One closing (from rest at z_max, φ = 0) and opening (started at HALF)
/// on the plant `d`, sampled every `ts`, with the measurement noise of `seed`.
fn cycle(d: &Description, ts: f64, drive: Drive, seed: u64) -> Cycle {
    let mut model = Model::build(d);
    let plant = ModelPlant::new(&mut model);
    let z_max = d.mechanics.z_max;
    let mut closing = c64::Controller::new(c64::Operation::Closing);
    let mut opening = c64::Controller::new(c64::Operation::Opening);
    opening.start(HALF);
    let mut example_closing = example64::Controller::new(example64::Operation::Closing);
    let mut example_opening = example64::Controller::new(example64::Operation::Opening);
    example_opening.start(HALF);
    let mut observe = match drive {
        Drive::Sensorless(filter) => Some(observer(filter, ts)),
        _ => None,
    };
    let mut noise = Noise(Rng::new(seed));
    let mut held = 0.0; // the voltage applied over the last sample period
    let mut control = |t: f64, m: &Measurement| -> f64 {
        let u = match drive {
            Drive::Uncontrolled => {
                if t < HALF {
                    24.0
                } else {
                    0.0
                }
            }
            Drive::SensorBased => {
                let k = if t < HALF {
                    &mut example_closing
                } else {
                    &mut example_opening
                };
                k.step(t, m.x[0], m.x[1], m.x[2])
            }
            Drive::Sensorless(_) => {
                // the ADC samples i just before the new voltage is applied
                let (i, _) = plant.current_and_voltage(t, &m.x, held);
                let (u_meas, i_meas) = (held + noise.sample(SIGMA_V), i + noise.sample(SIGMA_I));
                let [z, v, phi] = observe
                    .as_mut()
                    .map_or([f64::NAN; 3], |o| o(u_meas, i_meas));
                let k = if t < HALF { &mut closing } else { &mut opening };
                k.step(t, z, v, phi)
            }
        };
        held = u;
        u
    };
    let x0: State = [z_max, 0.0, 0.0, 0.0];
    let options = Options {
        rtol: 1e-8,
        ..Options::default()
    };
    let tr = simulate_sampled(
        &plant,
        &mut control,
        ts,
        2.0 * HALF,
        x0,
        Mode::StuckMax,
        &options,
    )
    .expect("simulation");
    let (closing_speed, b1) = landing(&tr.events, Limit::Min, 0.0, HALF);
    let (opening_speed, b2) = landing(&tr.events, Limit::Max, HALF, f64::INFINITY);
    Cycle {
        closing: closing_speed,
        opening: opening_speed,
        bounces: b1 + b2,
    }
}

#[test]
fn baseline_and_sensor_based_landing_on_the_mismatched_plant() {
    for (ks, r) in [(1.0, 1.0), (1.1, 0.9), (0.9, 1.1)] {
        for ts in [10e-6, 50e-6] {
            let Baselines {
                hard: u, sensor: s, ..
            } = Baselines::new(ks, r, ts);
            eprintln!("k_s×{ks} R×{r} Ts={ts:e}: uncontrolled {u:?} sensor-based {s:?}");
            // the mismatch costs softness, but every operation lands, far softer
            // than switching (measured: ≥ 60× at 10 µs, ≥ 60× at 50 µs)
            for (soft, hard) in [(s.closing, u.closing), (s.opening, u.opening)] {
                assert!(soft.is_finite() && hard.is_finite(), "{s:?} {u:?}");
                assert!(
                    soft * 20.0 < hard,
                    "k_s×{ks} R×{r} Ts={ts:e}: {s:?} vs {u:?}"
                );
            }
        }
    }
}

/// A mismatched plant at one sample period with its two baselines, which
/// use no measurement noise and so are the same for every seed: uncontrolled
/// switching and the sensor-based loop.
struct Baselines {
    ks: f64,
    r: f64,
    ts: f64,
    plant: Description,
    hard: Cycle,
    sensor: Cycle,
}

impl Baselines {
    fn new(ks: f64, r: f64, ts: f64) -> Baselines {
        let plant = mismatched_plant(ks, r);
        let hard = cycle(&plant, ts, Drive::Uncontrolled, SEED);
        let sensor = cycle(&plant, ts, Drive::SensorBased, SEED);
        Baselines {
            ks,
            r,
            ts,
            plant,
            hard,
            sensor,
        }
    }

    /// The sensorless loop with `filter` and the noise of `seed`, printed as
    /// one row of the report.
    fn sensorless(&self, filter: Filter, seed: u64) -> Cycle {
        let soft = cycle(&self.plant, self.ts, Drive::Sensorless(filter), seed);
        let pair = |c: &Cycle| format!("{:.2e} / {:.2e}", c.closing, c.opening);
        let ratio = |soft: f64, hard: f64| {
            if soft.is_finite() {
                format!("{:.0}×", hard / soft)
            } else {
                "no landing".to_owned()
            }
        };
        eprintln!(
            "{:>12} {:>6} {:>14} {:>8x} {:>20} {:>20} {:>20} {:>10} / {:<10} bounces {} / {}",
            format!("k×{} R×{}", self.ks, self.r),
            format!("{}µs", self.ts * 1e6),
            format!("{filter:?}"),
            seed,
            pair(&self.hard),
            pair(&self.sensor),
            pair(&soft),
            ratio(soft.closing, self.hard.closing),
            ratio(soft.opening, self.hard.opening),
            self.sensor.bounces,
            soft.bounces
        );
        soft
    }
}

fn report_header() {
    eprintln!(
        "{:>12} {:>6} {:>14} {:>8} {:>20} {:>20} {:>20} {:>23}",
        "plant",
        "Ts",
        "observer",
        "seed",
        "uncontrolled [m/s]",
        "sensor-based [m/s]",
        "sensorless [m/s]",
        "softer than switching"
    );
}

/// Measuring only v and i (noise σ_v = 15 mV, σ_i = 1 mA; the filters assume
/// σ_i = 2.5 mA, the core model's error included), the generated UKF
/// (estimating R) with the generated controller of the sensorless design
/// lands both operations at T_s = 10 µs on the Jiles–Atherton plant and with
/// ±10 % on k_s and R at least 10× softer than switching (the issue's
/// target); the generated EKF lands the closing 10× softer. Over five noise
/// seeds and the four corners see `sensorless_report`.
#[test]
fn sensorless_loop_lands_on_the_mismatched_plants() {
    // the design's `creep_speed = 5e-3` [m/s] reaches the emitted CREEP
    // [strokes/s] (1 mm stroke)
    assert!((c64::CREEP - 5.0).abs() < 1e-12, "{}", c64::CREEP);
    report_header();
    for (ks, r) in [(1.0, 1.0), (1.1, 0.9), (0.9, 1.1)] {
        let base = Baselines::new(ks, r, 10e-6);
        let hard = base.hard;
        for filter in [Filter::GeneratedUkf, Filter::GeneratedEkf] {
            let soft = base.sensorless(filter, SEED);
            let what = format!("k×{ks} R×{r} {filter:?}: {soft:?} vs {hard:?}");
            assert!(10.0 * soft.closing <= hard.closing, "{what}");
            if filter == Filter::GeneratedUkf {
                assert!(10.0 * soft.opening <= hard.opening, "{what}");
            }
        }
    }
}

/// The resistance state tracks the plant's R (oracle: the plant's own value,
/// 10 % off the design's) from v and i alone: 24 V switching on the JA plant
/// with R ×1.1, the generated f64 UKF and EKF; after 5 ms at the stop the
/// estimate is within 1 % of 82.5 Ω (it starts at the design's 75 Ω). On the
/// way the generated filters with the R state agree with the designer's
/// reference filters (≤ 1e-9 relative), and a NaN sample is skipped.
#[test]
fn resistance_state_tracks_the_plant() {
    use designer::observe::{ekf::Ekf, ukf::Ukf};
    use sensorless_valve::{ekf, ukf};
    let d = mismatched_plant(1.0, 1.1);
    let truth = d.coil.resistance;
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    let design =
        designer::description::parse_file(&root().join("tests/data/sensorless-valve.toml"))
            .unwrap_or_else(|e| panic!("{e}"));
    let o = design.observer.as_ref().expect("[observer]");
    let dm = DiscreteModel::from_observer(&Model::build(&design), o)
        .expect("[observer.kalman]")
        .expect("filter settings");
    assert_eq!(dm.resistance_index(), Some(3));
    let (mut u_ref, mut e_ref) = (Ukf::new(&dm), Ekf::new(&dm));
    let mut u_filter = ukf::f64::Filter::new();
    let mut e_filter = ekf::f64::Filter::new();
    let mut noise = Noise(Rng::new(0x7e515));
    let mut last = [f64::NAN; 2];
    let mut k = 0;
    let mut control = |t: f64, m: &Measurement| -> f64 {
        let (i, _) = plant.current_and_voltage(t, &m.x, 24.0);
        let (v, i) = (24.0 + noise.sample(SIGMA_V), i + noise.sample(SIGMA_I));
        let i = if k == 100 { f64::NAN } else { i };
        k += 1;
        let (gu, ge) = (u_filter.step(v, i), e_filter.step(v, i));
        let (ru, re) = (u_ref.step(v, i), e_ref.step(v, i));
        let r_of = |r: Option<f64>| r.unwrap_or(f64::NAN);
        for (g, r) in [
            ([gu.z, gu.v, gu.phi, r_of(gu.r)], ru),
            ([ge.z, ge.v, ge.phi, r_of(ge.r)], re),
        ] {
            let want = [r.z, r.v, r.phi, r.r.expect("R estimated")];
            // scales of z [m], v [m/s], φ [Wb], R [Ω]
            let scale = [1e-3, 1.0, 25e-6, 75.0];
            for ((a, b), s) in g.iter().zip(want).zip(scale) {
                assert!(a.is_finite(), "{g:?}");
                assert!((a - b).abs() <= 1e-9 * (b.abs() + s), "{g:?} vs {want:?}");
            }
        }
        last = [r_of(gu.r), r_of(ge.r)];
        24.0
    };
    let x0: State = [d.mechanics.z_max, 0.0, 0.0, 0.0];
    simulate_sampled(
        &plant,
        &mut control,
        ukf::f64::T_S,
        HALF,
        x0,
        Mode::StuckMax,
        &Options::default(),
    )
    .expect("simulation");
    for r in last {
        assert!((r - truth).abs() < 0.01 * truth, "R = {r} vs {truth}");
    }
    assert_eq!((u_filter.skipped(), e_filter.skipped()), (1, 1));
}

/// The full report (slow): every plant variant (the four corners of ±10 %
/// on k_s and R), five noise seeds, both generated filters at 10 µs, and the
/// reference UKF at 50 µs. Asserts what holds: the sensor-based loop lands
/// ≥ 20× softer than switching everywhere, and the generated UKF at 10 µs
/// lands both operations ≥ 10× softer on every plant and seed.
/// `cargo test --release -p reldesign-tests --test sensorless -- --ignored --nocapture`
#[test]
#[ignore]
fn sensorless_report() {
    report_header();
    let mut worst = [f64::INFINITY; 2];
    for (ks, r) in [(1.0, 1.0), (1.1, 0.9), (0.9, 1.1), (1.1, 1.1), (0.9, 0.9)] {
        let at = [10e-6, 50e-6].map(|ts| Baselines::new(ks, r, ts));
        for b in &at {
            let (hard, sensor, ts) = (b.hard, b.sensor, b.ts);
            for (s, h) in [
                (sensor.closing, hard.closing),
                (sensor.opening, hard.opening),
            ] {
                assert!(
                    20.0 * s < h,
                    "k×{ks} R×{r} Ts={ts:e}: {sensor:?} vs {hard:?}"
                );
            }
        }
        for seed in std::iter::once(SEED).chain(MORE_SEEDS) {
            for (base, filter) in [
                (&at[0], Filter::GeneratedUkf),
                (&at[0], Filter::GeneratedEkf),
                (&at[1], Filter::ReferenceUkf),
            ] {
                let (hard, soft) = (base.hard, base.sensorless(filter, seed));
                if filter == Filter::GeneratedUkf {
                    let ratios = [hard.closing / soft.closing, hard.opening / soft.opening];
                    for (w, q) in worst.iter_mut().zip(ratios) {
                        *w = w.min(if q.is_finite() { q } else { 0.0 });
                    }
                }
            }
        }
    }
    eprintln!(
        "generated UKF at 10 µs, softest margin over every plant and seed: closing {:.1}×, opening {:.1}×",
        worst[0], worst[1]
    );
    assert!(worst.iter().all(|&w| w >= 10.0), "{worst:?}");
}
