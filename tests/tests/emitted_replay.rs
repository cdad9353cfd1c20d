//! The replay self-calibration as emitted
//! (`generated/src/self_calibrating_sensor_valve.rs`: `Model`, the runtime's
//! `calibrate::Predictor` over the emitted `flow_terms` and `current_terms`,
//! with `Record`, `Calibration` and `calibrate`) equals the update
//! `reldesign loop --runs` runs (the runtime's `calibrate::calibrate` on the
//! designer's tapes with θ as inputs): the model and its Jacobians at
//! states across the stroke, the settings, and one update from each
//! operation of a run on a plant the design does not match, its samples
//! pushed into the emitted record as firmware would.

use designer::calibrate::{choose, run_runs, CalibrationDesign, TapePredictor};
use designer::closed_loop::{Measured, Noise};
use designer::description::{parse_str, Operation};
use designer::design::Design;
use reldesign_generated::self_calibrating_sensor_valve as sc;
use reldesign_runtime::calibrate::{calibrate, Outcome, Predictor, Record};
use reldesign_tests::example_path;

const EXAMPLE: &str = "self-calibrating-sensor-valve.toml";
const P: usize = 2;

fn example() -> (String, Design, CalibrationDesign) {
    let text = std::fs::read_to_string(example_path(EXAMPLE)).expect("the example");
    let d = parse_str(&text, EXAMPLE).unwrap_or_else(|e| panic!("{e}"));
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let c = choose(
        &design,
        d.controller.as_ref().expect("controller").sample_period,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    (text, design, c)
}

fn tapes(design: &Design, c: &CalibrationDesign) -> TapePredictor<P> {
    let ids: [_; P] = std::array::from_fn(|k| {
        let symbol = c.parameters[k].symbol;
        design
            .model
            .params
            .symbol(symbol)
            .expect("an adapted parameter")
    });
    TapePredictor::new(&design.model, &ids)
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-12 * scale.max(a.abs()).max(b.abs())
}

#[test]
fn the_emitted_model_and_its_jacobians_equal_the_tapes() {
    let (_, design, c) = example();
    assert_eq!(sc::f64::ADAPTED, ["coil.resistance", "core.phi_sat"]);
    let tapes = tapes(&design, &c);
    let emitted = sc::f64::Model;
    let nominal = sc::f64::THETA_DESIGN;
    for theta in [
        nominal,
        nominal.map(|x| 1.2 * x),
        [0.85 * nominal[0], 1.1 * nominal[1]],
    ] {
        for z in [0.0, 1e-6, 2e-4, 5e-4, 1e-3] {
            for (v, phi, u) in [(0.0, 0.0, 0.0), (-0.3, 8e-6, 12.0), (0.2, 1.6e-5, -24.0)] {
                let x = [z, v, phi];
                let (a, b) = (
                    tapes.derivative(&theta, &x, u),
                    emitted.derivative(&theta, &x, u),
                );
                for r in 0..3 {
                    let scale = a.dx[r].abs().max(1e-9);
                    assert!(close(a.dx[r], b.dx[r], scale), "f at {x:?}: {a:?} / {b:?}");
                    for k in 0..3 {
                        assert!(
                            close(a.f_x[r][k], b.f_x[r][k], 1e-9),
                            "∂f/∂x at {x:?}: {a:?} / {b:?}"
                        );
                    }
                    for k in 0..P {
                        assert!(
                            close(a.f_theta[r][k], b.f_theta[r][k], 1e-30),
                            "∂f/∂θ at {x:?}: {a:?} / {b:?}"
                        );
                    }
                }
                let (a, b) = (tapes.current(&theta, &x, u), emitted.current(&theta, &x, u));
                assert!(close(a.i, b.i, 1e-12), "i at {x:?}: {a:?} / {b:?}");
                for k in 0..3 {
                    assert!(
                        close(a.i_x[k], b.i_x[k], 1e-12),
                        "∂i/∂x at {x:?}: {a:?} / {b:?}"
                    );
                }
                for k in 0..P {
                    assert!(
                        close(a.i_theta[k], b.i_theta[k], 1e-30),
                        "∂i/∂θ at {x:?}: {a:?} / {b:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn the_emitted_settings_are_the_designs() {
    let (_, _, c) = example();
    assert_eq!(sc::f64::CALIBRATION, c.settings::<P>());
    assert_eq!(sc::f64::RECORD_CAPACITY, c.capacity);
    assert!(c.decimation > 1, "the replay's record is decimated");
}

/// One run at θ_d on the valve with R 10 % higher and φ_sat 8 % lower:
/// what the firmware measured, and each operation's start.
fn measured_run(
    text: &str,
    design: &Design,
    noise: Noise,
) -> (Vec<Measured>, Vec<(Operation, f64)>, f64) {
    let plant = text
        .replace("resistance = 75.0", "resistance = 82.5")
        .replace("phi_sat = 25e-6", "phi_sat = 23e-6");
    let plant = parse_str(&plant, "plant.toml").unwrap_or_else(|e| panic!("{e}"));
    let ts = design
        .controller
        .as_ref()
        .expect("controller")
        .sample_period;
    let runs = run_runs(
        design,
        None,
        Some(&plant),
        1,
        ts,
        noise,
        &Default::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let run = runs.into_iter().next().expect("one run").run_loop;
    (run.measured, run.operations, run.operation_length)
}

/// The samples of the operation starting at `start`, `length` long.
fn window(measured: &[Measured], start: f64, length: f64) -> impl Iterator<Item = &Measured> {
    let tolerance = 1e-9 * length;
    measured
        .iter()
        .filter(move |s| s.t >= start - tolerance && s.t < start + length - tolerance)
}

fn rest(operation: Operation) -> f64 {
    match operation {
        Operation::Closing => sc::f64::Z_MAX,
        Operation::Opening => sc::f64::Z_MIN,
    }
}

#[test]
fn the_emitted_update_equals_the_runtime_one_on_the_tapes() {
    let (text, design, c) = example();
    let (measured, operations, length) = measured_run(&text, &design, Noise::seeded(7));
    let settings = c.settings::<P>();
    let tapes = tapes(&design, &c);
    let mut updated = 0;
    for &(operation, start) in &operations {
        // the designer's: the runtime's update on the tapes
        let mut record = Box::new(Record::<f64, 512>::new());
        record.start(rest(operation));
        let mut emitted = Box::new(sc::f64::Record::new());
        emitted.start(rest(operation));
        let mut emitted_f32 = Box::new(sc::f32::Record::new());
        emitted_f32.start(rest(operation) as f32);
        for s in window(&measured, start, length) {
            record.push(&settings, s.commanded, s.voltage, s.current);
            emitted.push(&sc::f64::CALIBRATION, s.commanded, s.voltage, s.current);
            let (u, v, i) = (s.commanded as f32, s.voltage as f32, s.current as f32);
            emitted_f32.push(&sc::f32::CALIBRATION, u, v, i);
        }
        let mut theta = settings.nominal;
        let expected = calibrate(&tapes, &settings, &record, &mut theta);
        let mut calibration = sc::f64::Calibration::new(&sc::f64::CALIBRATION);
        let got = sc::f64::calibrate(&mut calibration, &emitted);
        match (expected, got) {
            (Outcome::Updated { after: a, .. }, Outcome::Updated { after: b, .. }) => {
                assert!(
                    close(a, b, 1e-9 * a),
                    "{operation:?}: error after {a:e} / {b:e}"
                );
                updated += 1;
            }
            // the same refusal (the opening's current, noisy, shows too little
            // of the motion: `Refusal::NoMotion`)
            (Outcome::Refused(a), Outcome::Refused(b)) if a == b => continue,
            _ => panic!("{operation:?}: {expected:?} / {got:?}"),
        }
        for k in 0..P {
            let d = (theta[k] - calibration.theta[k]).abs() / settings.nominal[k];
            assert!(
                d < 1e-9,
                "{operation:?}: θ {theta:?} / {:?}",
                calibration.theta
            );
        }
        // f32: the same update to the float's rounding
        let mut calibration_f32 = sc::f32::Calibration::new(&sc::f32::CALIBRATION);
        let got = sc::f32::calibrate(&mut calibration_f32, &emitted_f32);
        assert!(
            matches!(got, Outcome::Updated { .. }),
            "{operation:?} in f32: {got:?}"
        );
        for k in 0..P {
            let d = (theta[k] - f64::from(calibration_f32.theta[k])).abs() / settings.nominal[k];
            assert!(
                d < 1e-3,
                "{operation:?}: θ {theta:?} / f32 {:?}",
                calibration_f32.theta
            );
        }
    }
    assert!(updated > 0, "no operation's record was taken");
}

/// Run after run with the emitted f64 update between operations, as a
/// firmware would: the resistance moves towards the valve's (10 % high), and
/// the current's error falls to a quarter. (φ_sat does not: the replay
/// leaves 7 mA RMS of this noise-free closed loop's current unexplained at
/// any θ, and φ_sat ends 6 % above its design value, not 8 % below; the
/// designer's `loop --runs` does the same, docs/guide/self-calibration.md.)
#[test]
fn the_emitted_update_moves_the_resistance_towards_the_valve() {
    let (text, design, _) = example();
    let quiet = Noise {
        seed: 0,
        sigma: Some([0.0, 0.0]),
    };
    let (measured, operations, length) = measured_run(&text, &design, quiet);
    let mut calibration = sc::f64::Calibration::new(&sc::f64::CALIBRATION);
    let mut errors = Vec::new();
    for _ in 0..3 {
        for &(operation, start) in &operations {
            let mut record = Box::new(sc::f64::Record::new());
            record.start(rest(operation));
            for s in window(&measured, start, length) {
                record.push(&sc::f64::CALIBRATION, s.commanded, s.voltage, s.current);
            }
            if let Outcome::Updated { before, after } =
                sc::f64::calibrate(&mut calibration, &record)
            {
                errors.push((before, after));
            }
        }
    }
    let r = calibration.theta[0];
    assert!(
        (r - 82.5).abs() < 0.25 * (75.0 - 82.5_f64).abs(),
        "R: 75 → {r}, the valve's 82.5"
    );
    let (first, last) = (errors[0].0, errors[errors.len() - 1].1);
    assert!(
        last < 0.25 * first,
        "mean squared current error {first:e} → {last:e}"
    );
}
