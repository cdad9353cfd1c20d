//! The run-to-run self-calibration (`reldesign_runtime::calibrate` on the
//! designer's tapes): its sensitivities against central differences, its
//! update against the plant it was recorded on (noise-free), the records it
//! refuses, and the no-hover rule on a plant the design cannot follow.

use designer::calibrate::{operation_window, run_runs, TapePredictor};
use designer::closed_loop::{run_spaced_loop, LoopRun, Noise};
use designer::description::{parse_str, Description, Operation};
use designer::design::Design;
use reldesign_runtime::calibrate::{calibrate, replay, Outcome, Record, Refusal, Settings};
use support::example_path;

const EXAMPLE: &str = "self-calibrating-valve.toml";
const RECORD: usize = 1024;

fn example_text() -> String {
    std::fs::read_to_string(example_path(EXAMPLE)).expect("the example")
}

/// The example's physics with `changes` (key line → new line), no design sections.
fn plant(changes: &[(&str, &str)]) -> Description {
    let text = example_text();
    let mut physics = text
        .split("[trajectory]")
        .next()
        .expect("physics")
        .to_owned();
    for (from, to) in changes {
        assert!(physics.contains(from), "{from}");
        physics = physics.replacen(from, to, 1);
    }
    parse_str(&physics, "plant.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn design() -> Design {
    let d = parse_str(&example_text(), EXAMPLE).unwrap_or_else(|e| panic!("{e}"));
    Design::new(&d).unwrap_or_else(|e| panic!("{e}"))
}

/// One noise-free run of `design` on `plant`, operations a window apart.
fn quiet_run(design: &Design, plant: &Description) -> LoopRun {
    let t = design.description.trajectory.as_ref().expect("trajectory");
    let ts = design
        .controller
        .as_ref()
        .expect("controller")
        .sample_period;
    let noise = Noise {
        seed: 0,
        sigma: Some([0.0, 0.0]),
    };
    run_spaced_loop(
        design,
        Some(plant),
        ts,
        None,
        Some(operation_window(t)),
        noise,
        &Default::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

fn settings<const P: usize>(nominal: [f64; P], ts: f64) -> Settings<f64, P> {
    Settings {
        nominal,
        lower: nominal.map(|x| (0.5 * x).min(2.0 * x)),
        upper: nominal.map(|x| (0.5 * x).max(2.0 * x)),
        max_step: 0.2,
        sample_period: ts,
        decimation: 1,
        z_min: 0.0,
        z_max: 1e-3,
        iterations: 8,
        min_samples: 50,
        current_limit: 1.0,
        dip_tolerance: 2.4,
        dip_share: 0.05,
        motion_evidence: 1.0,
        difference_step: 1e-4,
        unexplained: f64::INFINITY,
    }
}

/// The record the firmware keeps of operation `k` of `run`.
fn record<const P: usize>(
    run: &LoopRun,
    k: usize,
    settings: &Settings<f64, P>,
) -> Box<Record<f64, RECORD>> {
    record_until(run, k, settings, run.operation_length)
}

/// The record of operation `k` of `run` over its first `length` [s].
fn record_until<const P: usize>(
    run: &LoopRun,
    k: usize,
    settings: &Settings<f64, P>,
    length: f64,
) -> Box<Record<f64, RECORD>> {
    let (operation, start) = run.operations[k];
    let mut r = Box::new(Record::new());
    r.start(match operation {
        Operation::Closing => 1e-3,
        Operation::Opening => 0.0,
    });
    let end = start + length;
    for s in run
        .measured
        .iter()
        .filter(|s| s.t >= start - 1e-12 && s.t < end - 1e-12)
    {
        r.push(settings, s.commanded, s.voltage, s.current);
    }
    r
}

fn predictor<const P: usize>(design: &Design, symbols: [&str; P]) -> TapePredictor<P> {
    let ids = symbols.map(|s| design.model.params.symbol(s).expect("a parameter"));
    TapePredictor::new(&design.model, &ids)
}

/// Where the replay is smooth in θ its sensitivities are the derivatives of
/// its current: an open-loop pulse's closing up to just before its contact,
/// and the whole record with the armature held at its start stop. (Not a
/// designed operation's motion: its pre-movement stage brings the model's
/// acceleration to 0 at the stop [PT §4], so the replay's lift-off step
/// flips with θ; nor across a contact, whose clamp is a kink of O(T_s).)
#[test]
fn the_sensitivities_match_central_differences_of_the_replayed_current() {
    let design = design();
    let plant = plant(&[]);
    // a model slower than the plant: its armature is still free where the record ends
    let theta = [78.0, 19.5e-6, -0.77];
    let model = predictor(&design, ["R", "A_gap", "F0"]);
    let s = settings(theta, 5e-5);
    let (free, arrival) = pulse_record(&plant, &s, 24.0);
    assert!(
        arrival.is_some_and(|t| t > 1e-3),
        "the pulse closes the valve: {arrival:?}"
    );
    let run = quiet_run(&design, &plant);
    let cases = [
        (free, false),
        (record(&run, 0, &s), true),
        (record(&run, 1, &s), true),
    ];
    for (k, (r, held)) in cases.iter().enumerate() {
        let held = *held;
        let at = replay(&model, &s, r, &theta, true, held);
        let n = (r.len() - 1) as f64;
        for j in 0..3 {
            if held && j == 2 {
                continue; // the preload does not reach the current of a held armature
            }
            // cost = Σe²/n: ∂cost/∂θ_j = −(2/n)·(Jᵀe)_j/θ_j (J in relative coordinates)
            let analytic = -2.0 / n * at.jte[j] / theta[j];
            let h = 1e-6 * theta[j].abs();
            let cost = |d: f64| {
                let mut t = theta;
                t[j] += d;
                replay(&model, &s, r, &t, false, held).cost
            };
            let central = (cost(h) - cost(-h)) / (2.0 * h);
            let error = (analytic - central).abs() / central.abs().max(1e-30);
            assert!(
                error < 1e-4,
                "case {k} (held: {held}), parameter {j}: analytic {analytic:e}, central {central:e}"
            );
        }
    }
}

/// The record of `volts` switched on at rest at z_max (no controller), cut
/// two samples before the armature reaches z_min; and that arrival time.
fn pulse_record<const P: usize>(
    plant: &Description,
    s: &Settings<f64, P>,
    volts: f64,
) -> (Box<Record<f64, RECORD>>, Option<f64>) {
    let (times, current) = open_loop(plant, volts);
    let arrival = times.1;
    let mut r = Box::new(Record::new());
    r.start(1e-3);
    for (k, (t, i)) in times.0.iter().zip(&current).enumerate() {
        if arrival.is_some_and(|a| *t > a - 2.0 * s.sample_period) {
            break;
        }
        let u = if k == 0 { 0.0 } else { volts };
        r.push(s, u, u, *i);
    }
    (r, arrival)
}

/// `volts` on `plant` from rest at z_max for 14 ms at the 50 µs samples:
/// (the times and the first arrival at a stop) and the currents.
fn open_loop(plant: &Description, volts: f64) -> ((Vec<f64>, Option<f64>), Vec<f64>) {
    use designer::model::{Model, ModelPlant};
    use designer::sim::{simulate, EventKind, Mode, PiecewiseLinear, MAX_DIM};
    let mut model = Model::build(plant);
    let p = ModelPlant::new(&mut model);
    let input = PiecewiseLinear::new(vec![0.0, 0.02], vec![volts, volts]).expect("input");
    let mut x0 = [0.0; MAX_DIM];
    x0[0] = 1e-3;
    let times: Vec<f64> = (0..=280).map(|k| k as f64 * 5e-5).collect();
    let tr = simulate(&p, &input, x0, Mode::StuckMax, &times, &Default::default()).expect("sim");
    let (current, _) = p.currents_and_voltages(&tr.t, &tr.x, &tr.u);
    let arrival = tr.events.iter().find_map(|e| match e.kind {
        EventKind::Impact { .. } | EventKind::Stick { .. } => Some(e.t),
        _ => None,
    });
    ((tr.t.clone(), arrival), current)
}

#[test]
fn a_noise_free_record_gives_back_the_plant_it_was_recorded_on() {
    let design = design();
    // a stop without rebound: the replay's contact is inelastic
    let plant = plant(&[
        ("resistance = 75.0", "resistance = 82.5"),
        ("area = 20e-6", "area = 19e-6"),
        ("restitution = 0.5", "restitution = 0.0"),
    ]);
    let run = quiet_run(&design, &plant);
    let model = predictor(&design, ["R", "A_gap"]);
    let s = settings([75.0, 20e-6], 5e-5);
    let mut theta = s.nominal;
    for _ in 0..6 {
        for k in 0..2 {
            let r = record(&run, k, &s);
            let _ = calibrate(&model, &s, &r, &mut theta);
        }
    }
    let truth = [82.5, 19e-6];
    for (fitted, truth) in theta.iter().zip(truth) {
        assert!(
            (fitted / truth - 1.0).abs() < 2e-3,
            "fitted {theta:?}, the plant {truth:e}"
        );
    }
}

#[test]
fn records_that_are_not_operations_are_refused() {
    let design = design();
    let model = predictor(&design, ["R"]);
    let s = settings([75.0], 5e-5);
    let plant = plant(&[("resistance = 75.0", "resistance = 80.0")]);
    let run = quiet_run(&design, &plant);
    let mut theta = s.nominal;
    let refused =
        |r: &Record<f64, RECORD>, theta: &mut [f64; 1]| match calibrate(&model, &s, r, theta) {
            Outcome::Refused(why) => Some(why),
            Outcome::Updated { .. } => None,
        };
    // an ordinary operation is taken (its first 18 ms: a record of a long
    // rest after the landing holds little of the motion)
    assert_eq!(
        refused(&record_until(&run, 1, &s, 18e-3), &mut theta.clone()),
        None
    );
    // the ADC at its limit
    let low_limit = Settings {
        current_limit: 0.05,
        ..s
    };
    assert_eq!(
        refused(&record_until(&run, 1, &low_limit, 18e-3), &mut theta),
        Some(Refusal::Saturated)
    );
    // a supply that delivered half the command
    let mut dip = Box::new(Record::<f64, RECORD>::new());
    dip.start(1e-3);
    for m in run.measured.iter().take(200) {
        dip.push(&s, m.commanded, 0.5 * m.commanded, m.current);
    }
    assert_eq!(refused(&dip, &mut theta), Some(Refusal::SupplyDip));
    // a few samples only, and a NaN
    let mut short = Box::new(Record::<f64, RECORD>::new());
    short.start(1e-3);
    for m in run.measured.iter().take(10) {
        short.push(&s, m.commanded, m.voltage, m.current);
    }
    assert_eq!(refused(&short, &mut theta), Some(Refusal::TooShort));
    short.push(&s, 1.0, f64::NAN, 0.1);
    assert_eq!(refused(&short, &mut theta), Some(Refusal::NotFinite));
    // 3 V for the whole window: the armature never leaves z_max
    let no_motion = held_record(&plant, &s, 3.0);
    assert_eq!(refused(&no_motion, &mut theta), Some(Refusal::NoMotion));
    assert_eq!(theta, s.nominal, "a refused record leaves θ unchanged");
}

/// A record of `volts` held on the plant at rest at z_max (no controller).
fn held_record(plant: &Description, s: &Settings<f64, 1>, volts: f64) -> Box<Record<f64, RECORD>> {
    let ((_, arrival), current) = open_loop(plant, volts);
    assert_eq!(arrival, None, "{volts} V does not move the armature");
    let mut r = Box::new(Record::new());
    r.start(1e-3);
    for (k, i) in current.iter().enumerate() {
        let u = if k == 0 { 0.0 } else { volts };
        r.push(s, u, u, *i);
    }
    r
}

#[test]
fn every_operation_reaches_its_stop_on_a_plant_the_design_cannot_follow() {
    let design = design();
    // a spring preloaded 60 % harder: the law's takeoff balances the wrong force
    let plant = plant(&[("preload = -0.75", "preload = -1.2")]);
    let runs = run_runs(
        &design,
        None,
        Some(&plant),
        1,
        5e-5,
        Noise::seeded(7),
        &Default::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    for o in &runs[0].operations {
        assert!(
            o.outcome.impact_velocity.is_some(),
            "{:?} never reached its stop",
            o.outcome.operation
        );
    }
}

/// The prediction-error update (`calibrate::innovations`) on one noise-free
/// run of the design on a plant 10 % more resistive with a 5 % smaller gap
/// and a 10 % weaker preload: four updates over the same run lower the
/// innovations every time until no step lowers them, bring R and the gap to the plant's within 3 % and
/// the preload closer to it (its part of the current is small beside the
/// bounces the filter does not model).
#[test]
fn the_innovations_update_moves_towards_the_plant() {
    use designer::calibrate::{candidates, choose, innovations, Adapted, Outcome};
    use reldesign_runtime::calibrate::Calibration;
    let design = design();
    let plant = plant(&[
        ("resistance = 75.0", "resistance = 82.5"),
        ("area = 20e-6", "area = 19e-6"),
        ("preload = -0.75", "preload = -0.675"),
    ]);
    let run = quiet_run(&design, &plant);
    let keys = ["coil.resistance", "gap.area", "mechanics.preload"];
    let adapted: Vec<Adapted> = candidates(&design.description)
        .into_iter()
        .filter(|c| keys.contains(&c.key))
        .map(|c| Adapted {
            key: c.key,
            symbol: c.symbol,
            nominal: c.nominal,
            lower: (0.7 * c.nominal).min(1.3 * c.nominal),
            upper: (0.7 * c.nominal).max(1.3 * c.nominal),
            new_information: 1.0,
        })
        .collect();
    let mut c = choose(&design, 5e-5).unwrap_or_else(|e| panic!("{e}"));
    c.parameters = adapted;
    c.iterations = 4;
    let mut calibration = Calibration::<f64, 3>::new(&c.settings());
    for k in 0..4 {
        let u = innovations::update(&design, &c, &mut calibration, &run.measured)
            .unwrap_or_else(|e| panic!("{e}"));
        match u {
            Outcome::Updated { before, after } => assert!(after < before, "{u:?}"),
            // converged: no step lowers the error any more
            Outcome::Refused(Refusal::NoProgress) if k > 0 => {}
            _ => panic!("update {k}: {u:?}"),
        }
    }
    let truth = [82.5, 19e-6, -0.675];
    for ((a, fitted), truth) in c.parameters.iter().zip(&calibration.theta).zip(truth) {
        let closer = (fitted - truth).abs() < (a.nominal - truth).abs();
        let near = (fitted / truth - 1.0).abs() < 0.03 || a.key == "mechanics.preload";
        assert!(
            closer && near,
            "{}: {fitted:e}, the plant's {truth:e}",
            a.key
        );
    }
}

/// `Calibration::unexplained` counts the updates in a row that leave more
/// than `Settings::unexplained` of the current unexplained: not on the
/// record of the plant (noise-free), on each record whose current carries a
/// 1 kHz (1.3 kHz) ripple of 20 mA that no θ explains, and from 0 again after the
/// plain record.
#[test]
fn the_calibration_counts_updates_that_leave_the_current_unexplained() {
    use reldesign_runtime::calibrate::Calibration;
    let design = design();
    let model = predictor(&design, ["R"]);
    let s = Settings {
        // (5 mA)²: the ripple's mean square is (20 mA)²/2
        unexplained: 25e-6,
        ..settings([75.0], 5e-5)
    };
    let plant = plant(&[("resistance = 75.0", "resistance = 80.0")]);
    let run = quiet_run(&design, &plant);
    let plain = record_until(&run, 1, &s, 18e-3);
    let (_, start) = run.operations[1];
    let rippled = |hz: f64| {
        let mut r = Box::new(Record::<f64, RECORD>::new());
        r.start(0.0);
        for m in (run.measured.iter()).filter(|m| m.t >= start - 1e-12 && m.t < start + 18e-3) {
            let ripple = 0.02 * (2.0 * std::f64::consts::PI * hz * (m.t - start)).sin();
            r.push(&s, m.commanded, m.voltage, m.current + ripple);
        }
        r
    };
    let mut calibration = Calibration::new(&s);
    let mut counts = Vec::new();
    for r in [&plain, &rippled(1e3), &rippled(1.3e3), &plain] {
        let outcome = calibration.update(&model, &s, r);
        assert!(
            matches!(outcome, Outcome::Updated { .. }),
            "{outcome:?} after {counts:?}"
        );
        counts.push(calibration.unexplained);
    }
    assert_eq!(counts, [0, 1, 2, 0]);
    calibration.reset(&s);
    assert_eq!(calibration.unexplained, 0);
}
