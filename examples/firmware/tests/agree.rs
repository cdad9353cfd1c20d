//! The three ways to get the controller agree: the `design!` macro, the
//! `build.rs` route (`reldesign_build::compile`) and the checked-in output of
//! `reldesign build` (`reldesign_generated`) give bit-identical control
//! inputs for a grid of states, references and times, in f32 and in f64.

use firmware_example::{perfect_tracking_valve as via_macro, pwm_compare, via_build_script, Valve};
use reldesign_generated::perfect_tracking_valve as checked_in;

/// The build script wrote exactly the checked-in file.
#[test]
fn the_build_script_output_is_the_checked_in_file() {
    let built = include_str!(concat!(env!("OUT_DIR"), "/perfect_tracking_valve.rs"));
    let checked = include_str!("../../../generated/src/perfect_tracking_valve.rs");
    assert!(
        built == checked,
        "build.rs output differs from generated/src/perfect_tracking_valve.rs \
         (is the checked-in file stale? see generated/tests/fresh.rs)"
    );
}

macro_rules! agreement {
    ($module:ident, $float:ident, $law:ident, $steps:ident, $constants:ident) => {
        mod $module {
            use super::*;

            /// Same bits; any NaN equals any NaN (payloads are not specified).
            pub fn same(a: $float, b: $float) -> bool {
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
            }

            pub fn states() -> Vec<[$float; 3]> {
                let zs = [-1e-4, 0.0, 1e-12, 1e-6, 2e-4, 5e-4, 8e-4, 1e-3, 1.1e-3];
                let vs = [-2.0, -0.3, 0.0, 0.3, 2.0];
                let phis = [
                    -3e-5,
                    -1e-6,
                    0.0,
                    1e-9,
                    2e-9,
                    3e-9,
                    5e-7,
                    1e-5,
                    2.4e-5,
                    3e-5,
                    $float::NAN,
                ];
                let mut out = Vec::new();
                for &z in &zs {
                    for &v in &vs {
                        for &phi in &phis {
                            out.push([z, v, phi]);
                        }
                    }
                }
                out
            }

            /// The references of both operations on a time grid around [t₀, t_f].
            pub fn references() -> Vec<[$float; 4]> {
                let mut out = Vec::new();
                for op in [
                    checked_in::$float::Operation::Closing,
                    checked_in::$float::Operation::Opening,
                ] {
                    let mut c = checked_in::$float::Controller::new(op);
                    for k in 0..=40 {
                        out.push(c.reference(k as $float * 2e-4));
                    }
                }
                out
            }

            #[test]
            fn $law() {
                let (mut n, mut inside) = (0, 0);
                for [z, v, phi] in states() {
                    for [zr, vr, ar, jr] in references() {
                        let a = via_macro::$float::law(z, v, phi, zr, vr, ar, jr);
                        let b = via_build_script::$float::law(z, v, phi, zr, vr, ar, jr);
                        let c = checked_in::$float::law(z, v, phi, zr, vr, ar, jr);
                        assert!(
                            same(a, c) && same(b, c),
                            "law{:?}: {a:e} {b:e} {c:e}",
                            (z, v, phi, zr, vr, ar, jr)
                        );
                        let a = via_macro::$float::guarded_law(z, v, phi, zr, vr, ar, jr);
                        let b = via_build_script::$float::guarded_law(z, v, phi, zr, vr, ar, jr);
                        let c = checked_in::$float::guarded_law(z, v, phi, zr, vr, ar, jr);
                        assert!(
                            same(a, c) && same(b, c),
                            "guarded_law{:?}: {a:e} {b:e} {c:e}",
                            (z, v, phi, zr, vr, ar, jr)
                        );
                        n += 1;
                        // Not vacuous: the guard and the saturation leave room.
                        if c.is_finite()
                            && c > checked_in::$float::U_MIN
                            && c < checked_in::$float::U_MAX
                        {
                            inside += 1;
                        }
                    }
                }
                assert!(n > 10_000);
                assert!(inside > n / 20, "{inside} of {n} inputs unsaturated");
            }

            #[test]
            fn $steps() {
                let states = states();
                for (start, op) in [(0.0, 0), (0.25, 0), (0.0, 1), (1.5, 1)] {
                    let mut a = via_macro::$float::Controller::new(if op == 0 {
                        via_macro::$float::Operation::Closing
                    } else {
                        via_macro::$float::Operation::Opening
                    });
                    let mut b = via_build_script::$float::Controller::new(if op == 0 {
                        via_build_script::$float::Operation::Closing
                    } else {
                        via_build_script::$float::Operation::Opening
                    });
                    let mut c = checked_in::$float::Controller::new(if op == 0 {
                        checked_in::$float::Operation::Closing
                    } else {
                        checked_in::$float::Operation::Opening
                    });
                    a.start(start);
                    b.start(start);
                    c.start(start);
                    let period = checked_in::$float::SAMPLE_PERIOD;
                    // 8 ms: pre-movement, motion, hold.
                    for k in 0..800 {
                        let t = start + k as $float * period;
                        let [z, v, phi] = states[(k * 7) % states.len()];
                        let (ua, ub, uc) = (
                            a.step(t, z, v, phi),
                            b.step(t, z, v, phi),
                            c.step(t, z, v, phi),
                        );
                        assert!(
                            same(ua, uc) && same(ub, uc),
                            "step at t = {t}: {ua:e} {ub:e} {uc:e}"
                        );
                        assert!(uc.is_finite());
                        let (ra, rb, rc) = (a.reference(t), b.reference(t), c.reference(t));
                        for i in 0..4 {
                            assert!(
                                same(ra[i], rc[i]) && same(rb[i], rc[i]),
                                "reference at t = {t}"
                            );
                        }
                    }
                }
            }

            #[test]
            fn $constants() {
                assert_eq!(
                    via_macro::$float::REFERENCE_CLOSING,
                    checked_in::$float::REFERENCE_CLOSING
                );
                assert_eq!(
                    via_build_script::$float::REFERENCE_CLOSING,
                    checked_in::$float::REFERENCE_CLOSING
                );
                assert_eq!(
                    via_macro::$float::REFERENCE_OPENING,
                    checked_in::$float::REFERENCE_OPENING
                );
                assert_eq!(
                    via_build_script::$float::REFERENCE_OPENING,
                    checked_in::$float::REFERENCE_OPENING
                );
                for (a, b, c) in [
                    (
                        via_macro::$float::GAIN_K1,
                        via_build_script::$float::GAIN_K1,
                        checked_in::$float::GAIN_K1,
                    ),
                    (
                        via_macro::$float::GAIN_K2,
                        via_build_script::$float::GAIN_K2,
                        checked_in::$float::GAIN_K2,
                    ),
                    (
                        via_macro::$float::GAIN_K3,
                        via_build_script::$float::GAIN_K3,
                        checked_in::$float::GAIN_K3,
                    ),
                    (
                        via_macro::$float::M,
                        via_build_script::$float::M,
                        checked_in::$float::M,
                    ),
                    (
                        via_macro::$float::SAMPLE_PERIOD,
                        via_build_script::$float::SAMPLE_PERIOD,
                        checked_in::$float::SAMPLE_PERIOD,
                    ),
                ] {
                    assert!(same(a, c) && same(b, c));
                }
            }
        }
    };
}

