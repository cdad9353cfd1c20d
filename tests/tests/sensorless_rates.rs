//! Sensorless soft landing against the sample period (the hysteresis
//! control issue, its part 3), in the designer's closed loop
//! (`designer::closed_loop::run_loop`, which runs the runtime's controller
//! and filter code) on the mismatched plants of `tests/tests/sensorless.rs`
//! (a Jiles–Atherton core, ±10 % on k_s and R), with the measurement noise
//! of the semera paper's study (σ_v = 15 mV, σ_i = 1 mA), two designs:
//!
//! - `tests/data/sensorless-valve.toml`: feedback linearization on the
//!   saturating core, the observer on [z, z_prev, φ, R] with the paper's
//!   Euler step [JA 84c], tuned at 10 µs;
//! - `tests/data/sensorless-ja-valve.toml`: the same law on the plants'
//!   Jiles–Atherton core (the design's with the reversal rule "reversible",
//!   the plants keep the paper's clamp [JA 52]), the UKF on
//!   [z, z_prev, φ, H_c, R] with the exponential flux step, the law's voltage
//!   corrected to R̂, tuned at 50 µs.
//!
//! Each is redone at each period (the observer's process noise per step
//! ∝ T_s). The tables of docs/validation/sensorless.md:
//!
//! ```sh
//! cargo test --release -p reldesign-tests --test sensorless_rates -- --include-ignored --nocapture
//! ```
//!
//! CI runs the 10 µs UKF row of the first design and the 50 µs row of the
//! second on one seed. `observer_lags_the_armature_at_the_stops` (ignored)
//! measures what limits the landing speed: the filter's lag at the stops on
//! the design's own model without noise.

use designer::closed_loop::resample_observer;
use designer::description::{parse_str, Description, Operation};
use designer::sim::{EventKind, Limit, Options};
use reldesign_tests::landings::{landings, Landings};
use reldesign_tests::root;
use reldesign_tests::sensorless::mismatched_plant;

/// (k_s factor, R factor) of the plants.
const PLANTS: [(f64, f64); 5] = [(1.0, 1.0), (1.1, 0.9), (0.9, 1.1), (1.1, 1.1), (0.9, 0.9)];

/// The design on the saturating core (Euler step, tuned at 10 µs).
const SATURATING: &str = "tests/data/sensorless-valve.toml";
/// The design on the Jiles–Atherton core (exponential step, tuned at 50 µs).
const JILES_ATHERTON: &str = "tests/data/sensorless-ja-valve.toml";

/// The design of `file` with its observer `estimator` driving the law, at `ts`.
fn design(file: &str, estimator: &str, ts: f64) -> Description {
    let text = std::fs::read_to_string(root().join(file)).unwrap();
    let line = format!("estimator = \"{estimator}\"\n");
    let text = match text.find("estimator = \"") {
        Some(at) => {
            let end = at + text[at..].find('\n').unwrap() + 1;
            format!("{}{line}{}", &text[..at], &text[end..])
        }
        None => text.replacen("[controller]\n", &format!("[controller]\n{line}"), 1),
    };
    let text = text.replacen(
        "estimators = [\"ukf\"]",
        "estimators = [\"ekf\", \"ukf\"]",
        1,
    );
    let mut d = parse_str(&text, file).unwrap_or_else(|e| panic!("{e}"));
    if let Some(c) = &mut d.controller {
        c.sample_period = ts;
    }
    if let Some(o) = &mut d.observer {
        resample_observer(o, ts);
    }
    d
}

/// The figures of `file`'s design at `ts` with `estimator`, over the plants
/// and `seeds` (the switching of every plant lands: each run has its ratio).
fn row(file: &str, estimator: &str, ts: f64, seeds: std::ops::Range<u64>) -> Landings {
    let plants: Vec<_> = PLANTS
        .iter()
        .map(|&(ks, r)| mismatched_plant(ks, r))
        .collect();
    let r = landings(
        &design(file, estimator, ts),
        &plants,
        Some([15e-3, 1e-3]),
        seeds,
        &Options::default(),
    );
    assert_eq!(r.unscored, 0, "a plant's switching does not land: {r:?}");
    r
}

/// CI, on the first noise seed: at 10 µs the saturating design's UKF lands
/// every plant's closing ≥ 10× and opening ≥ 9× softer than switching
/// (measured 12.3× and 10.3×; other seeds hover once in 25 openings, see
/// the docs).
#[test]
fn ukf_at_10_us_lands_every_plant_on_the_first_seed() {
    let r = row(SATURATING, "ukf", 10e-6, 0..1);
    eprintln!("{r:?}");
    assert!(r.worst[0] >= 10.0 && r.worst[1] >= 9.0, "{r:?}");
}

/// CI, on the first noise seed: at the paper's 50 µs the Jiles–Atherton
/// design lands every plant's closing and opening ≥ 10× softer than
/// switching (measured on this seed 34.5× and 31.3×; over the table's 5
/// seeds 34.5× and 11.7× at worst; the bounces and the held-out seeds:
/// docs/validation/sensorless.md).
#[test]
fn ja_design_at_50_us_lands_every_plant_ten_times_softer() {
    let r = row(JILES_ATHERTON, "ukf", 50e-6, 0..1);
    eprintln!("{r:?}");
    assert!(r.worst[0] >= 10.0 && r.worst[1] >= 10.0, "{r:?}");
}

