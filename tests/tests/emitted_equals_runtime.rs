//! The controller `reldesign loop` and `sweep` run (the runtime's own logic on
//! the designer's run-time design, `designer::design::RuntimePlan` and
//! `RuntimeHold`, `RuntimeBackstepping`) equals the emitted, compiled code
//! (`generated/`), at random states and times, for the four laws and both
//! floats: the sliding-mode law bit for bit in f64, the feedback-linearizing
//! law, the position hold of the model-based sliding mode and the
//! backstepping law to 1e-9 (tape against emitted arithmetic).

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

/// A random observed state [z, v, φ, H_c] of the Jiles–Atherton valve's
/// hold: z over the stroke, at the stops, on the edges of the stop band and at
/// the position; v up to ±0.5 m/s; φ over ±twice the holding flux, tiny
/// (|φ| ≤ 10⁻⁷ Wb on a log scale, either sign, around the guard) or 0;
/// H_c within ±2000 A/m. A third of the states lie near the hold (z within
/// 20 µm of the position, |v| ≤ 5 mm/s, φ within 5 % of the holding flux),
/// where the law is not saturated.
fn hold_state(rng: &mut SplitMix64, h: &designer::design::HoldDesign) -> [f64; 4] {
    let mut r = |lo: f64, hi: f64| lo + (hi - lo) * rng.uniform();
    let band = h.landed_band;
    if r(0.0, 3.0) < 1.0 {
        return [
            h.position + r(-20e-6, 20e-6),
            r(-5e-3, 5e-3),
            h.holding_flux * r(0.95, 1.05),
            r(-2000.0, 2000.0),
        ];
    }
    let z = match r(0.0, 8.0) as u32 {
        0 => h.z_min,
        1 => h.z_max,
        2 => [h.z_min + band, h.z_max - band, h.position][(r(0.0, 3.0)) as usize],
        _ => r(h.z_min, h.z_max),
    };
    let v = if r(0.0, 5.0) < 1.0 { 0.0 } else { r(-0.5, 0.5) };
    let sign = if r(0.0, 1.0) < 0.5 { -1.0 } else { 1.0 };
    let phi = match r(0.0, 6.0) as u32 {
        0 => 0.0,
        1 | 2 => sign * 10f64.powf(r(-14.0, -7.0)),
        3 => h.phi_guard,
        _ => r(-2.0, 2.0) * h.holding_flux,
    };
    [z, v, phi, r(-2000.0, 2000.0)]
}

/// The position hold [JA 89], [JA 94] the designer runs (`RuntimeHold`: the
/// runtime's `PositionHold` on the law's tape) equals the emitted one at
/// 20 000 random states: f64 bit for bit where the output is saturated or
/// decided by a rule (stop, guard), and within 1e-9 relative where the law
/// is evaluated (tape against emitted arithmetic: 7e-12 at worst). f32 (the
/// states rounded to f32, against the f64 reference at the exact ones) stays
/// within 1e-4 of u_max (2.4 mV, below one step of a 12-bit PWM of the
/// supply): 1.8 mV at worst, at φ twice the guard where β ∝ 1/φ is largest,
/// 25 µV near the hold. f32 can only disagree by more where a rule's
/// decision flips inside the f32 rounding of z, φ or of the decision's
/// constant: z within ~1e-10 m of a stop band's edge (in f32
/// z_max − LANDED_BAND rounds to z_max) or φ within ~1e-15 Wb of PHI_GUARD.
/// The exact edges sampled here decide alike (no state disagrees); at most
/// 0.1 % of the states may.
#[test]
fn hold_runtime_equals_the_emitted_controller() {
    use reldesign_generated::jiles_atherton_valve as ja;
    let d = design("jiles-atherton-valve.toml");
    let h = d.hold.as_ref().expect("the example designs a hold");
    let mut model = d.model.clone();
    let reference = designer::design::RuntimeHold::new(&mut model, h).controller();
    let (e64, e32) = (ja::f64::Controller::new(), ja::f32::Controller::new());
    let mut rng = SplitMix64::new(16);
    let n = 20_000;
    let (mut law, mut f32_disagree, mut worst64, mut worst32) = (0, 0, 0.0f64, 0.0f64);
    for _ in 0..n {
        let x = hold_state(&mut rng, h);
        let [z, v, phi, hc] = x;
        let want = reference.step(z, v, phi, hc);
        assert!((0.0..=h.u_max).contains(&want), "{want} at {x:?}");
        let got = e64.step(z, v, phi, hc);
        if want > 0.0 && want < h.u_max {
            law += 1;
            let rel = (got - want).abs() / want;
            worst64 = worst64.max(rel);
            assert!(rel <= 1e-9, "f64 {got} vs {want} at {x:?}");
        } else {
            assert_eq!(got, want, "f64 at {x:?}");
        }
        let [z, v, phi, hc] = x.map(|a| a as f32);
        let got32 = f64::from(e32.step(z, v, phi, hc));
        let d = (got32 - want).abs();
        if d <= 1e-4 * h.u_max {
            worst32 = worst32.max(d);
        } else {
            f32_disagree += 1;
        }
    }
    // a third of the states lie near the hold: the law is not saturated there
    assert!(
        law * 4 > n,
        "the law ran unsaturated at {law} of {n} states"
    );
    assert!(f32_disagree * 1000 <= n, "f32: {f32_disagree} of {n}");
    eprintln!(
        "hold: {law} of {n} states unsaturated; f64 within {worst64:.1e} relative, \
         f32 within {worst32:.1e} V ({f32_disagree} beyond 1e-4·u_max)"
    );
}

