//! Sensorless soft landing against the sample period (the hysteresis
//! control issue, its part 3): the sensorless design of `tests/data/sensorless-valve.toml`
//! (feedback linearization on the saturating core, the observer on
//! [z, z_prev, φ, R] from the coil voltage and current) in the designer's
//! closed loop (`designer::closed_loop::run_loop`, which runs the runtime's
//! controller and filter code) on the mismatched plants of
//! `tests/tests/sensorless.rs` (a Jiles–Atherton core, ±10 % on k_s and R),
//! with the measurement noise of the semera paper's study (σ_v = 15 mV,
//! σ_i = 1 mA), at 10, 20, 50 and 100 µs. The design is redone at each
//! period (the observer's process noise per step ∝ T_s).
//!
//! The table of docs/validation/sensorless.md ("Against the sample period"):
//!
//! ```sh
//! cargo test --release -p reldesign-tests --test sensorless_rates -- --ignored --nocapture
//! ```
//!
//! CI runs the 10 µs UKF row on one seed.

use designer::closed_loop::{resample_observer, run_loop, switching_baseline, Noise};
use designer::description::{parse_str, Description};
use designer::design::Design;
use designer::sim::Options;
use reldesign_tests::{root, sensorless::mismatched_plant};

/// (k_s factor, R factor) of the plants.
const PLANTS: [(f64, f64); 5] = [(1.0, 1.0), (1.1, 0.9), (0.9, 1.1), (1.1, 1.1), (0.9, 0.9)];

/// The worst, over plants and seeds, of how many times softer than the
/// switching each operation lands (0 where it never lands in its window),
/// the most bounces, and the runs below 10× or with more than one bounce.
#[derive(Debug, Clone, Copy)]
struct Row {
    worst: [f64; 2],
    best: [f64; 2],
    bounces: usize,
    failing: usize,
    runs: usize,
}

/// The sensorless design with `estimator`, at `ts`.
fn design(estimator: &str, ts: f64) -> Description {
    let text = std::fs::read_to_string(root().join("tests/data/sensorless-valve.toml")).unwrap();
    let text = text.replacen(
        "[controller]\n",
        &format!("[controller]\nestimator = \"{estimator}\"\n"),
        1,
    );
    let mut d = parse_str(&text, "sensorless-valve.toml").unwrap_or_else(|e| panic!("{e}"));
    if let Some(c) = &mut d.controller {
        c.sample_period = ts;
    }
    if let Some(o) = &mut d.observer {
        resample_observer(o, ts);
    }
    d
}

fn row(estimator: &str, ts: f64, seeds: u64) -> Row {
    let d = design(estimator, ts);
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let t = d.trajectory.as_ref().unwrap();
    let mut row = Row {
        worst: [f64::INFINITY; 2],
        best: [0.0; 2],
        bounces: 0,
        failing: 0,
        runs: 0,
    };
    for (ks, r) in PLANTS {
        let plant = mismatched_plant(ks, r);
        let switching = switching_baseline(&d, Some(&plant), &Options::default()).unwrap();
        for seed in 0..seeds {
            let noise = Noise {
                seed,
                sigma: Some([15e-3, 1e-3]),
            };
            let run = run_loop(&design, Some(&plant), ts, None, noise, &Options::default())
                .unwrap_or_else(|e| panic!("{e}"));
            for (k, (o, (_, hard))) in run
                .outcomes(t.takeoff, t.landing)
                .iter()
                .zip(&switching)
                .enumerate()
            {
                let hard = hard.expect("the switching lands").abs();
                let softer = o.impact_velocity.map_or(0.0, |v| hard / v.abs().max(1e-12));
                row.worst[k] = row.worst[k].min(softer);
                row.best[k] = row.best[k].max(softer);
                row.bounces = row.bounces.max(o.bounces);
                row.failing += usize::from(softer < 10.0 || o.bounces > 1);
                row.runs += 1;
            }
        }
    }
    row
}

/// CI, on the first noise seed: at 10 µs the UKF lands every plant's
/// closing ≥ 10× and opening ≥ 9× softer than switching (measured 12.3×
/// and 10.3×; other seeds hover once in 25 openings, see the docs).
#[test]
fn ukf_at_10_us_lands_every_plant_on_the_first_seed() {
    let r = row("ukf", 10e-6, 1);
    eprintln!("{r:?}");
    assert!(r.worst[0] >= 10.0 && r.worst[1] >= 9.0, "{r:?}");
}

#[test]
#[ignore = "the table of docs/validation/sensorless.md: a few seconds in release, minutes in debug"]
fn table_against_the_sample_period() {
    println!("| T_s | filter | closing × (worst–best) | opening × (worst–best) | most bounces | runs < 10× or > 1 bounce |");
    println!("| --- | --- | --- | --- | --- | --- |");
    for ts in [10e-6, 20e-6, 50e-6, 100e-6] {
        for estimator in ["ukf", "ekf"] {
            let r = row(estimator, ts, 5);
            println!(
                "| {} µs | {} | {:.1}–{:.0} | {:.1}–{:.0} | {} | {} of {} |",
                ts * 1e6,
                estimator.to_uppercase(),
                r.worst[0],
                r.best[0],
                r.worst[1],
                r.best[1],
                r.bounces,
                r.failing,
                r.runs
            );
        }
    }
}
