//! The sensorless, self-calibrating driver (`firmware_example::self_calibrating`)
//! in closed loop with the emitted file's own discretised model as the valve
//! (`ukf::f32::transition` / `measurement` at a θ 10 % more resistive than the
//! design, the armature clamped to its stops): a run of two operations from
//! the coil's voltage and current alone, then the update between runs.

use firmware_example::self_calibrating::{Operation, SelfCalibratingValve};
use firmware_example::sensorless_via_build_script::ukf::f32 as model;
use reldesign_runtime::calibrate::{Outcome, Refusal};

/// The build script wrote exactly the checked-in file.
#[test]
fn the_build_script_output_is_the_checked_in_file() {
    let built = include_str!(concat!(env!("OUT_DIR"), "/self_calibrating_valve.rs"));
    let checked = include_str!("../../../generated/src/self_calibrating_valve.rs");
    assert!(
        built == checked,
        "build.rs output differs from generated/src/self_calibrating_valve.rs"
    );
}

/// The valve: the emitted model at `theta`, its input held over each sample.
struct Plant {
    theta: [f32; 10],
    x: [f32; 3],
}

impl Plant {
    fn at_rest(theta: [f32; 10]) -> Plant {
        Plant {
            theta,
            x: [model::Z_MAX, model::Z_MAX, 0.0],
        }
    }

    /// u over one sample; the current after it.
    fn sample(&mut self, u: f32) -> f32 {
        let [z, zp, phi] = self.x;
        let o = model::transition(z, zp, phi, u, &self.theta);
        self.x = [o.z_next, o.zp_next, o.phi_next];
        model::measurement(self.x[0], self.x[1], self.x[2], u, &self.theta).i
    }
}

/// One run (closing, then opening, each `window` samples): the z reached at
/// the end of each operation.
fn run(valve: &mut SelfCalibratingValve, plant: &mut Plant, window: usize) -> [f32; 2] {
    let mut reached = [f32::NAN; 2];
    let mut u = 0.0;
    let mut i = plant.sample(0.0);
    for (k, op) in [Operation::Closing, Operation::Opening]
        .into_iter()
        .enumerate()
    {
        valve.command(op);
        for _ in 0..window {
            u = valve.tick(u, i);
            assert!(u.is_finite() && (-24.0..=24.0).contains(&u), "u = {u}");
            i = plant.sample(u);
        }
        reached[k] = plant.x[0];
    }
    reached
}

#[test]
fn a_run_lands_and_the_update_moves_r_towards_the_valve() {
    let mut theta = model::THETA_DESIGN;
    theta[0] *= 1.1; // coil.resistance
    assert_eq!(model::ADAPTED[0], "coil.resistance");
    let mut valve = SelfCalibratingValve::new();
    let mut plant = Plant::at_rest(theta);
    // the design's window: 25 ms a operation at 50 µs
    let window = (model::RECORD_CAPACITY - 1) / 2;
    let reached = run(&mut valve, &mut plant, window);
    assert!(
        reached[0] <= model::Z_MIN + 1e-6,
        "the closing ended at z = {}",
        reached[0]
    );
    assert!(
        reached[1] >= model::Z_MAX - 1e-6,
        "the opening ended at z = {}",
        reached[1]
    );
    let outcome = valve.calibrate();
    assert!(matches!(outcome, Outcome::Updated { .. }), "{outcome:?}");
    // a noise-free valve of the model's own family is explained
    assert_eq!(valve.calibration().unexplained, 0);
    assert!(!valve.unexplained());
    let r = valve.calibration().theta[0];
    let (design, truth) = (model::THETA_DESIGN[0], theta[0]);
    assert!(
        (r - truth).abs() < 0.5 * (design - truth).abs(),
        "R: {design} → {r}, the valve's {truth}"
    );
    // the way back
    valve.reset_calibration();
    assert_eq!(valve.calibration().theta, model::THETA_DESIGN);
}

#[test]
fn a_record_that_is_not_a_run_changes_nothing() {
    let mut valve = SelfCalibratingValve::new();
    // nothing recorded
    assert_eq!(valve.calibrate(), Outcome::Refused(Refusal::TooShort));
    // a saturated ADC
    valve.command(Operation::Closing);
    for _ in 0..model::RECORD_CAPACITY {
        valve.tick(24.0, 5.0);
    }
    assert_eq!(valve.calibrate(), Outcome::Refused(Refusal::Saturated));
    assert_eq!(valve.calibration().theta, model::THETA_DESIGN);
    assert_eq!(valve.calibration().refusals, 2);
}