/// The backstepping controller [SB 19] with its hybrid switching [SB 31–33]
/// the designer runs (`RuntimeBackstepping`: the runtime's
/// `SwitchedBackstepping` on the law's tape) equals the emitted one along
/// 20 000 samples of random states at increasing times (two periods of the
/// square reference): the same switching mode at every sample, f64 bit for
/// bit where the output is decided by a rule (waiting, guard, saturation)
/// and within 1e-9 relative where the law is evaluated; f32 (the states
/// rounded to f32) within 1e-4 of u_max at all but 0.1 % of the samples
/// (a rule's decision can flip inside the f32 rounding of V ≤ C or F_d's
/// sign). F_d and u of the law alone are compared too.
#[test]
fn backstepping_runtime_equals_the_emitted_controller() {
    use reldesign_generated::backstepping_valve as bs;
    use reldesign_runtime::backstepping::Backstepping;
    let d = design("backstepping-valve.toml");
    let b = d
        .backstepping
        .as_ref()
        .expect("the example designs backstepping");
    let mut model = d.model.clone();
    let plan = designer::design::RuntimeBackstepping::new(&mut model, b);
    let mut reference = designer::design::RuntimeBackstepping::new(&mut model, b).controller();
    let (mut e64, mut e32) = (bs::f64::Controller::new(), bs::f32::Controller::new());
    let mut rng = SplitMix64::new(17);
    let n = 20_000;
    let t_end = 2.0 * bs::f64::PERIOD;
    let (mut law, mut f32_disagree, mut worst64, mut worst32) = (0, 0, 0.0f64, 0.0f64);
    let (flux, u_max) = (b.holding[0].0, b.u_max);
    for k in 0..n {
        let t = t_end * k as f64 / n as f64;
        let r = |rng: &mut SplitMix64, lo: f64, hi: f64| lo + (hi - lo) * rng.uniform();
        // half the samples near a target (the law runs), half anywhere
        let near = k % 2 == 0;
        let z = if near {
            r(&mut rng, 3.5e-4, 7.5e-4)
        } else {
            r(&mut rng, 0.0, b.z_max)
        };
        let v = if near {
            r(&mut rng, -0.02, 0.02)
        } else {
            r(&mut rng, -1.0, 1.0)
        };
        let phi = if near {
            flux * r(&mut rng, 0.9, 1.15)
        } else {
            r(&mut rng, -2.0, 2.0) * flux
        };
        let y_r = if near {
            4e-4
        } else {
            r(&mut rng, 0.0, b.z_max)
        };
        // the law and F_d alone
        let (want_law, got_law) = (
            plan.law([z, v, phi, 0.0], y_r),
            bs::f64::law(z, v, phi, y_r),
        );
        assert!(
            (got_law - want_law).abs() <= 1e-9 * want_law.abs().max(1.0),
            "law {got_law} vs {want_law}"
        );
        let (want_fd, got_fd) = (
            plan.desired_force(z, v, y_r),
            bs::f64::desired_force(z, v, y_r),
        );
        assert!(
            (got_fd - want_fd).abs() <= 1e-12 * want_fd.abs().max(1.0),
            "F_d {got_fd} vs {want_fd}"
        );
        // the controllers, stepped alike
        let want = reference.step(t, z, v, phi, 0.0);
        let got = e64.step(t, z, v, phi, 0.0);
        assert_eq!(
            format!("{:?}", e64.mode()),
            format!("{:?}", reference.mode()),
            "mode at t = {t}"
        );
        if want > b.u_min && want < u_max && want != 0.0 {
            law += 1;
            let rel = (got - want).abs() / want.abs();
            worst64 = worst64.max(rel);
            assert!(rel <= 1e-9, "f64 {got} vs {want} at t = {t}");
        } else {
            assert_eq!(got, want, "f64 at t = {t}");
        }
        let got32 = f64::from(e32.step(t as f32, z as f32, v as f32, phi as f32, 0.0));
        let dev = (got32 - want).abs();
        if dev <= 1e-4 * u_max {
            worst32 = worst32.max(dev);
        } else {
            f32_disagree += 1;
        }
    }
    assert!(
        law * 10 > n,
        "the law ran unsaturated at {law} of {n} samples"
    );
    assert!(f32_disagree * 1000 <= n, "f32: {f32_disagree} of {n}");
    eprintln!(
        "backstepping: {law} of {n} samples by the law; f64 within {worst64:.1e} relative, \
         f32 within {worst32:.1e} V ({f32_disagree} beyond 1e-4·u_max)"
    );
}

