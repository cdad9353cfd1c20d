//! What `[controller] settling_time` or `poles` mean: the gains K of the
//! tracking law [PT 48], and the steady position error K leaves where the
//! model's acceleration is off (a spring that differs from the description).

use super::Gains;
use crate::bisect::bisect;

/// 5 % settling-time criterion of a triple real pole.
const SETTLING_FRACTION: f64 = 0.05;

/// λ·t_s of a triple real pole −λ with 5 % settling time t_s: the root of
/// e^{−x}(1 + x + x²/2) = 0.05 (≈ 6.2958).
pub fn triple_pole_settling_product() -> f64 {
    // The residual decreases strictly for x > 0: bisection on [0, 50].
    let residual = |x: f64| (-x).exp() * (1.0 + x + 0.5 * x * x) - SETTLING_FRACTION;
    bisect(0.0, 50.0, |x| residual(x) > 0.0)
}

impl Gains {
    /// K = [k1, k2, k3] of [PT 48]: the error dynamics [PT 49] ξ̃' = (A − BK)ξ̃
    /// of the triple integrator have the characteristic polynomial
    /// s³ + k3·s² + k2·s + k1 = Π(s − p_i).
    ///
    /// A settling time t_s places a triple pole at −λ, λ = 6.2958…/t_s (5 %
    /// criterion), so K = [λ³, 3λ², 3λ].
    pub fn k(&self) -> [f64; 3] {
        let [p1, p2, p3] = match *self {
            Gains::SettlingTime(ts) => {
                let lambda = triple_pole_settling_product() / ts;
                [-lambda; 3]
            }
            Gains::Poles(p) => p,
        };
        [
            -(p1 * p2 * p3),
            p1 * p2 + p1 * p3 + p2 * p3,
            -(p1 + p2 + p3),
        ]
    }

    /// The steady position error [m] the law leaves at rest where its
    /// model's acceleration at the true state is off by `acceleration_error`
    /// [m/s²] (a spring Δk_s off at the stop z: Δk_s·z/m), with the damping
    /// rate c/m `damping_rate` [1/s]. Derived here from [PT 48–50]: at rest
    /// (v = 0, φ̇ = 0, the reference at rest) the model's jerk along the
    /// true state is only ∂a/∂v·a = −(c/m)·a, so k1·z̃ + k3·ã = −(c/m)·a with
    /// ã = −a: z̃ = ((k3 − c/m)/k1)·Δa (3/λ² − (c/m)/λ³ for a triple pole).
    pub fn steady_position_error(&self, damping_rate: f64, acceleration_error: f64) -> f64 {
        let [k1, _, k3] = self.k();
        (k3 - damping_rate) / k1 * acceleration_error
    }
}

/// The longest 5 % settling time [s] of a triple pole whose
/// [`Gains::steady_position_error`] is at most `bound` [m], rounded down to
/// four significant digits (so the printed value keeps it), among the poles
/// λ > (c/m)/2 where the error falls as λ grows; `None` where none is.
pub fn settling_time_within(bound: f64, damping_rate: f64, acceleration_error: f64) -> Option<f64> {
    let error = |lambda: f64| (3.0 * lambda - damping_rate) / lambda.powi(3) * acceleration_error;
    let (mut lo, mut hi) = ((damping_rate / 2.0).max(1e-9), 1e12_f64);
    if !(bound > 0.0 && error(hi) <= bound) {
        return None;
    }
    if error(lo) > bound {
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            if error(mid) > bound {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo = hi;
    }
    Some(round_down(triple_pole_settling_product() / lo))
}

/// `x` rounded down to four significant digits.
fn round_down(x: f64) -> f64 {
    let q = 10f64.powi(x.log10().floor() as i32 - 3);
    (x / q).floor() * q
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The named settling time keeps the error within the bound, and one
    /// 0.1 % longer does not (it is rounded down to four digits only); with
    /// no damping it is t_s·√(bound/error) of any settling time.
    #[test]
    fn the_settling_time_within_a_bound_is_the_longest_that_keeps_it() {
        let (bound, da) = (2e-5, 100.0);
        for damping_rate in [0.0, 50.0, 500.0] {
            let ts = settling_time_within(bound, damping_rate, da).expect("one exists");
            let error = |ts: f64| Gains::SettlingTime(ts).steady_position_error(damping_rate, da);
            assert!(error(ts) <= bound, "c/m = {damping_rate}: {}", error(ts));
            assert!(
                error(1.001 * ts) > bound,
                "c/m = {damping_rate}: {ts} not the longest"
            );
        }
        let ts = settling_time_within(bound, 0.0, da).unwrap();
        let e1 = Gains::SettlingTime(1e-3).steady_position_error(0.0, da);
        assert!(
            (ts / (1e-3 * (bound / e1).sqrt()) - 1.0).abs() < 1e-3,
            "{ts}"
        );
        assert_eq!(settling_time_within(0.0, 0.0, da), None);
    }
}