agreement!(
    in_f64,
    f64,
    law_agrees_f64,
    steps_agree_f64,
    constants_agree_f64
);
agreement!(
    in_f32,
    f32,
    law_agrees_f32,
    steps_agree_f32,
    constants_agree_f32
);

/// `Valve::tick` is the checked-in f32 controller stepped at t = k·T_s from
/// the command, and 0 V while idle or released.
#[test]
fn valve_ticks_like_the_checked_in_controller() {
    let mut valve = Valve::new();
    assert_eq!(valve.operation(), None);
    assert_eq!(valve.tick(1e-3, 0.0, 0.0).to_bits(), 0.0f32.to_bits());

    let states = in_f32::states();
    for op in [
        firmware_example::Operation::Closing,
        firmware_example::Operation::Opening,
    ] {
        valve.command(op);
        assert_eq!(valve.operation(), Some(op));
        let mut reference = checked_in::f32::Controller::new(match op {
            firmware_example::Operation::Closing => checked_in::f32::Operation::Closing,
            firmware_example::Operation::Opening => checked_in::f32::Operation::Opening,
        });
        for k in 0..800u32 {
            let [z, v, phi] = states[(k as usize * 13) % states.len()];
            let t = k as f32 * firmware_example::SAMPLE_PERIOD;
            let u = valve.tick(z, v, phi);
            assert!(in_f32::same(u, reference.step(t, z, v, phi)), "k = {k}");
            assert!((firmware_example::U_MIN..=firmware_example::U_MAX).contains(&u));
        }
    }
    valve.release();
    assert_eq!(valve.operation(), None);
    assert_eq!(valve.tick(5e-4, 0.0, 1e-5), 0.0);
}

