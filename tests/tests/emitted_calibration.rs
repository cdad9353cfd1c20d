//! The self-calibration as emitted (`generated/src/self_calibrating_valve.rs`:
//! the UKF's `Model` at θ, `Record`, `Calibration`, `calibrate`) equals the
//! update `reldesign loop --runs` runs (the runtime's
//! `calibrate::innovations` on the designer's tapes with θ as inputs): one
//! run of the design on a plant within ±20 %, its measured voltage and current
//! pushed into the emitted record as firmware would, one update each.
//! And the emitted law at an adapted θ equals the designer's law derived
//! again on the adapted description.

use designer::calibrate::{adapted_design, choose, innovations, run_runs, Outcome};
use designer::closed_loop::{Measured, Noise};
use designer::description::parse_str;
use designer::design::{Design, RuntimePlan};
use reldesign_generated::self_calibrating_valve as sc;
use reldesign_runtime::calibrate::Calibration;
use reldesign_runtime::control::Law;
use reldesign_tests::example_path;
use reldesign_tests::variants::{physics_of, variant};

const EXAMPLE: &str = "self-calibrating-valve.toml";

/// Plants whose run the emitted filter and the designer's tapes follow alike
/// at θ_d (mean ν² equal to 1e-12). The two evaluate the same expressions in
/// a different order, and on some runs the filter amplifies that rounding:
/// on plant 2 their innovations differ by 1e-9 from sample 173 on, and their
/// mean ν² end 4 % apart. One update step compared there would compare two
/// rounding paths, not two implementations. At θ_d plants 1, 8 and 9 of 1–10
/// run alike to 1e-12, but plant 8's step still differs by 1e-4 of θ_d (a
/// filter at θ + h·θ_d, or the trial's, parts ways) (2026-12-03).
const SEEDS: [u64; 2] = [1, 9];

fn example() -> (String, Design) {
    let text = std::fs::read_to_string(example_path(EXAMPLE)).expect("the example");
    let d = parse_str(&text, EXAMPLE).unwrap_or_else(|e| panic!("{e}"));
    (
        text.clone(),
        Design::new(&d).unwrap_or_else(|e| panic!("{e}")),
    )
}

