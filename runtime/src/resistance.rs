//! The law's voltage for the coil resistance the observer estimates
//! (`controller.compensate_resistance`).
//!
//! Under voltage drive the model's electrical equation is
//! φ̇ = (N·u − R·MMF)/(N² + R·k_e) with the coil current
//! i = (N·MMF + k_e·u)/(N² + R·k_e); solved for the input that gives a
//! flux rate φ̇ it reads u = N·φ̇ + R·i, i = (MMF + k_e·φ̇)/N. The laws that
//! compute their voltage from the model (feedback linearization [PT 50],
//! the model-based sliding mode [JA 89]) command a flux rate through u
//! computed with the design's R; for the same flux rate a coil of
//! resistance R̂ needs u + (R̂ − R)·i. The current used is the one measured
//! at the sample (the observer's input): it differs from the current of the
//! commanded flux rate by k_e·Δφ̇/N where the law changes φ̇ from one sample
//! to the next, an error (R̂ − R)·k_e·Δφ̇/N: the product of the resistance's
//! error and of the flux rate's change.

use crate::control::saturate_to;
use crate::linalg::Scalar;

/// `u` (for the design's `r_design`) corrected to the coil resistance
/// `r_estimate` at the measured `current`: u + (R̂ − R)·i, saturated to
/// [`u_min`, `u_max`]. Where the correction is not finite (no estimate, a
/// NaN current) it is left out: `u` saturated.
#[inline]
pub fn compensate_resistance<T: Scalar>(
    u: T,
    r_estimate: T,
    r_design: T,
    current: T,
    (u_min, u_max): (T, T),
) -> T {
    let correction = (r_estimate - r_design) * current;
    let u = if correction.finite() {
        u + correction
    } else {
        u
    };
    saturate_to(u, u_min, u_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The model's voltage for a flux rate at R and at R̂: the correction
    /// turns the first into the second exactly.
    #[test]
    fn the_correction_is_the_models_voltage_at_the_estimated_resistance() {
        let (n, k_e) = (1200.0_f64, 1500.0);
        for (mmf, phi_dot, r, r_hat) in [
            (40.0, 0.012, 75.0, 82.5),
            (-5.0, -0.003, 75.0, 67.5),
            (300.0, 0.0, 50.0, 51.0),
        ] {
            let i = (mmf + k_e * phi_dot) / n;
            let voltage = |r: f64| n * phi_dot + r * i;
            let u = compensate_resistance(voltage(r), r_hat, r, i, (-1e3, 1e3));
            assert!((u - voltage(r_hat)).abs() <= 1e-12 * voltage(r_hat).abs().max(1.0));
            // and back: the flux rate of the model at R̂ with that voltage
            let k = n * n + r_hat * k_e;
            let back = (n * u - r_hat * mmf) / k;
            assert!((back - phi_dot).abs() <= 1e-15, "{back} {phi_dot}");
        }
    }

    #[test]
    fn saturated_and_nan_safe() {
        let limits = (-24.0_f32, 24.0);
        assert_eq!(compensate_resistance(20.0, 90.0, 75.0, 1.0, limits), 24.0);
        assert_eq!(compensate_resistance(5.0, f32::NAN, 75.0, 0.2, limits), 5.0);
        assert_eq!(
            compensate_resistance(5.0, 80.0, 75.0, f32::INFINITY, limits),
            5.0
        );
        assert_eq!(
            compensate_resistance(f32::NAN, 80.0, 75.0, 0.2, limits),
            0.0
        );
        assert_eq!(compensate_resistance(-30.0, 75.0, 75.0, 0.0, limits), -24.0);
    }
}
