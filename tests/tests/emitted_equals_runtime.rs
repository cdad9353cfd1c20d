//! The controller `reldesign loop` and `sweep` run (the runtime's own logic on
//! the designer's run-time design, `designer::design::RuntimePlan`) equals the
//! emitted, compiled code (`generated/`), at random states and times, for both
//! laws and both floats: the sliding-mode law bit for bit in f64, the
//! feedback-linearizing law to 1e-9 (tape against emitted arithmetic).

use designer::description::{parse_file, Operation};
use designer::design::{Design, RuntimePlan};
use designer::random::SplitMix64;
use reldesign_generated::{perfect_tracking_valve as pt, sliding_mode_valve as sm};
use support::example_path;

fn design(example: &str) -> Design {
    Design::new(&parse_file(&example_path(example)).unwrap()).unwrap_or_else(|e| panic!("{e}"))
}

/// A random (t, z, v, a, φ) over the operation and the stroke, with the
/// stops and the rest states often hit exactly.
fn state(rng: &mut SplitMix64, z_max: f64, t_end: f64) -> [f64; 5] {
    let pick = |rng: &mut SplitMix64, exact: &[f64], lo: f64, hi: f64| {
        let k = (rng.uniform() * (exact.len() + 2) as f64) as usize;
        exact
            .get(k)
            .copied()
            .unwrap_or(lo + (hi - lo) * rng.uniform())
    };
    [
        t_end * rng.uniform(),
        pick(rng, &[0.0, z_max], 0.0, z_max),
        pick(rng, &[0.0], -0.5, 0.5),
        pick(rng, &[0.0], -2000.0, 2000.0),
        pick(rng, &[0.0], -3e-5, 3e-5),
    ]
}

#[test]
fn sliding_mode_runtime_plan_equals_the_emitted_controller() {
    let d = design("sliding-mode-valve.toml");
    let c = d.controller.as_ref().unwrap();
    let mut model = d.model.clone();
    let mut rng = SplitMix64::new(14);
    let (mut f32_disagree, n) = (0, 20_000);
    for k in 0..n {
        let closing = k % 2 == 0;
        let op = if closing {
            Operation::Closing
        } else {
            Operation::Opening
        };
        let mut reference = RuntimePlan::new(&mut model, c).controller(op);
        let (op64, op32) = if closing {
            (sm::f64::Operation::Closing, sm::f32::Operation::Closing)
        } else {
            (sm::f64::Operation::Opening, sm::f32::Operation::Opening)
        };
        let (mut e64, mut e32) = (
            sm::f64::Controller::new(op64),
            sm::f32::Controller::new(op32),
        );
        let [t, z, v, a, phi] = state(&mut rng, 1e-3, 6e-3);
        let want = reference.step(t, [z, v, phi, 0.0], a);
        assert_eq!(
            e64.step(t, z, v, a, phi),
            want,
            "f64 at {:?}",
            [t, z, v, a, phi]
        );
        let got32 = f64::from(e32.step(t as f32, z as f32, v as f32, a as f32, phi as f32));
        f32_disagree += usize::from(got32 != want);
    }
    // f32 can only flip the switch where s is within its rounding of 0
    assert!(f32_disagree * 1000 < n, "{f32_disagree} of {n}");
}

#[test]
fn feedback_linearization_runtime_plan_equals_the_emitted_controller() {
    let d = design("perfect-tracking-valve.toml");
    let c = d.controller.as_ref().unwrap();
    let mut model = d.model.clone();
    let mut rng = SplitMix64::new(15);
    for k in 0..5_000 {
        let closing = k % 2 == 0;
        let op = if closing {
            Operation::Closing
        } else {
            Operation::Opening
        };
        let mut reference = RuntimePlan::new(&mut model, c).controller(op);
        let mut emitted = pt::f64::Controller::new(if closing {
            pt::f64::Operation::Closing
        } else {
            pt::f64::Operation::Opening
        });
        let [t, z, v, a, phi] = state(&mut rng, 1e-3, 7e-3);
        let want = reference.step(t, [z, v, phi, 0.0], a);
        let got = emitted.step(t, z, v, phi);
        assert!(
            (got - want).abs() <= 1e-9 * want.abs().max(1.0),
            "{got} vs {want} at {:?}",
            [t, z, v, phi]
        );
    }
}

/// [SM 43] and [SM 35] at both stops, in the emitted code: closing at z_min
/// holds with u_max·sgn φ, opening at z_max gives 0, and at rest on the
/// reference (s = 0) sgn* is −1 at z_min, +1 at z_max.
#[test]
fn emitted_sliding_mode_keeps_the_hybrid_rules() {
    use sm::f64::{Controller, Operation::*, U_MAX};
    let (z_min, z_max) = (sm::f64::Z_MIN, sm::f64::Z_MAX);
    assert_eq!(
        Controller::new(Closing).step(3e-3, z_min, 0.0, 0.0, 1e-5),
        U_MAX
    );
    assert_eq!(
        Controller::new(Closing).step(3e-3, z_min, 0.0, 0.0, -1e-5),
        -U_MAX
    );
    assert_eq!(
        Controller::new(Opening).step(3e-3, z_max, 0.0, 0.0, 1e-5),
        0.0
    );
    // before takeoff, at rest on the reference: s = 0
    assert_eq!(
        Controller::new(Opening).step(0.5e-3, z_min, 0.0, 0.0, 1e-5),
        -U_MAX
    );
    assert_eq!(
        Controller::new(Closing).step(0.5e-3, z_max, 0.0, 0.0, 1e-5),
        U_MAX
    );
}