#[test]
fn pwm_compare_maps_volts_to_a_clamped_signed_duty() {
    assert_eq!(pwm_compare(12.0, 24.0, 1000), 500);
    assert_eq!(pwm_compare(-24.0, 24.0, 1000), -1000);
    assert_eq!(pwm_compare(30.0, 24.0, 1000), 1000); // bus sag: clamped
    assert_eq!(pwm_compare(0.0, 24.0, 1000), 0);
    assert_eq!(pwm_compare(f32::NAN, 24.0, 1000), 0);
    assert_eq!(pwm_compare(12.0, 0.0, 1000), 0);
    assert_eq!(pwm_compare(12.0, f32::NAN, 1000), 0);
    assert_eq!(pwm_compare(-24.0, 24.0, u16::MAX), -i16::MAX);
}

/// The backstepping positioner: the three ways give the same file and, run
/// through two periods of its square reference on the same states, the same
/// inputs bit for bit and the same switching modes, in f32 and f64.
#[test]
fn the_three_ways_agree_on_the_backstepping_positioner() {
    use firmware_example::{
        backstepping_valve as macro_bs, positioner_via_build_script as script_bs,
    };
    use reldesign_generated::backstepping_valve as checked_bs;
    let built = include_str!(concat!(env!("OUT_DIR"), "/backstepping_valve.rs"));
    let checked = include_str!("../../../generated/src/backstepping_valve.rs");
    assert!(
        built == checked,
        "build.rs output differs from generated/src/backstepping_valve.rs"
    );
    let (mut a, mut b, mut c) = (
        macro_bs::f64::Controller::new(),
        script_bs::f64::Controller::new(),
        checked_bs::f64::Controller::new(),
    );
    let (mut a32, mut b32, mut c32) = (
        macro_bs::f32::Controller::new(),
        script_bs::f32::Controller::new(),
        checked_bs::f32::Controller::new(),
    );
    let mut n = 0;
    for k in 0..4000 {
        let t = k as f64 * 1e-4;
        let z = 1e-3 * (0.5 + 0.45 * (k as f64 * 0.37).sin());
        let v = 0.05 * (k as f64 * 0.11).cos();
        let phi = 9e-6 * (1.0 + 0.2 * (k as f64 * 0.05).sin());
        let (ua, ub, uc) = (
            a.step(t, z, v, phi, 0.0),
            b.step(t, z, v, phi, 0.0),
            c.step(t, z, v, phi, 0.0),
        );
        assert!(
            ua.to_bits() == uc.to_bits() && ub.to_bits() == uc.to_bits(),
            "f64 at t = {t}"
        );
        assert!(format!("{:?}", a.mode()) == format!("{:?}", c.mode()));
        let (t, z, v, phi) = (t as f32, z as f32, v as f32, phi as f32);
        let (ua, ub, uc) = (
            a32.step(t, z, v, phi, 0.0),
            b32.step(t, z, v, phi, 0.0),
            c32.step(t, z, v, phi, 0.0),
        );
        assert!(
            ua.to_bits() == uc.to_bits() && ub.to_bits() == uc.to_bits(),
            "f32 at t = {t}"
        );
        n += 1;
    }
    assert_eq!(n, 4000);
}
