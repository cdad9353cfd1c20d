//! The |φ̇|-weighted normalised RMS error of jiles-atherton-actuator-model
//! [JA 81], its weights estimated from the data, and the flux estimated from the
//! electrical signals when the recording has no flux column.
//!
//! **Weights.** |φ̇| comes from the measured flux (`phi`, or `lambda`/N) by a
//! central difference over ±[`SMOOTH_HALF_WIDTH`] samples, otherwise from
//! the coil equation φ̇ = (v − R·i)/N averaged over the same 2·m + 1 samples.
//! The light smoothing keeps sample-to-sample noise (σ_v, σ_i, and the
//! difference of a noisy flux) from dominating the weight where the flux is
//! nearly constant; over a few samples it leaves the flux transients, which
//! last hundreds of samples, unchanged.

use super::measured::Measured;

/// Half-width m of the smoothing window (2·m + 1 samples).
pub const SMOOTH_HALF_WIDTH: usize = 2;

/// [JA 81] wNRMSE = √(Σ w·(sim − exp)² / Σ w·exp²).
///
/// A reference that is zero wherever the weight is non-zero has no scale:
/// the result is then 0 for a perfect match and +∞ otherwise.
///
/// # Panics
/// If the slices differ in length (a programming error, not a data error).
pub fn wnrmse(sim: &[f64], exp: &[f64], weight: &[f64]) -> f64 {
    assert!(
        sim.len() == exp.len() && exp.len() == weight.len(),
        "one simulated value, one measured value and one weight per sample"
    );
    let (mut num, mut den) = (0.0, 0.0);
    for ((s, e), w) in sim.iter().zip(exp).zip(weight) {
        num += w * (s - e).powi(2);
        den += w * e * e;
    }
    match (num, den) {
        (n, d) if d > 0.0 => (n / d).sqrt(),
        (0.0, _) => 0.0,
        _ => f64::INFINITY,
    }
}

/// |φ̇| at every sample, estimated from the data (see the module docs).
pub fn flux_rate_weights(data: &Measured, turns: f64, resistance: f64) -> Vec<f64> {
    signed_flux_rate(data, turns, resistance)
        .into_iter()
        .map(f64::abs)
        .collect()
}

/// φ̇ at every sample, smoothed (see the module docs).
pub fn signed_flux_rate(data: &Measured, turns: f64, resistance: f64) -> Vec<f64> {
    if let Some(flux) = measured_flux(data, turns) {
        return central_difference(&flux, data.dt, SMOOTH_HALF_WIDTH);
    }
    let rate: Vec<f64> = data
        .v
        .iter()
        .zip(&data.i)
        .map(|(v, i)| (v - resistance * i) / turns)
        .collect();
    moving_average(&rate, SMOOTH_HALF_WIDTH)
}

/// The flux φ [Wb]: the measured `phi` column, else `lambda`/N, else the
/// integral of (v − R·i)/N from zero at the first sample (the actuator
/// starts at rest, demagnetised), by the trapezoidal rule.
pub fn flux_from_data(data: &Measured, turns: f64, resistance: f64) -> Vec<f64> {
    if let Some(flux) = measured_flux(data, turns) {
        return flux;
    }
    let mut flux = Vec::with_capacity(data.len());
    let mut acc = 0.0;
    let rate = |k: usize| (data.v[k] - resistance * data.i[k]) / turns;
    for k in 0..data.len() {
        if k > 0 {
            acc += 0.5 * (data.t[k] - data.t[k - 1]) * (rate(k - 1) + rate(k));
        }
        flux.push(acc);
    }
    flux
}

/// Whether the recording measures the flux itself (`phi` or `lambda`).
pub fn has_measured_flux(data: &Measured) -> bool {
    data.phi.is_some() || data.lambda.is_some()
}

fn measured_flux(data: &Measured, turns: f64) -> Option<Vec<f64>> {
    if let Some(phi) = &data.phi {
        return Some(phi.clone());
    }
    data.lambda
        .as_ref()
        .map(|l| l.iter().map(|x| x / turns).collect())
}

/// Central difference over ±m samples (fewer at the ends, one-sided at the
/// first and last sample).
fn central_difference(x: &[f64], dt: f64, m: usize) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            let lo = k.saturating_sub(m);
            let hi = (k + m).min(n.saturating_sub(1));
            if hi > lo {
                (x[hi] - x[lo]) / ((hi - lo) as f64 * dt)
            } else {
                0.0
            }
        })
        .collect()
}

/// Centred moving average over 2·m + 1 samples (fewer at the ends).
fn moving_average(x: &[f64], m: usize) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            let lo = k.saturating_sub(m);
            let hi = (k + m).min(n.saturating_sub(1));
            x[lo..=hi].iter().sum::<f64>() / (hi - lo + 1) as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(phi: Option<Vec<f64>>) -> Measured {
        let n = 200;
        let dt = 1e-4;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        // φ(t) = 1e-5·sin(50 t) driven through N = 100 turns, R = 10 Ω, i = 0.2 A.
        let (n_turns, r, i) = (100.0, 10.0, 0.2);
        let v = t
            .iter()
            .map(|t| r * i + n_turns * 1e-5 * 50.0 * (50.0 * t).cos())
            .collect();
        Measured {
            v,
            i: vec![i; n],
            z: None,
            phi,
            lambda: None,
            t,
            dt,
            file_name: "synthetic".into(),
            edges: None,
        }
    }

    #[test]
    fn wnrmse_matches_its_definition() {
        let e = wnrmse(&[1.1, 2.0, 0.0], &[1.0, 2.0, 1.0], &[1.0, 3.0, 0.0]);
        // √(1·0.01 / (1·1 + 3·4))
        assert!((e - (0.01f64 / 13.0).sqrt()).abs() < 1e-15);
        assert_eq!(wnrmse(&[0.0], &[0.0], &[1.0]), 0.0);
        assert_eq!(wnrmse(&[1.0], &[0.0], &[1.0]), f64::INFINITY);
    }

    #[test]
    fn flux_and_its_rate_agree_with_the_closed_form() {
        let d = data(None);
        let flux = flux_from_data(&d, 100.0, 10.0);
        let rate = signed_flux_rate(&d, 100.0, 10.0);
        for (k, t) in d.t.iter().enumerate() {
            assert!((flux[k] - 1e-5 * (50.0 * t).sin()).abs() < 1e-9, "φ at {t}");
            if (3..197).contains(&k) {
                let exact = 1e-5 * 50.0 * (50.0 * t).cos();
                assert!((rate[k] - exact).abs() < 1e-4 * 5e-4, "φ̇ at {t}");
            }
        }
        // From a measured flux column: the same rate by differences.
        let with_phi = data(Some(flux.clone()));
        let w = flux_rate_weights(&with_phi, 100.0, 10.0);
        assert!((w[100] - rate[100].abs()).abs() < 1e-3 * rate[100].abs());
    }
}
