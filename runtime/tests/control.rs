//! `reldesign_runtime::control` on a toy design (a two-segment table, a law
//! linear in its inputs): every rule of the module docs, in f64 and f32.

use reldesign_runtime::control::{
    eval_segment, guarded_law, saturate, ConstPlan, Landing, Law, Motion, Plan, Settings,
    SoftLanding,
};
use reldesign_runtime::{Controller, Measurement};

macro_rules! toy {
    ($module:ident, $f:ident) => {
        mod $module {
            use super::*;

            /// Two segments on [t₀, t_f] = [1, 3] s: a = 1 then a = −1, so z goes from
            /// 0 to 1 m and back to rest (opening); closing is its mirror, 1 → 0 m.
            pub const OPENING: [[$f; 7]; 2] = [
                [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
                [2.0, 0.5, 1.0, -1.0, 0.0, 0.0, 0.0],
            ];
            pub const CLOSING: [[$f; 7]; 2] = [
                [1.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0],
                [2.0, 0.5, -1.0, 1.0, 0.0, 0.0, 0.0],
            ];

            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub enum Operation {
                Closing,
                Opening,
            }

            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub struct Toy;

            impl ConstPlan for Toy {
                const PLAN: Self = Toy;
            }

            pub const SETTINGS: Settings<$f> = Settings {
                    u_min: -24.0,
                    u_max: 20.0,
                    takeoff: 1.0,
                    landing: 3.0,
                    phi_guard: 1e-3,
                    landed_band: 1e-6,
                    press: 0.01,
                    creep: 0.5,
                    creep_max: 0.05,
                    arrival_margin: 1.0,
                    arrival_band: 1e-6,
                };

            impl Plan<$f> for Toy {
                type Operation = Operation;
                fn settings(&self) -> Settings<$f> {
                    SETTINGS
                }
                fn motion(&self, operation: Operation) -> Motion<'_, $f> {
                    match operation {
                        Operation::Closing => Motion {
                            landing: Landing::Closing,
                            z0: 1.0,
                            zf: 0.0,
                            table: &CLOSING,
                        },
                        Operation::Opening => Motion {
                            landing: Landing::Opening,
                            z0: 0.0,
                            zf: 1.0,
                            table: &OPENING,
                        },
                    }
                }
            }

            impl Law<$f> for Toy {
                /// u = 100·(z_r − z) + v_r − v + a_r + j_r + φ
                fn law(&self, x: [$f; 4], r: [$f; 4]) -> $f {
                    100.0 * (r[0] - x[0]) + r[1] - x[1] + r[2] + r[3] + x[2] + x[3]
                }
            }

            pub type Ctl = SoftLanding<Toy, $f>;

            pub fn close(a: $f, b: $f) -> bool {
                (a - b).abs() <= 1e-6
            }

            #[test]
            fn eval_segment_integrates_the_cubic_acceleration() {
                // a(τ) = 1 + 2τ + 3τ² + 4τ³ from z = 0.5, v = −1
                let row: [$f; 7] = [0.0, 0.5, -1.0, 1.0, 2.0, 3.0, 4.0];
                let tau: $f = 0.5;
                let a = 1.0 + 2.0 * tau + 3.0 * tau * tau + 4.0 * tau * tau * tau;
                let j = 2.0 + 6.0 * tau + 12.0 * tau * tau;
                let v = -1.0 + tau + tau * tau + tau * tau * tau + tau * tau * tau * tau;
                let z = 0.5 - tau
                    + tau * tau / 2.0
                    + tau * tau * tau / 3.0
                    + tau.powi(4) / 4.0
                    + tau.powi(5) / 5.0;
                let got = eval_segment(&row, tau);
                for (g, w) in got.iter().zip([z, v, a, j]) {
                    assert!(close(*g, w), "{got:?} vs {:?}", [z, v, a, j]);
                }
            }

            #[test]
            fn reference_rests_tracks_the_table_then_presses_and_creeps() {
                let mut c = Ctl::new(Operation::Opening);
                c.start(10.0);
                // pre-movement stage: z₀ at rest, also for a NaN time
                assert_eq!(c.reference(10.5), [0.0, 0.0, 0.0, 0.0]);
                assert_eq!(c.reference($f::NAN), [0.0, 0.0, 0.0, 0.0]);
                // the table: first segment, then the second
                let r = c.reference(11.5);
                assert!(close(r[0], 0.125) && close(r[1], 0.5) && close(r[2], 1.0), "{r:?}");
                let r = c.reference(12.5);
                assert!(close(r[0], 0.875) && close(r[1], 0.5) && close(r[2], -1.0), "{r:?}");
                // after t_f: press + creep beyond z_f = 1 (stroke +1)
                let r = c.reference(13.02);
                assert!(close(r[0], 1.0 + 0.01 + 0.5 * 0.02) && close(r[1], 0.5), "{r:?}");
                assert_eq!([r[2], r[3]], [0.0, 0.0]);
                // … up to creep_max, then at rest there
                let r = c.reference(14.0);
                assert!(close(r[0], 1.0 + 0.01 + 0.05) && r[1] == 0.0, "{r:?}");
                // closing mirrors it (stroke −1)
                let mut c = Ctl::new(Operation::Closing);
                let r = c.reference(3.02);
                assert!(close(r[0], -0.01 - 0.01) && close(r[1], -0.5), "{r:?}");
            }

            #[test]
            fn the_cursor_only_moves_forward_until_restarted() {
                let mut c = Ctl::new(Operation::Opening);
                let late = c.reference(2.5);
                // an earlier time within [t₀, t_f] stays on the second segment
                let r = c.reference(1.5);
                let second = eval_segment(&OPENING[1], 1.5 - 2.0);
                assert_eq!(r, second);
                assert_ne!(r, eval_segment(&OPENING[0], 0.5));
                c.start(0.0);
                assert_eq!(c.reference(1.5), eval_segment(&OPENING[0], 0.5));
                assert_eq!(c.reference(2.5), late);
                assert_eq!(c.operation(), Operation::Opening);
            }

            #[test]
            fn step_is_the_guarded_saturated_law_at_the_reference() {
                let mut c = Ctl::new(Operation::Opening);
                let (z, v, phi) = (0.1, 0.2, 0.5);
                let r = c.clone().reference(1.5);
                let want = Toy.law([z, v, phi, 0.0], r);
                assert!(want > -24.0 && want < 20.0, "{want}");
                assert_eq!(c.step(1.5, z, v, phi), want);
                // the field H_c reaches the law through step_with_field
                let with_field = Toy.law([z, v, phi, 0.25], r);
                assert_ne!(with_field, want);
                assert_eq!(c.clone().step_with_field(1.5, z, v, phi, 0.25), with_field);
                // the guard at φ ≤ phi_guard: u_max without evaluating the law
                assert_eq!(c.step(1.5, z, v, 1e-3), 20.0);
                assert_eq!(c.step(1.5, z, v, -0.5), 20.0);
                assert_eq!(guarded_law(&Toy, [z, v, 0.0, 0.0], r), 20.0);
                // saturation of a large law value, a NaN law value → 0
                assert_eq!(c.step(1.5, -10.0, v, phi), 20.0);
                assert_eq!(c.step(1.5, 10.0, v, phi), -24.0);
                assert_eq!(c.step(1.5, $f::NAN, v, phi), 0.0);
                // the runtime's Controller trait is the same step
                let y = Measurement { z, v, phi };
                assert_eq!(Controller::step(&mut c, 1.5, &y), want);
            }

            #[test]
            fn the_hold_rules_apply_at_the_end_stop_after_landing() {
                let mut c = Ctl::new(Operation::Closing);
                // closing at z_f: u_max·sgn φ, sgn 0 = +1, NaN φ → 0
                assert_eq!(c.step(3.5, 0.0, 0.0, 0.3), 20.0);
                assert_eq!(c.step(3.5, 0.0, 0.0, -0.3), -20.0);
                assert_eq!(c.step(3.5, 1e-7, 0.0, 0.0), 20.0);
                assert_eq!(c.step(3.5, -1.0, 0.0, $f::NAN), 0.0);
                // not yet at the stop: the law (unsaturated here)
                let mut away = Ctl::new(Operation::Closing);
                let u = away.step(3.5, 0.01, 0.0, 0.3);
                assert!(u > -24.0 && u < 20.0, "{u}");
                // before t_f the rule does not apply
                assert_ne!(away.step(2.5, 0.0, 0.0, 0.3), 20.0);
                for z in [1.0, 2.0] {
                    let mut o = Ctl::new(Operation::Opening);
                    assert_eq!(o.step(3.5, z, 0.0, 0.3), 0.0);
                }
                assert_ne!(Ctl::new(Operation::Opening).step(3.5, 0.9, 0.0, 0.3), 0.0);
            }

            #[test]
            fn once_held_at_its_stop_the_armature_stays_held_for_the_operation() {
                // a position read that leaves the band after the rule has
                // held (an estimate flickering at its clamp, a bounce) does
                // not hand the armature back to the law
                let mut c = Ctl::new(Operation::Closing);
                assert_ne!(c.step(3.2, 0.01, 0.0, 0.3), 20.0);
                assert_eq!(c.step(3.3, 0.0, 0.0, 0.3), 20.0);
                assert_eq!(c.step(3.4, 0.01, 0.0, 0.3), 20.0);
                assert_eq!(c.step(3.5, 0.5, 0.0, -0.3), -20.0);
                let mut o = Ctl::new(Operation::Opening);
                assert_eq!(o.step(3.3, 1.0, 0.0, 0.3), 0.0);
                assert_eq!(o.step(3.4, 0.9, 0.0, 0.3), 0.0);
                // a new operation is not held
                c.start(10.0);
                assert_ne!(c.step(13.5, 0.01, 0.0, 0.3), 20.0);
                o.start(10.0);
                assert_ne!(o.step(13.5, 0.9, 0.0, 0.3), 0.0);
            }

            #[test]
            fn an_armature_short_of_its_stop_is_driven_there_after_the_margin() {
                // t_f = 3, arrival margin 1: until 4 the law, then the push
                let mut c = Ctl::new(Operation::Closing);
                let before = c.step(3.9, 0.5, 0.0, 1.0);
                assert!(!c.finished_late() && before != 20.0, "{before}");
                assert_eq!(c.step(4.1, 0.5, 0.0, 1.0), 20.0);
                assert_eq!(c.step(4.1, 0.5, 0.0, -1.0), -20.0);
                assert!(c.finished_late());
                c.start(10.0);
                assert!(!c.finished_late(), "a new operation starts on time");
                // opening: the flux quenched at u_min, then 0 V
                let mut c = Ctl::new(Operation::Opening);
                assert_eq!(c.step(4.1, 0.5, 0.0, 1.0), -24.0);
                assert_eq!(c.step(4.1, 0.5, 0.0, 1e-4), 0.0);
                assert!(c.finished_late());
                // at the stop: the flux drained all the same, but not late
                let mut c = Ctl::new(Operation::Opening);
                assert_eq!(c.step(4.1, 1.0, 0.0, 1.0), -24.0);
                assert_eq!(c.step(4.1, 1.0, 0.0, 1e-4), 0.0);
                assert!(!c.finished_late());
                let mut c = Ctl::new(Operation::Closing);
                assert_eq!(c.step(4.1, 0.0, 0.0, 1.0), 20.0);
                assert!(!c.finished_late());
            }

            /// A plan whose arrival band is wider than its contact band (a
            /// sensorless design: its estimate creeps onto the clamp).
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub struct Estimated;

            impl Plan<$f> for Estimated {
                type Operation = Operation;
                fn settings(&self) -> Settings<$f> {
                    Settings { arrival_band: 0.05, ..SETTINGS }
                }
                fn motion(&self, operation: Operation) -> Motion<'_, $f> {
                    Toy.motion(operation)
                }
            }

            impl Law<$f> for Estimated {
                fn law(&self, x: [$f; 4], r: [$f; 4]) -> $f {
                    Toy.law(x, r)
                }
            }

            #[test]
            fn a_push_within_the_arrival_band_is_not_late() {
                // t_f + margin = 4: the estimate 0.01 short of its stop (not
                // in the contact band) is pushed, and had arrived
                for (op, z) in [(Operation::Opening, 0.99), (Operation::Closing, 0.01)] {
                    let mut c = SoftLanding::with(Estimated, op);
                    c.step(4.1, z, 0.0, 1.0);
                    assert!(!c.finished_late(), "{op:?} at {z}");
                    // 0.1 short: late, and still late once read at the stop
                    let mut c = SoftLanding::with(Estimated, op);
                    let far = if op == Operation::Opening { 0.9 } else { 0.1 };
                    c.step(4.1, far, 0.0, 1.0);
                    c.step(4.2, Toy.motion(op).zf, 0.0, 1.0);
                    assert!(c.finished_late(), "{op:?} at {far}");
                    // within the band at the push: a later read far away does not make it late
                    let mut c = SoftLanding::with(Estimated, op);
                    c.step(4.1, z, 0.0, 1.0);
                    c.step(4.2, far, 0.0, 1.0);
                    assert!(!c.finished_late(), "{op:?} at {z}, then {far}");
                }
                // a band narrower than the contact band counts as the contact band
                let narrow = Settings { arrival_band: 0.0, ..SETTINGS };
                let closing = Toy.motion(Operation::Closing);
                assert!(reldesign_runtime::control::arrived(&closing, &narrow, 1e-7));
            }

            #[test]
            fn any_input_gives_a_finite_saturated_output() {
                let odd = [0.0, -0.0, 1e-300, $f::NAN, $f::INFINITY, $f::NEG_INFINITY, 0.5];
                for op in [Operation::Closing, Operation::Opening] {
                    let mut c = Ctl::new(op);
                    for &t in &[0.0, 1.5, 2.5, 3.5, 1e9, $f::NAN, $f::NEG_INFINITY] {
                        for &z in &odd {
                            for &phi in &odd {
                                let u = c.step(t, z, 0.1, phi);
                                assert!((-24.0..=20.0).contains(&u), "{op:?} {t} {z} {phi}: {u}");
                            }
                        }
                    }
                }
                let s = SETTINGS;
                assert_eq!(saturate($f::NAN, &s), 0.0);
                assert_eq!(saturate($f::INFINITY, &s), 20.0);
                assert_eq!(saturate($f::NEG_INFINITY, &s), -24.0);
                let positive = Settings { u_min: 1.0, ..s };
                assert_eq!(saturate($f::NAN, &positive), 1.0);
            }

            /// `new` is const: a controller can live in a static.
            pub static IDLE: Ctl = Ctl::new(Operation::Closing);

            #[test]
            fn a_const_controller_starts_at_zero() {
                let mut c = IDLE.clone();
                assert_eq!(c.operation(), Operation::Closing);
                assert_eq!(c.reference(0.5), [1.0, 0.0, 0.0, 0.0]);
            }
        }
    };
}

toy!(in_f64, f64);
toy!(in_f32, f32);