/// The emitted backstepping controller, f64 and f32, drives the sampled loop
/// on the valve's hybrid model (two periods of the square reference, from
/// rest on z_max) as the run-time one does: the same modes, the position
/// within 1e-9 m (f64) and 1e-7 m (f32, 10⁻⁴ of the stroke) of the
/// run-time loop's at every sample.
#[test]
fn emitted_backstepping_drives_the_loop_as_the_runtime_one() {
    use designer::backstepping_loop::run_backstepping;
    use designer::closed_loop::Noise;
    use designer::model::{Model, ModelPlant};
    use designer::sim::{simulate_sampled, Measurement, Mode, Options, MAX_DIM};
    use reldesign_generated::backstepping_valve as bs;
    let d = design("backstepping-valve.toml");
    let b = d.backstepping.as_ref().expect("backstepping");
    let ts = b.sample_period;
    let reference = run_backstepping(
        &d,
        None,
        ts,
        None,
        Noise::seeded(0),
        None,
        &Options::default(),
    )
    .expect("the run-time loop runs");
    let want = &reference.run.trajectory;
    let mut model = Model::build(&d.description);
    let plant = ModelPlant::new(&mut model);
    let mut x0 = [0.0; MAX_DIM];
    x0[0] = b.z_max;
    let t_end = *want.t.last().expect("samples");
    let (mut c64, mut c32) = (bs::f64::Controller::new(), bs::f32::Controller::new());
    let mut modes = Vec::new();
    let mut step64 = |_t: f64, m: &Measurement| {
        let u = c64.step(m.t, m.x[0], m.x[1], m.x[2], 0.0);
        modes.push(format!("{:?}", c64.mode()));
        u
    };
    let got64 = simulate_sampled(
        &plant,
        &mut step64,
        ts,
        t_end,
        x0,
        Mode::StuckMax,
        &Options::default(),
    )
    .expect("the f64 loop runs");
    let mut step32 = |_t: f64, m: &Measurement| {
        let u = c32.step(m.t as f32, m.x[0] as f32, m.x[1] as f32, m.x[2] as f32, 0.0);
        f64::from(u)
    };
    let got32 = simulate_sampled(
        &plant,
        &mut step32,
        ts,
        t_end,
        x0,
        Mode::StuckMax,
        &Options::default(),
    )
    .expect("the f32 loop runs");
    assert_eq!(got64.t.len(), want.t.len());
    let want_modes: Vec<String> = reference.modes.iter().map(|m| format!("{m:?}")).collect();
    assert_eq!(modes, want_modes, "the switching modes");
    let worst = |got: &designer::sim::Trajectory| {
        (0..want.t.len()).fold(0.0f64, |w, k| w.max((got.x[k][0] - want.x[k][0]).abs()))
    };
    let (w64, w32) = (worst(&got64), worst(&got32));
    assert!(w64 <= 1e-9, "f64: max |Δz| = {w64:e} m");
    assert!(w32 <= 1e-7, "f32: max |Δz| = {w32:e} m");
    eprintln!(
        "backstepping loop: max |Δz| f64 {w64:.1e} m, f32 {w32:.1e} m over {} samples",
        want.t.len()
    );
}
