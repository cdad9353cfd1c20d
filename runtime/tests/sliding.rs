//! `reldesign_runtime::sliding` on a toy plan (a two-segment table, λ₁ = 10,
//! λ₂ = 20): every rule of the module docs — [SM 17], [SM 34], [SM 35],
//! [SM 43], the non-negative current of [SM §5], NaN safety — in f64 and f32.

use reldesign_runtime::control::{ConstPlan, Landing, Motion, Plan, Settings};
use reldesign_runtime::sliding::{surface, switching_sign, SlidingMode, Surface, SurfaceSettings};

macro_rules! toy {
    ($module:ident, $f:ident) => {
        mod $module {
            use super::*;

            /// Opening: z from 0 to 1 m on [t₀, t_f] = [1, 3] s; closing its mirror.
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

            macro_rules! toy_plan {
                ($name:ident, $nonnegative:expr) => {
                    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
                    pub struct $name;

                    impl ConstPlan for $name {
                        const PLAN: Self = $name;
                    }

                    impl Plan<$f> for $name {
                        type Operation = Operation;
                        fn settings(&self) -> Settings<$f> {
                            Settings {
                            u_min: -24.0,
                            u_max: 20.0,
                            takeoff: 1.0,
                            landing: 3.0,
                            phi_guard: 1e-3,
                            landed_band: 1e-6,
                            press: 0.0,
                            creep: 0.0,
                            creep_max: 0.0,
                            arrival_margin: 1.0,
                            arrival_band: 1e-6,
                            }
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

                    impl Surface<$f> for $name {
                        fn surface(&self) -> SurfaceSettings<$f> {
                            SurfaceSettings {
                                lambda1: 10.0,
                                lambda2: 20.0,
                                nonnegative_current: $nonnegative,
                            }
                        }
                    }
                };
            }
            toy_plan!(Toy, false);
            toy_plan!(Unipolar, true);

            type Ctl = SlidingMode<Toy, $f>;

            #[test]
            fn the_surface_is_the_weighted_error() {
                let s = surface(&Toy.surface(), [0.5, 0.25, 2.0], [0.25, 0.5, 1.0]);
                // ã + 30·ṽ + 200·z̃ = 1 − 7.5 + 50
                assert!((s - 43.5).abs() < 1e-4, "{s}");
                assert_eq!(switching_sign(-1e-30 as $f, false), Some(-1.0));
                assert_eq!(switching_sign(1e-30 as $f, true), Some(1.0));
                assert_eq!(switching_sign(0.0 as $f, true), Some(-1.0));
                assert_eq!(switching_sign(0.0 as $f, false), Some(1.0));
                assert_eq!(switching_sign($f::NAN, false), None);
            }

            #[test]
            fn the_law_switches_on_the_sign_of_s_and_of_phi() {
                let mut c = Ctl::new(Operation::Opening);
                let r = c.clone().reference(1.5);
                // above the reference: s > 0 → u = u_max·sgn φ [SM 34]
                let (z, v, a) = (r[0] + 0.01, r[1], r[2]);
                assert_eq!(c.step(1.5, z, v, a, 1e-5), 20.0);
                assert_eq!(c.step(1.5, z, v, a, -1e-5), -20.0);
                // below it: s < 0 → the opposite sign
                assert_eq!(c.step(1.5, r[0] - 0.01, v, a, 1e-5), -20.0);
                // φ = 0 counts as positive
                assert_eq!(c.step(1.5, z, v, a, 0.0), 20.0);
            }

            #[test]
            fn at_rest_on_the_reference_s_is_zero_and_sgn_star_picks_by_mode() {
                // opening starts at z_min (q = 1) on its reference: s = 0 → −1 [SM 35]
                let mut c = Ctl::new(Operation::Opening);
                assert_eq!(c.step(0.5, 0.0, 0.0, 0.0, 1e-5), -20.0);
                // closing starts at z_max (q = 3): s = 0 → +1
                let mut c = Ctl::new(Operation::Closing);
                assert_eq!(c.step(0.5, 1.0, 0.0, 0.0, 1e-5), 20.0);
            }

            #[test]
            fn the_expert_rules_hold_the_end_stop_even_before_t_f() {
                // closing at z_f = 0 mid-motion: held closed, u = u_max·sgn φ [SM 43]
                let mut c = Ctl::new(Operation::Closing);
                assert_eq!(c.step(2.0, 0.0, 0.0, 0.0, 1e-5), 20.0);
                assert_eq!(c.step(2.0, 5e-7, 0.3, 0.0, -1e-5), -20.0);
                // opening at z_f = 1: u = 0
                let mut c = Ctl::new(Operation::Opening);
                assert_eq!(c.step(2.0, 1.0, 0.0, 0.0, 1e-5), 0.0);
                assert_eq!(c.step(9.0, 1.0, 0.0, 0.0, 1e-5), 0.0);
            }

            #[test]
            fn once_held_after_t_f_the_armature_stays_held_for_the_operation() {
                // t_f = 3: a position read that leaves the band after the rule
                // has held (an estimate flickering at its clamp, a bounce)
                // does not hand the armature back to the law
                let mut c = Ctl::new(Operation::Closing);
                assert_eq!(c.step(3.2, 0.0, 0.0, 0.0, 1e-5), 20.0);
                assert_eq!(c.step(3.3, 0.01, 0.3, 0.0, 1e-5), 20.0);
                assert_eq!(c.step(3.4, 0.5, 0.3, 0.0, -1e-5), -20.0, "u_max·sgn φ");
                let mut o = Ctl::new(Operation::Opening);
                assert_eq!(o.step(3.3, 1.0, 0.0, 0.0, 1e-5), 0.0);
                assert_eq!(o.step(3.4, 0.9, -0.3, 0.0, 1e-5), 0.0);
                // before t_f the rule holds only while the armature is there
                let mut c = Ctl::new(Operation::Closing);
                assert_eq!(c.step(2.0, 0.0, 0.0, 0.0, 1e-5), 20.0);
                let r = c.clone().reference(2.1);
                assert_eq!(c.step(2.1, r[0] - 0.01, r[1], r[2], 1e-5), -20.0);
                // a new operation is not held
                o.start(10.0);
                let r = o.clone().reference(13.5);
                assert_ne!(o.step(13.5, r[0] - 0.1, r[1], r[2], 1e-5), 0.0);
            }

            #[test]
            fn late_is_decided_at_the_push_s_first_sample() {
                // t_f + margin = 4: short of the stop then → late, whatever follows
                let mut c = Ctl::new(Operation::Closing);
                c.step(4.1, 0.5, 0.0, 0.0, 1e-5);
                c.step(4.2, 0.0, 0.0, 0.0, 1e-5);
                assert!(c.finished_late());
                // at its stop then → not late, though a bounce reads it away later
                let mut c = Ctl::new(Operation::Closing);
                c.step(4.1, 0.0, 0.0, 0.0, 1e-5);
                c.step(4.2, 0.5, 0.0, 0.0, 1e-5);
                assert!(!c.finished_late());
                // a NaN position has not arrived; a new operation starts on time
                let mut c = Ctl::new(Operation::Opening);
                c.step(4.1, $f::NAN, 0.0, 0.0, 1e-5);
                assert!(c.finished_late());
                c.start(10.0);
                assert!(!c.finished_late());
            }

            #[test]
            fn a_non_negative_current_is_never_driven_below_zero() {
                let mut c = SlidingMode::<Unipolar, $f>::new(Operation::Opening);
                let r = c.clone().reference(1.5);
                let below = r[0] - 0.01; // s < 0: the law asks for −u_max
                assert_eq!(c.step(1.5, below, r[1], r[2], 0.2), -20.0, "i > 0: allowed");
                assert_eq!(c.step(1.5, below, r[1], r[2], 0.0), 0.0, "i = 0: not below");
                assert_eq!(c.step(1.5, below, r[1], r[2], -0.1), 0.0);
                assert_eq!(c.step(1.5, r[0] + 0.01, r[1], r[2], -0.1), 20.0);
            }

            #[test]
            fn any_input_gives_a_finite_saturated_output() {
                let odd = [0.0, -0.0, 1.0, -1.0, 1e30, -1e30, $f::INFINITY, $f::NEG_INFINITY, $f::NAN];
                for op in [Operation::Closing, Operation::Opening] {
                    let mut c = Ctl::new(op);
                    for &x in &odd {
                        for t in [0.5, 1.5, 2.5, 5.0, $f::NAN] {
                            let u = c.step(t, 0.5, x, 0.0, 1e-5);
                            assert!(u.is_finite() && (-24.0..=20.0).contains(&u), "{u}");
                            let u = c.step(t, 0.5, 0.0, x, x);
                            assert!(u.is_finite() && (-24.0..=20.0).contains(&u), "{u}");
                        }
                    }
                    assert_eq!(c.step(1.5, 0.5, 0.0, $f::NAN, 1e-5), 0.0, "NaN s → 0");
                    assert_eq!(c.step(1.5, 0.5, 0.0, 0.0, $f::NAN), 0.0, "NaN φ → 0");
                }
            }
        }
    };
}

toy!(f64_toy, f64);
toy!(f32_toy, f32);
