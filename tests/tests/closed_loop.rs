//! The generated controller (generated/, f64 and f32) in closed loop with the
//! hybrid simulator on the perfect-tracking valve: closing and opening,
//! t₀ = 1 ms, t_f = 6 ms, u ∈ [−24, 24] V, trajectory bound 20 V, 1 ms
//! settling time (perfect-tracking-soft-landing [PT §5]).

use designer::model::{Model, ModelPlant};
use designer::sim::{simulate_sampled, Limit, Measurement, Mode, Options};
use reldesign_generated::perfect_tracking_valve::{f32 as c32, f64 as c64};
use reldesign_tests::{example, impacts};

/// RMSE of z during the motion (perfect-tracking-soft-landing [PT 69], with the
/// square root of the errata), the equivalent impact velocity v_eq [PT 70], the
/// largest landing speed and the number of bounces at the destination.
#[derive(Debug)]
pub struct Outcome {
    pub rmse_z: f64,
    pub v_eq: f64,
    pub landing_speed: f64,
    pub bounces: usize,
    pub final_mode: Mode,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Law {
    /// The generated feedback-linearizing controller, f64.
    Generated64,
    /// The same, f32.
    Generated32,
    /// The paper's comparison [PT 67–68]: u = −U·sgn(s), s = (d/dt + λ)²(z_r − z).
    SlidingMode,
}

const T0: f64 = 1e-3;
const TF: f64 = 6e-3;

fn run(closing: bool, ts: f64, law: Law) -> Outcome {
    let d = example("perfect-tracking-valve.toml");
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    let (z_min, z_max) = (d.mechanics.z_min, d.mechanics.z_max);
    // Closing starts at rest at z_max with no flux; opening starts held at z_min
    // with 20 % more flux than the force balance needs (an initial ξ₃ error, [PT §5.1]).
    let mu0_a = 4e-7 * std::f64::consts::PI * 20e-6;
    let hold_flux = (2.0 * -(d.mechanics.preload + d.mechanics.stiffness * z_min) * mu0_a).sqrt();
    let (x0, mode0) = if closing {
        ([z_max, 0.0, 0.0, 0.0], Mode::StuckMax)
    } else {
        ([z_min, 0.0, 1.2 * hold_flux, 0.0], Mode::StuckMin)
    };
    let (op64, op32) = if closing {
        (c64::Operation::Closing, c32::Operation::Closing)
    } else {
        (c64::Operation::Opening, c32::Operation::Opening)
    };
    let (mut k64, mut k32) = (c64::Controller::new(op64), c32::Controller::new(op32));
    let mut reference = c64::Controller::new(op64);
    let mut sliding_reference = c64::Controller::new(op64);
    let (lambda, u_sm) = (4745.0, 24.0);
    let z_f = if closing { z_min } else { z_max };
    let mut control = |t: f64, m: &Measurement| match law {
        Law::Generated64 => k64.step(t, m.x[0], m.x[1], m.x[2]),
        Law::Generated32 => {
            f64::from(k32.step(t as f32, m.x[0] as f32, m.x[1] as f32, m.x[2] as f32))
        }
        Law::SlidingMode => {
            // the paper's reference [PT 51]: z_f at rest after t_f
            let [zr, vr, ar, _] = if t > TF {
                [z_f, 0.0, 0.0, 0.0]
            } else {
                sliding_reference.reference(t)
            };
            let mut dx = [0.0; 4];
            designer::sim::Plant::deriv(&plant, t, &m.x, 0.0, &mut dx);
            // [PT 67] s = (ä_r − a) + 2λ(v_r − v) + λ²(z_r − z), a = T₃(x) [PT 41]
            let s = (ar - dx[1]) + 2.0 * lambda * (vr - m.x[1]) + lambda * lambda * (zr - m.x[0]);
            -u_sm * s.signum() // [PT 68]
        }
    };
    let options = Options {
        rtol: 1e-10,
        ..Options::default()
    };
    let tr =
        simulate_sampled(&plant, &mut control, ts, 10e-3, x0, mode0, &options).expect("simulation");
    let (mut sum, mut n) = (0.0, 0usize);
    for (t, x) in tr.t.iter().zip(&tr.x) {
        if (T0..=TF).contains(t) {
            sum += (x[0] - reference.reference(*t)[0]).powi(2);
            n += 1;
        }
    }
    let destination = if closing { Limit::Min } else { Limit::Max };
    let (mut v2, mut landing_speed, mut bounces) = (0.0, 0.0f64, 0);
    for (v_before, v_after) in impacts(&tr.events, destination, T0, f64::INFINITY) {
        v2 += v_before * v_before;
        landing_speed = landing_speed.max(v_before);
        bounces += usize::from(v_after != 0.0);
    }
    Outcome {
        rmse_z: (sum / n as f64).sqrt(),
        v_eq: v2.sqrt(),
        landing_speed,
        bounces,
        final_mode: *tr.mode.last().unwrap(),
    }
}

/// The nominal targets: RMSE ≤ 5 nm at Ts = 1 µs and ≤ 50 nm at
/// 10 µs, landing ≤ 1 mm/s, no bounce (an independent reference reaches 1.5
/// and 12 nm), for the generated f64 and f32 code, closing and opening.
#[test]
fn generated_controller_soft_lands_nominally() {
    for law in [Law::Generated64, Law::Generated32] {
        for closing in [true, false] {
            for (ts, rmse_max) in [(1e-6, 5e-9), (10e-6, 50e-9)] {
                let o = run(closing, ts, law);
                let what = format!(
                    "{law:?} {} Ts = {ts:e}: {o:?}",
                    if closing { "closing" } else { "opening" }
                );
                eprintln!("{what}");
                assert!(o.rmse_z <= rmse_max, "{what}");
                assert!(o.landing_speed <= 1e-3 && o.bounces == 0, "{what}");
                assert_eq!(
                    o.final_mode,
                    if closing {
                        Mode::StuckMin
                    } else {
                        Mode::StuckMax
                    },
                    "{what}"
                );
            }
        }
    }
}

/// The sampling sweep of [PT Fig. 7]: feedback linearization beats the sliding-mode
/// controller [PT 67–68] in RMSE_z at every sampling period, and in v_eq
/// wherever the sliding mode lands at all (at Ts ≤ 5 µs its closing hovers
/// nanometres above the stop and never completes: v_eq = 0 there means "did
/// not land", and the test requires FL to land instead).
#[test]
fn feedback_linearization_beats_sliding_mode_at_every_sampling_period() {
    eprintln!(
        "{:>6} {:>8} {:>12} {:>12} {:>12} {:>12}",
        "op", "Ts [µs]", "RMSE FL [m]", "RMSE SM [m]", "v_eq FL", "v_eq SM"
    );
    for closing in [true, false] {
        for ts_us in [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0] {
            let ts = ts_us * 1e-6;
            let fl = run(closing, ts, Law::Generated64);
            let sm = run(closing, ts, Law::SlidingMode);
            let op = if closing { "close" } else { "open" };
            eprintln!(
                "{op:>6} {ts_us:>8} {:>12.3e} {:>12.3e} {:>12.3e} {:>12.3e}",
                fl.rmse_z, sm.rmse_z, fl.v_eq, sm.v_eq
            );
            assert!(
                fl.rmse_z < sm.rmse_z,
                "{op} Ts = {ts_us} µs: RMSE FL {fl:?} vs SM {sm:?}"
            );
            let destination = if closing {
                Mode::StuckMin
            } else {
                Mode::StuckMax
            };
            if sm.v_eq > 0.0 {
                assert!(
                    fl.v_eq < sm.v_eq,
                    "{op} Ts = {ts_us} µs: v_eq FL {fl:?} vs SM {sm:?}"
                );
            } else {
                // The sliding mode never reached the end stop (it hovers above
                // it): the operation is not completed, while FL lands.
                assert!(
                    fl.v_eq > 0.0 && fl.final_mode == destination,
                    "{op} Ts = {ts_us} µs: FL {fl:?}"
                );
                eprintln!("        (sliding mode never reached the end stop)");
            }
        }
    }
}
