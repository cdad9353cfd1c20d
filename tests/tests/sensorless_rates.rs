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
//! second on one seed.

use designer::closed_loop::{resample_observer, run_loop, switching_baseline, LoopRun, Noise};
use designer::description::{parse_str, Description, Operation};
use designer::design::Design;
use designer::sim::{EventKind, Limit, Options};
use reldesign_tests::{root, sensorless::mismatched_plant};

/// (k_s factor, R factor) of the plants.
const PLANTS: [(f64, f64); 5] = [(1.0, 1.0), (1.1, 0.9), (0.9, 1.1), (1.1, 1.1), (0.9, 0.9)];

/// The design on the saturating core (Euler step, tuned at 10 µs).
const SATURATING: &str = "tests/data/sensorless-valve.toml";
/// The design on the Jiles–Atherton core (exponential step, tuned at 50 µs).
const JILES_ATHERTON: &str = "tests/data/sensorless-ja-valve.toml";

/// Over plants and seeds, per operation (closing, opening): how many times
/// softer than the switching the first impact is (0 where the armature
/// never lands within t₀ after t_f), worst and best; the runs below 10×; the
/// most bounces within that window and the runs with more than one; the
/// highest bounce [m] (the largest excursion from the stop between an
/// impact that bounced and the next one, at the samples).
#[derive(Debug, Clone, Copy)]
struct Row {
    worst: [f64; 2],
    best: [f64; 2],
    below_ten: usize,
    bounces: usize,
    bouncing: usize,
    highest: f64,
    runs: usize,
}

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

/// The highest bounce [m] at `operation`'s stop of `d` within (from, to]:
/// the largest distance from the stop between an impact that bounced and
/// the next impact, at the samples.
fn highest_bounce(run: &LoopRun, d: &Description, operation: Operation, from: f64, to: f64) -> f64 {
    let (limit, stop) = match operation {
        Operation::Closing => (Limit::Min, d.mechanics.z_min),
        Operation::Opening => (Limit::Max, d.mechanics.z_max),
    };
    let tr = &run.trajectory;
    let impacts: Vec<(f64, bool)> = tr
        .events
        .iter()
        .filter(|e| e.t > from && e.t <= to)
        .filter_map(|e| match e.kind {
            EventKind::Impact {
                limit: l, v_after, ..
            } if l == limit => Some((e.t, v_after != 0.0)),
            _ => None,
        })
        .collect();
    let mut highest = 0.0_f64;
    for (k, &(t, bounced)) in impacts.iter().enumerate() {
        let next = impacts.get(k + 1).map_or(to, |&(t, _)| t);
        if bounced {
            for (s, x) in tr.t.iter().zip(&tr.x) {
                if *s > t && *s < next {
                    highest = highest.max((x[0] - stop).abs());
                }
            }
        }
    }
    highest
}

fn row(file: &str, estimator: &str, ts: f64, seeds: std::ops::Range<u64>) -> Row {
    let d = design(file, estimator, ts);
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let t = d.trajectory.as_ref().unwrap();
    let mut row = Row {
        worst: [f64::INFINITY; 2],
        best: [0.0; 2],
        below_ten: 0,
        bounces: 0,
        bouncing: 0,
        highest: 0.0,
        runs: 0,
    };
    for (ks, r) in PLANTS {
        let plant = mismatched_plant(ks, r);
        let switching = switching_baseline(&d, Some(&plant), &Options::default()).unwrap();
        for seed in seeds.clone() {
            let noise = Noise {
                seed,
                sigma: Some([15e-3, 1e-3]),
            };
            let run = run_loop(&design, Some(&plant), ts, None, noise, &Options::default())
                .unwrap_or_else(|e| panic!("{e}"));
            let outcomes = run.outcomes(t.takeoff, t.landing);
            for (k, (o, (_, hard))) in outcomes.iter().zip(&switching).enumerate() {
                let hard = hard.expect("the switching lands").abs();
                let softer = o.impact_velocity.map_or(0.0, |v| hard / v.abs().max(1e-12));
                row.worst[k] = row.worst[k].min(softer);
                row.best[k] = row.best[k].max(softer);
                row.below_ten += usize::from(softer < 10.0);
                row.bounces = row.bounces.max(o.bounces);
                row.bouncing += usize::from(o.bounces > 1);
                let (_, start) = run.operations[k];
                let window = (start + t.takeoff, start + run.operation_length);
                let highest = highest_bounce(&run, &d, o.operation, window.0, window.1);
                row.highest = row.highest.max(highest);
                row.runs += 1;
            }
        }
    }
    row
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
                    "| {name} | {} µs | {} | {:.1}–{:.0} | {:.1}–{:.0} | {} of {} | {} | {} | {:.1} |",
                    ts * 1e6,
                    estimator.to_uppercase(),
                    r.worst[0],
                    r.best[0],
                    r.worst[1],
                    r.best[1],
                    r.below_ten,
                    r.runs,
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