#[test]
#[ignore = "the tables of docs/validation/sensorless.md: 5 s in release"]
fn table_against_the_sample_period() {
    println!("| design | T_s | filter | closing × (worst–best) | opening × (worst–best) | runs < 10× | most bounces | runs > 1 bounce | highest bounce [µm] |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for (name, file) in [
        ("saturating", SATURATING),
        ("Jiles–Atherton", JILES_ATHERTON),
    ] {
        for ts in [10e-6, 20e-6, 50e-6, 100e-6] {
            for estimator in ["ukf", "ekf"] {
                let r = row(file, estimator, ts, 0..5);
                println!(
                    "| {name} | {} µs | {} | {} | {} | {} | {:.1} |",
                    ts * 1e6,
                    estimator.to_uppercase(),
                    r.softness_cells(),
                    r.bounces,
                    r.bouncing,
                    r.highest * 1e6
                );
            }
        }
    }
}

/// The Jiles–Atherton design at 50 µs on 50 noise seeds that no choice of
/// the design saw (50–99; the table's 0–4 tuned it, 5–49 chose the creep
/// and the substeps): 500 runs, 9 of them below 10× (measured): the closings
/// of seed 70 on three plants and of seed 92 on two hover (land later than
/// 1 ms after t_f; in the traced one R̂ ends the 24 V pre-movement 1 % low,
/// biasing the flux estimate up and the position estimate 3–7 µm towards the
/// stop), two openings of seed 58 hover, two land at 9.6–9.7×.
#[test]
#[ignore = "500 runs: 10 s in release"]
fn ja_design_at_50_us_on_held_out_seeds() {
    let r = row(JILES_ATHERTON, "ukf", 50e-6, 50..100);
    println!(
        "held-out seeds 50–99: worst closing {:.1}×, opening {:.1}×; {} of {} runs < 10×",
        r.worst[0], r.worst[1], r.below_ten, r.runs
    );
    assert!(r.below_ten <= 9, "{r:?}");
}

/// The observer at the stops, without any mismatch: the Jiles–Atherton
/// design at 50 µs on its own model (the reversal rule "reversible", the
/// design's k_s and R) with no measurement noise, so that what remains is
/// the filter itself. At the first impact of each operation the estimate
/// lags the armature: measured 4.6 µm and 11 mm/s at the closing
/// (impact at 19.7 mm/s, 70× softer than switching), 15 µm and 11 mm/s at
/// the opening (39.5 mm/s, 19×). The law tracks the estimate, so the
/// armature runs ahead of the reference by that lag and lands at about the
/// reference's speed that far from the stop. docs/validation/sensorless.md,
/// "What keeps the landings above 2 mm/s".
#[test]
#[ignore = "a characterisation of the observer: 0.1 s in release"]
fn observer_lags_the_armature_at_the_stops() {
    let d = design(JILES_ATHERTON, "ukf", 50e-6);
    let design = designer::design::Design::new(&d).unwrap();
    let quiet = designer::closed_loop::Noise {
        seed: 0,
        sigma: Some([0.0, 0.0]),
    };
    let run =
        designer::closed_loop::run_loop(&design, None, 50e-6, None, quiet, &Options::default())
            .unwrap();
    let estimates = run.estimates.as_ref().expect("an observer drives the law");
    let t = d.trajectory.as_ref().unwrap();
    for &(operation, start) in &run.operations {
        // the stop the operation lands on, and the direction towards it
        let (stop, towards) = match operation {
            Operation::Closing => (Limit::Min, -1.0),
            Operation::Opening => (Limit::Max, 1.0),
        };
        let (at, v_before) = run
            .trajectory
            .events
            .iter()
            .filter(|e| e.t > start + t.takeoff && e.t <= start + run.operation_length)
            .find_map(|e| match e.kind {
                EventKind::Impact {
                    limit, v_before, ..
                } if limit == stop => Some((e.t, v_before)),
                _ => None,
            })
            .expect("the armature lands");
        // the last sample before the impact
        let i = run
            .trajectory
            .t
            .partition_point(|&s| s < at)
            .saturating_sub(1);
        let (x, e) = (run.trajectory.x[i], estimates[i]);
        let lag = [(x[0] - e.z) * towards, (x[1] - e.v) * towards];
        println!(
            "{operation:?}: impact {:.1} mm/s at {:+.2} ms from t_f; the estimate {:.2} µm and {:.1} mm/s behind",
            v_before.abs() * 1e3,
            (at - start - t.landing) * 1e3,
            lag[0] * 1e6,
            lag[1] * 1e3
        );
        assert!(lag[0] > 1e-6 && lag[1] > 5e-3, "{operation:?}: {lag:?}");
        assert!(v_before.abs() > 10e-3, "{operation:?}: {v_before}");
    }
}
