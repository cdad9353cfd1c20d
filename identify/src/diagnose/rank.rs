//! Ranking candidate explanations: weighted error with a complexity penalty
//! (BIC), and the noise floor below which no extension is worth its
//! parameters.
//!
//! The residual that a fit minimises is weighted by |φ̇| ([JA 81]), so its
//! samples do not count equally: the BIC uses the effective sample count
//! n_eff = (Σw)²/Σw² of the weights (Kish), which equals n for equal weights
//! and is smaller when the weight concentrates in the transients.
//!
//! The floor has two parts: the current's own measurement noise, and the
//! voltage's, which the replay integrates (a saturated coil of small
//! inductance passes it on to the current almost as δv/R). The second is
//! measured, not modelled: the baseline is replayed once more on the
//! measured voltage plus white noise of the voltage's estimated σ, and the
//! two replayed currents compared ([`voltage_floor`]).

/// Effective number of samples of weights `w` (Kish): (Σw)²/Σw².
pub fn effective_samples(w: &[f64]) -> f64 {
    let (s, s2) = w.iter().fold((0.0, 0.0), |(s, s2), &x| (s + x, s2 + x * x));
    if s2 > 0.0 {
        s * s / s2
    } else {
        0.0
    }
}

/// Bayesian information criterion of a weighted least-squares fit with
/// `parameters` free parameters and weighted NRMSE `wnrmse`:
/// n·ln(wNRMSE²) + k·ln n (constant terms dropped: only differences matter).
pub fn bic(wnrmse: f64, parameters: usize, n_eff: f64) -> f64 {
    let n = n_eff.max(1.0);
    n * (wnrmse * wnrmse).max(f64::MIN_POSITIVE).ln() + parameters as f64 * n.ln()
}

/// The standard deviation of white measurement noise on `x`, estimated from
/// the second differences (which cancel any signal smooth over three samples)
/// with the median absolute deviation (robust to the steps of a square wave):
/// σ ≈ 1.4826·MAD(Δ²x)/√6.
pub fn noise_std(x: &[f64]) -> f64 {
    let mut d2: Vec<f64> = x
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .collect();
    if d2.is_empty() {
        return 0.0;
    }
    let mid = d2.len() / 2;
    let (_, median, _) = d2.select_nth_unstable_by(mid, f64::total_cmp);
    1.4826 * *median / 6f64.sqrt()
}

/// The noise floor of both columns: √(current² + voltage²).
pub fn combined_floor(current: f64, voltage: f64) -> f64 {
    current.hypot(voltage)
}

/// The wNRMSE between a replay on the measured voltage and one on the
/// measured voltage plus fresh noise of the same σ: what the voltage's own
/// noise costs any model replayed on it.
pub fn voltage_floor(replayed: &[f64], renoised: &[f64], i: &[f64], w: &[f64]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (((a, b), i), w) in replayed.iter().zip(renoised).zip(i).zip(w) {
        num += w * (a - b).powi(2);
        den += w * i * i;
    }
    if den > 0.0 && num.is_finite() {
        (num / den).sqrt()
    } else {
        0.0
    }
}

/// `n` standard normal samples, reproducible from `seed` (splitmix64 and
/// Box–Muller).
pub fn white_noise(n: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    let mut uniform = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let (u1, u2) = (uniform().max(f64::MIN_POSITIVE), uniform());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        })
        .collect()
}

/// `x` with white noise of standard deviation `sigma` added, reproducible
/// from `seed`.
pub fn with_noise(x: &[f64], sigma: f64, seed: u64) -> Vec<f64> {
    x.iter()
        .zip(white_noise(x.len(), seed))
        .map(|(x, e)| x + sigma * e)
        .collect()
}

/// The wNRMSE [JA 81] that white current noise of standard deviation `sigma`
/// alone gives against the measured current `i` with weights `w`.
pub fn noise_floor(sigma: f64, i: &[f64], w: &[f64]) -> f64 {
    let sw: f64 = w.iter().sum();
    let swi2: f64 = w.iter().zip(i).map(|(w, i)| w * i * i).sum();
    if swi2 > 0.0 {
        sigma * (sw / swi2).sqrt()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_std_sees_through_a_square_wave() {
        let noise = white_noise(20_000, 7);
        let x: Vec<f64> = noise
            .iter()
            .enumerate()
            .map(|(k, e)| {
                let square = if (k / 500) % 2 == 0 { 0.2 } else { 0.0 };
                let ramp = 1e-5 * k as f64;
                square + ramp + 1e-3 * e
            })
            .collect();
        let sigma = noise_std(&x);
        assert!((sigma / 1e-3 - 1.0).abs() < 0.05, "σ = {sigma}");
    }

    #[test]
    fn floor_matches_the_wnrmse_of_pure_noise() {
        let n = 50_000;
        let noise = white_noise(n, 3);
        let i: Vec<f64> = (0..n)
            .map(|k| 0.1 + 0.05 * (k as f64 * 1e-3).sin())
            .collect();
        let w: Vec<f64> = (0..n)
            .map(|k| 1.0 + (k as f64 * 7e-4).cos().abs())
            .collect();
        let noisy: Vec<f64> = i.iter().zip(&noise).map(|(i, e)| i + 2e-3 * e).collect();
        let num: f64 = (0..n).map(|k| w[k] * (noisy[k] - i[k]).powi(2)).sum();
        let den: f64 = (0..n).map(|k| w[k] * i[k] * i[k]).sum();
        let measured = (num / den).sqrt();
        let floor = noise_floor(2e-3, &i, &w);
        assert!(
            (measured / floor - 1.0).abs() < 0.02,
            "{measured} vs {floor}"
        );
    }

    #[test]
    fn bic_prefers_the_simpler_model_at_equal_error() {
        let n = effective_samples(&[1.0; 1000]);
        assert_eq!(n, 1000.0);
        assert!(bic(0.01, 1, n) < bic(0.01, 2, n));
        // A 1 % relative drop in error over 1000 samples beats one parameter
        // (1000·ln(0.98) ≈ −20 < ln 1000 ≈ 6.9) …
        assert!(bic(0.0099, 2, n) < bic(0.01, 1, n));
        // … a 0.1 % drop does not.
        assert!(bic(0.00999, 2, n) > bic(0.01, 1, n));
    }

    #[test]
    fn effective_samples_of_concentrated_weights() {
        let mut w = vec![0.0; 1000];
        w[..10].fill(1.0);
        assert!((effective_samples(&w) - 10.0).abs() < 1e-12);
    }
}