/// One run at θ_d on the plant of `seed`: what the firmware measured.
fn measured_run(text: &str, design: &Design, seed: u64) -> Vec<Measured> {
    let plant = variant(physics_of(text), seed);
    let ts = design
        .controller
        .as_ref()
        .expect("controller")
        .sample_period;
    let runs = run_runs(
        design,
        None,
        Some(&plant.description),
        1,
        ts,
        Noise::seeded(seed),
        &Default::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    runs.into_iter().next().expect("one run").run_loop.measured
}

/// One update of the emitted code (`ukf::…::calibrate` on its own `Record`)
/// limited to `iterations` Levenberg–Marquardt steps.
macro_rules! emitted_update {
    ($m:ident, $f:ty, $measured:expr, $iterations:expr) => {{
        use sc::ukf::$m as e;
        let mut record = e::Record::new();
        record.start(e::Z_MAX);
        for m in $measured {
            let (c, v, i) = (m.commanded as $f, m.voltage as $f, m.current as $f);
            record.push(&e::CALIBRATION, c, v, i);
        }
        let mut settings = e::CALIBRATION;
        settings.iterations = $iterations;
        let mut calibration = e::Calibration::new(&settings);
        let outcome = calibration.update_innovations::<e::Model, 3, 7, { e::RECORD_CAPACITY }>(
            &<e::Model as reldesign_runtime::observe::Stateless<$f, 3>>::MODEL,
            &settings,
            &record,
        );
        (outcome, calibration.theta)
    }};
}

#[test]
fn the_emitted_update_equals_the_designers() {
    let (text, design) = example();
    let ts = design
        .controller
        .as_ref()
        .expect("controller")
        .sample_period;
    let c = choose(&design, ts).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(c.parameters.len(), 10, "every physics parameter but N");
    let keys: Vec<&str> = c.parameters.iter().map(|a| a.key).collect();
    assert_eq!(keys, sc::ukf::f64::ADAPTED, "the emitted θ is the design's");
    for seed in SEEDS {
        let measured = measured_run(&text, &design, seed);
        assert!(
            measured.len() <= sc::ukf::f64::RECORD_CAPACITY,
            "{} samples in a run: the emitted record holds {}",
            measured.len(),
            sc::ukf::f64::RECORD_CAPACITY
        );
        // one step: the same Jacobian, the same step
        let mut one = c.clone();
        one.iterations = 1;
        let mut tape = Calibration::<f64, 10>::new(&one.settings());
        let by_tape = innovations::update(&design, &one, &mut tape, &measured)
            .unwrap_or_else(|e| panic!("{e}"));
        let (by_code, theta) = emitted_update!(f64, f64, &measured, 1);
        let (by_f32, theta32) = emitted_update!(f32, f32, &measured, 1);
        let mut befores = Vec::new();
        for outcome in [by_tape, by_code] {
            let Outcome::Updated { before, after } = outcome else {
                panic!("plant {seed}: {outcome:?}")
            };
            assert!(after < before, "plant {seed}: {outcome:?}");
            befores.push(before);
        }
        // the two filters at θ_d agree over the whole run (see `SEEDS`)
        assert!(
            (befores[0] - befores[1]).abs() <= 1e-9 * befores[0],
            "plant {seed}: the filters at θ_d part ways (mean ν²: tapes {:e}, emitted {:e})",
            befores[0],
            befores[1]
        );
        let Outcome::Updated { before, after } = by_f32 else {
            panic!("plant {seed}, f32: {by_f32:?}")
        };
        assert!(after < before, "plant {seed}, f32: {by_f32:?}");
        for (k, a) in c.parameters.iter().enumerate() {
            let scale = a.nominal.abs();
            let (t, e, e32) = (tape.theta[k], theta[k], f64::from(theta32[k]));
            assert!(
                (t - e).abs() <= 1e-5 * scale,
                "plant {seed}, {}: tapes {t:e}, emitted f64 {e:e}",
                a.key
            );
            let (lo, hi) = (a.lower, a.upper);
            assert!(
                (lo..=hi).contains(&e32),
                "plant {seed}, {}: f32 {e32:e} outside [{lo:e}, {hi:e}]",
                a.key
            );
        }
        // the whole update (8 steps) lowers the error in both floats, by > 10 %
        for (outcome, what) in [
            (emitted_update!(f64, f64, &measured, 8).0, "f64"),
            (
                match emitted_update!(f32, f32, &measured, 8).0 {
                    Outcome::Updated { before, after } => Outcome::Updated {
                        before: f64::from(before),
                        after: f64::from(after),
                    },
                    Outcome::Refused(r) => Outcome::Refused(r),
                },
                "f32",
            ),
        ] {
            let Outcome::Updated { before, after } = outcome else {
                panic!("plant {seed}, {what}: {outcome:?}")
            };
            assert!(after < 0.9 * before, "plant {seed}, {what}: {outcome:?}");
        }
    }
}

#[test]
fn the_emitted_law_at_an_adapted_theta_is_the_adapted_designs() {
    let (_, design) = example();
    let c = choose(&design, 5e-5).unwrap_or_else(|e| panic!("{e}"));
    // every parameter moved, within its domain
    let theta: Vec<f64> = (c.parameters.iter().enumerate())
        .map(|(k, a)| a.nominal * if k % 2 == 0 { 1.13 } else { 0.88 })
        .collect();
    let values: Vec<(&str, f64)> = c
        .parameters
        .iter()
        .map(|a| a.key)
        .zip(theta.clone())
        .collect();
    let adapted = adapted_design(&design, &values).unwrap_or_else(|e| panic!("{e}"));
    let controller = adapted.controller.as_ref().expect("controller");
    let mut model = adapted.model.clone();
    let plan = RuntimePlan::new(&mut model, controller);
    let emitted = sc::f64::Design {
        theta: theta.clone().try_into().expect("10 values"),
    };
    let mut worst: f64 = 0.0;
    for k in 0..200 {
        let s = f64::from(k) / 200.0;
        let x = [1e-3 * (1.0 - s), 0.3 * (s - 0.5), 4e-6 + 8e-6 * s, 0.0];
        let reference = [1e-3 * s, -0.2 * s, 50.0 * (s - 0.5), 1e5 * (0.5 - s)];
        let by_design = plan.law(x, reference);
        let by_code = emitted.law(x, reference);
        worst = worst.max((by_design - by_code).abs() / by_design.abs().max(1.0));
    }
    assert!(worst < 1e-9, "the emitted law at θ differs by {worst:e}");
}
