//! A reference that stops short of the stop and approaches it slowly
//! (`[trajectory] standoff`, `approach_speed`).
//!
//! A sensorless loop tracks its *estimate*, and a real stop is not where the
//! description puts it: the armature meets the stop up to tens of µm ahead of
//! the reference, where a reference landing at rest still moves at
//! v ≈ √(2·a·Δ) (60–110 mm/s on the self-calibrating valve at 50 µs). This
//! reference makes the move (energy-optimal or polynomial) to z_s = z_f ∓ δ, at
//! rest by t_s, then approaches the stop at v_c: an acceleration ramp
//! a(τ) = 6·v_c/τ_r²·τ·(1 − τ/τ_r) over τ_r = δ/(2·v_c) (it covers δ/4), then v_c
//! until it reaches z_f at t_f. Any stop, or any lead of the armature on its
//! reference, within δ is met at no more than v_c. After t_f the runtime's
//! creep goes on at the same speed. The approach takes t_f − t_s = 5·δ/(4·v_c).
//! It is the deterministic limit of the probability-based design
//! (`optimal/robust.rs`): the speed at every stop within δ is bounded, not
//! only its expectation weighed.

use crate::description::Approach;
use crate::design::trajectory::reference::{Flat, Reference};

/// The move (a reference ending at rest at z_s at t_s), then the approach.
pub struct Approached<R> {
    pub moving: R,
    pub approach: Approach,
    /// z_f: the stop.
    pub stop: f64,
    /// t_f: when the approach reaches it.
    pub landing: f64,
}

impl<R: Reference> Approached<R> {
    /// The move's end time t_s and the ramp's end, for the table's knots.
    pub fn breaks(&self) -> [f64; 2] {
        self.approach.knots(self.landing)
    }

    fn direction(&self) -> f64 {
        let (t0, _) = self.moving.motion();
        (self.stop - self.moving.at(t0).z).signum()
    }
}

impl<R: Reference> Reference for Approached<R> {
    /// The move before t_s; the ramp and the constant speed after it, held at
    /// the stop (still moving at v_c) from t_f on.
    fn at(&self, t: f64) -> Flat {
        let [start, _] = self.breaks();
        if t <= start {
            return self.moving.at(t);
        }
        let s = self.direction();
        let (v_c, ramp) = (self.approach.speed, self.approach.ramp());
        let tau = t.min(self.landing) - start;
        let z_s = self.stop - s * self.approach.standoff;
        if tau < ramp {
            let r = tau / ramp;
            Flat {
                z: z_s + s * v_c * tau * r * r * (1.0 - 0.5 * r),
                v: s * v_c * r * r * (3.0 - 2.0 * r),
                a: s * 6.0 * v_c / ramp * r * (1.0 - r),
                jerk: s * 6.0 * v_c / (ramp * ramp) * (1.0 - 2.0 * r),
            }
        } else {
            Flat {
                z: z_s + s * v_c * (tau - 0.5 * ramp),
                v: s * v_c,
                a: 0.0,
                jerk: 0.0,
            }
        }
    }

    fn motion(&self) -> (f64, f64) {
        (self.moving.motion().0, self.landing)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::trajectory::reference::Polynomial;

    fn opening() -> Approached<Polynomial> {
        let approach = Approach {
            standoff: 20e-6,
            speed: 10e-3,
        };
        let (zs, ts) = approach.move_end(0.0, 1e-3, 8e-3);
        Approached {
            moving: Polynomial {
                z0: 0.0,
                zf: zs,
                t0: 1e-3,
                tf: ts,
            },
            approach,
            stop: 1e-3,
            landing: 8e-3,
        }
    }

    #[test]
    fn the_approach_reaches_the_stop_at_its_speed_at_t_f() {
        let r = opening();
        let end = r.at(8e-3);
        assert!((end.z - 1e-3).abs() < 1e-15, "{end:?}");
        assert!((end.v - 10e-3).abs() < 1e-15 && end.a == 0.0);
        assert!((r.breaks()[0] - 5.5e-3).abs() < 1e-15);
        assert_eq!(r.motion(), (1e-3, 8e-3));
    }

    #[test]
    fn position_speed_and_acceleration_are_continuous_and_differentiate_consistently() {
        let r = opening();
        let h = 1e-9;
        for k in 0..=400 {
            let t = 5e-3 + 2.999e-3 * f64::from(k) / 400.0;
            let (m, f, p) = (r.at(t - h), r.at(t), r.at(t + h));
            assert!(((p.z - m.z) / (2.0 * h) - f.v).abs() < 1e-7, "v at {t}");
            assert!(((p.v - m.v) / (2.0 * h) - f.a).abs() < 1e-4, "a at {t}");
        }
        for t in r.breaks() {
            let (m, p) = (r.at(t - 1e-12), r.at(t + 1e-12));
            assert!(
                (m.z - p.z).abs() < 1e-12 && (m.v - p.v).abs() < 1e-8 && (m.a - p.a).abs() < 1e-3
            );
        }
    }

    #[test]
    fn a_closing_approaches_downwards() {
        let approach = Approach {
            standoff: 10e-6,
            speed: 5e-3,
        };
        let (zs, ts) = approach.move_end(1e-3, 0.0, 6e-3);
        assert_eq!(zs, 10e-6);
        let r = Approached {
            moving: Polynomial {
                z0: 1e-3,
                zf: zs,
                t0: 1e-3,
                tf: ts,
            },
            approach,
            stop: 0.0,
            landing: 6e-3,
        };
        let f = r.at(5.99e-3);
        assert!(f.v == -5e-3 && f.z > 0.0 && f.z < 1e-7, "{f:?}");
    }
}
