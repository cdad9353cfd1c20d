//! What `[controller] settling_time` or `poles` mean: the gains K of the
//! tracking law [PT 48], and the steady position error K leaves where the
//! model's acceleration is off (a spring that differs from the description).

use super::Gains;

/// 5 % settling-time criterion of a triple real pole.
const SETTLING_FRACTION: f64 = 0.05;

/// λ·t_s of a triple real pole −λ with 5 % settling time t_s: the root of
/// e^{−x}(1 + x + x²/2) = 0.05 (≈ 6.2958).
pub fn triple_pole_settling_product() -> f64 {
    // The residual decreases strictly for x > 0: bisection on [0, 50].
    let residual = |x: f64| (-x).exp() * (1.0 + x + 0.5 * x * x) - SETTLING_FRACTION;
    let (mut lo, mut hi) = (0.0_f64, 50.0_f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if residual(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
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

    /// The steady position error [m] per acceleration error [m/s²] of the
    /// law's model: at rest under u = α + β·(K·(ξ_r − T(x)) + z_r⁽³⁾) [PT 50]
    /// with ξ̃ = ξ_r − T(x), the jerk k1·z̃ + k2·ṽ + k3·ã = 0 with ṽ = 0, so
    /// z̃ = −(k3/k1)·ã (3/λ² for a settling time).
    pub fn position_per_acceleration(&self) -> f64 {
        let [k1, _, k3] = self.k();
        k3 / k1
    }
}
