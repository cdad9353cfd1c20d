//! SEMERA: stochastic electromagnetic estimation of the resistance r, the
//! apparent inductance l and the flux linkage λ of a reluctance actuator from
//! sampled coil voltage and current alone (semera-electromagnetic-estimation
//! [SE §II], [SE Alg. 1]), generic over the float: the emitted estimators
//! (`f32`, `f64`) and the designer's f64 reference are this code.
//!
//! The filter ([SE Alg. 1], one [`Semera::step`] per sample, every Δ):
//!
//! - state x_k = [r_k, l_k, l_{k−1}] [SE 10], observation z_k = u_k [SE 9] with the
//!   stochastic observation row H_k = [ι_k, ι_k/Δ, −ι_{k−1}/Δ] [SE 11];
//! - process model [SE 16] with F of [SE 21] (constant r, linear l; the prediction
//!   [SE 19] is garbled in the text, it reads l̂_{k+1/k} = 2·l̂_{k/k} − l̂_{k−1/k},
//!   ERRATA), G of [SE 23], Q = diag(σ_ṙ², σ_l̈²) [SE 24], so
//!   G·Q·Gᵀ = diag((σ_ṙ·Δ)², (σ_l̈·Δ²)², 0);
//! - prior x̄₀ = [r̄₀, l̄₀, l̄₀] [SE 25], P₀ of [SE 26] with σ²_r0 in its first
//!   diagonal element (the text prints σ_r0, ERRATA);
//! - the gain [SE 43] K̂ = Σ Hᵀ (H Σ Hᵀ + σ_v²)⁻¹: the observation noise [SE 12–15]
//!   depends on the state and on the current noise through H itself, so the
//!   paper derives the gain from z_k = C_k x_k + v_v (only the voltage noise,
//!   σ_v²) and evaluates it at H_k in place of the unknown C_k. The
//!   state-dependent variance R_k of [SE 15] therefore does not enter the step
//!   (it is [`Semera::observation_noise_variance`], a diagnostic);
//! - Σ_{k/k} = (I − K̂ H) Σ (line 10). With g = Σ Hᵀ this is
//!   B = Σ − K̂ gᵀ (symmetric in exact arithmetic: its upper triangle is
//!   used), and it also equals the Joseph form
//!   (I − K̂ H) Σ (I − K̂ H)ᵀ + σ_v² K̂ K̂ᵀ = B − d K̂ᵀ with d = B Hᵀ − σ_v² K̂,
//!   where d vanishes in exact arithmetic but corrects B's rounding to first
//!   order. The step evaluates the l block (rows and columns 2–3) as B − d K̂ᵀ
//!   and the r row as B. Reason: B alone loses Σ's positive definiteness in
//!   f32. Σ's l block is nearly singular (l_k ≈ l_{k−1}), its entries grow by
//!   σ_l̈ through the rest periods and the update cancels them to ~1e-9 of
//!   their size; Σ(1,1) then goes negative within the first decay of the
//!   current and r̂ random-walks away (by up to 30 Ω over 300 noisy cycles of
//!   the semera valve in f32). Correcting the l block, where the cancellation
//!   happens, is enough: the f32 r̂ then stays within 3e-4 Ω of f64 on those
//!   300 cycles (1e-4 relative on a relay-like record with [SE Table V]'s
//!   parameters), as does the full Joseph form, at 8 more multiplications
//!   instead of 15;
//! - the confidence-interval detector: the a posteriori r and l are the
//!   estimates only if |ι_k| and |ι_{k−1}| both lie outside [−n_σ σ_i, n_σ σ_i]
//!   (and the sample was used, below); otherwise the expert rule
//!   r̂_k = r̂_{k−1}, l̂_k = l̄₀ (the device at rest; lines 13–15 of [SE Alg. 1],
//!   lost in the text, are read from [SE §II-C]);
//! - λ̂_k = l̂_k·ι_k (line 16), φ̂ = λ̂/N and R̂ = N²/l̂ ([SE §II-C], N known).
//!
//! Choices the paper leaves open, made here:
//!
//! - [SE Alg. 1] registers ι₀ before its loop. [`Semera::new`] starts at rest
//!   with ι₀ = 0, so the first call of `step` is k = 1 (under the expert rule,
//!   since |ι₀| is inside the interval).
//! - A sample whose update would not be finite (a NaN or infinite v or i, or
//!   the sample after a non-finite current, whose H uses it) is a missing
//!   measurement: the filter only predicts, and the estimate of that sample
//!   follows the expert rule (`valid` is false); its λ̂ is then l̄₀·ι
//!   (not finite for a non-finite current). The state stays finite.
//!
//! No allocation, no panic path, no division except 1/s (s ≥ σ_v² > 0) and
//! N²/l̂.

use crate::linalg::Scalar;
use crate::math::Real;

/// What [`Semera::new`] needs: the description's `[observer]` σ_v, σ_i, Δ,
/// the coil's N and `[observer.semera]` ([SE Table II] / [SE Table V]), by TOML key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings<T> {
    /// `observer.sample_period`: Δ [s].
    pub sample_period: T,
    /// `observer.voltage_noise`: σ_v [V], the gain's noise [SE 43].
    pub voltage_noise: T,
    /// `observer.current_noise`: σ_i [A], the CI detector's unit.
    pub current_noise: T,
    /// `coil.turns`: N, for φ = λ/N and R = N²/l.
    pub turns: T,
    /// r̄₀ [Ω]: expected initial resistance [SE 25].
    pub initial_resistance: T,
    /// σ_r0 [Ω] [SE 26].
    pub initial_resistance_std: T,
    /// l̄₀ [H]: inductance at rest [SE 25]; the expert rule's l̂.
    pub initial_inductance: T,
    /// σ_l0 [H] [SE 26].
    pub initial_inductance_std: T,
    /// σ_ṙ [Ω/s] [SE 24].
    pub resistance_rate_std: T,
    /// σ_l̈ [H/s²] [SE 24].
    pub inductance_accel_std: T,
    /// n_σ: half-width of the current's noise interval in σ_i.
    pub ci_sigmas: T,
}

/// The estimate of one sample (SEMERA and the integral estimator alike).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate<T> {
    /// r̂ [Ω], the coil resistance.
    pub r: T,
    /// l̂ [H], the apparent inductance (l̄₀ under the expert rule).
    pub l: T,
    /// λ̂ [Wb], the flux linkage.
    pub lambda: T,
    /// φ̂ = λ̂/N [Wb], the magnetic flux.
    pub phi: T,
    /// R̂ = N²/l̂ [H⁻¹], the reluctance.
    pub reluctance: T,
    /// The confidence-interval detector: |ι_k| and |ι_{k−1}| both exceed
    /// n_σ·σ_i (and, for SEMERA, the sample was used), so r̂ and l̂ come from
    /// the estimator; false under the expert rule (r̂ held, l̂ = l̄₀).
    pub valid: bool,
}

/// The step's constants, derived once from the [`Settings`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Constants<T> {
    /// 1/Δ [SE 11]
    inv_dt: T,
    /// σ_v² [SE 43]
    sigma_v2: T,
    /// (σ_ṙ·Δ)²: G Q Gᵀ (1, 1), [SE 23–24]
    q_r: T,
    /// (σ_l̈·Δ²)²: G Q Gᵀ (2, 2), [SE 23–24]
    q_l: T,
    /// n_σ·σ_i: the CI detector's bound
    ci: T,
    /// l̄₀: the expert rule's l̂
    l0: T,
    /// 1/N
    inv_turns: T,
    /// N²
    turns_sq: T,
    /// σ_i² (R_k of [SE 15] only)
    sigma_i2: T,
}

/// The SEMERA estimator ([SE Alg. 1]).
#[derive(Clone, Debug, PartialEq)]
pub struct Semera<T> {
    c: Constants<T>,
    /// x̂_{k+1/k} = [r, l, l_prev] (a priori for the next sample).
    x: [T; 3],
    /// Σ_{k+1/k}, symmetric: [Σ11, Σ12, Σ13, Σ22, Σ23, Σ33].
    p: [T; 6],
    /// ι_{k−1}.
    i_prev: T,
    /// r̂_{k−1} (the expert rule keeps it).
    r_hat: T,
}

impl<T: Scalar> Semera<T> {
    /// At rest ([SE Alg. 1], lines 1–3): x̂_{1/0} = x̄₀ = [r̄₀, l̄₀, l̄₀] [SE 25],
    /// Σ_{1/0} = P₀ [SE 26], ι₀ = 0.
    #[must_use]
    pub fn new(s: &Settings<T>) -> Self {
        let dt = s.sample_period;
        let c = Constants {
            inv_dt: T::ONE / dt,
            sigma_v2: s.voltage_noise * s.voltage_noise,
            q_r: (s.resistance_rate_std * dt) * (s.resistance_rate_std * dt),
            q_l: (s.inductance_accel_std * dt * dt) * (s.inductance_accel_std * dt * dt),
            ci: s.ci_sigmas * s.current_noise,
            l0: s.initial_inductance,
            inv_turns: T::ONE / s.turns,
            turns_sq: s.turns * s.turns,
            sigma_i2: s.current_noise * s.current_noise,
        };
        // [SE 26]: σ²_r0 (ERRATA), and the l block [[σ²_l0, σ²_l0], [σ²_l0, σ²_l0]] (l₋₁ = l₀)
        let var_r0 = s.initial_resistance_std * s.initial_resistance_std;
        let var_l0 = s.initial_inductance_std * s.initial_inductance_std;
        Semera {
            c,
            x: [
                s.initial_resistance,
                s.initial_inductance,
                s.initial_inductance,
            ],
            p: [var_r0, T::ZERO, T::ZERO, var_l0, var_l0, var_l0],
            i_prev: T::ZERO,
            r_hat: s.initial_resistance,
        }
    }

    /// One sample k: the measured coil voltage u_k = `v` [V] and current
    /// ι_k = `i` [A] ([SE Alg. 1], lines 5–16).
    #[must_use]
    pub fn step(&mut self, v: T, i: T) -> Estimate<T> {
        let c = &self.c;
        // line 7: H_k [SE 11]
        let h1 = i;
        let h2 = i * c.inv_dt;
        let h3 = -(self.i_prev * c.inv_dt);
        // line 8: K̂ [SE 43] = g/s, g = Σ Hᵀ, s = H Σ Hᵀ + σ_v²
        let [p11, p12, p13, p22, p23, p33] = self.p;
        let g1 = p11 * h1 + p12 * h2 + p13 * h3;
        let g2 = p12 * h1 + p22 * h2 + p23 * h3;
        let g3 = p13 * h1 + p23 * h2 + p33 * h3;
        let s = h1 * g1 + h2 * g2 + h3 * g3 + c.sigma_v2;
        let w = T::ONE / s;
        // line 9: x̂_{k/k} = x̂_{k/k−1} + K̂·ν, ν = z_k − H_k x̂_{k/k−1}, K̂·ν = g·(ν/s)
        let [mut r, mut l, mut lp] = self.x;
        let nu = v - (h1 * r + h2 * l + h3 * lp);
        let mut q = self.p;
        let m = nu * w;
        // a non-finite sample is a missing measurement: prediction only
        let used = m.finite();
        if used {
            let (k1, k2, k3) = (g1 * w, g2 * w, g3 * w);
            r = r + g1 * m;
            l = l + g2 * m;
            lp = lp + g3 * m;
            // line 10: Σ_{k/k} = (I − K̂ H) Σ = B = Σ − K̂ gᵀ, the l block as the
            // Joseph form B − d K̂ᵀ, d = B Hᵀ − σ_v² K̂ (= 0 up to rounding; module docs)
            let (b11, b12, b13) = (p11 - k1 * g1, p12 - k1 * g2, p13 - k1 * g3);
            let (b22, b23, b33) = (p22 - k2 * g2, p23 - k2 * g3, p33 - k3 * g3);
            let d2 = b12 * h1 + b22 * h2 + b23 * h3 - c.sigma_v2 * k2;
            let d3 = b13 * h1 + b23 * h2 + b33 * h3 - c.sigma_v2 * k3;
            q = [b11, b12, b13, b22 - d2 * k2, b23 - d2 * k3, b33 - d3 * k3];
        }
        // lines 11–12: x̂_{k+1/k} = F x̂_{k/k}, Σ_{k+1/k} = F Σ Fᵀ + G Q Gᵀ [SE 21], [SE 23], [SE 24]
        let [q11, q12, q13, q22, q23, q33] = q;
        let two = T::ONE + T::ONE;
        self.x = [r, two * l - lp, l];
        self.p = [
            q11 + c.q_r,
            two * q12 - q13,
            q12,
            (two + two) * (q22 - q23) + q33 + c.q_l,
            two * q22 - q23,
            q22,
        ];
        // lines 13–15: the CI detector and the expert rule
        let valid = used && Real::abs(i) > c.ci && Real::abs(self.i_prev) > c.ci;
        let (r_hat, l_hat) = if valid { (r, l) } else { (self.r_hat, c.l0) };
        self.r_hat = r_hat;
        self.i_prev = i;
        // line 16 and [SE §II-C]: λ = l·ι, φ = λ/N, R = N²/l
        let lambda = l_hat * i;
        Estimate {
            r: r_hat,
            l: l_hat,
            lambda,
            phi: lambda * c.inv_turns,
            reluctance: c.turns_sq / l_hat,
            valid,
        }
    }

    /// x̂_{k+1/k} = [r, l, l_prev]: the a priori state for the next sample.
    #[must_use]
    pub fn state(&self) -> [T; 3] {
        self.x
    }

    /// Σ_{k+1/k} as a full 3×3 matrix.
    #[must_use]
    pub fn covariance(&self) -> [[T; 3]; 3] {
        let [a, b, c, d, e, f] = self.p;
        [[a, b, c], [b, d, e], [c, e, f]]
    }

    /// R_k of [SE 15] at the a priori state for the next sample: the variance of
    /// the observation noise [SE 12], σ_v² + σ_i²·((r + l/Δ)² + (l_prev/Δ)²).
    /// Not used by the step (the gain [SE 43] takes σ_v² alone, see the module
    /// docs); a diagnostic of how much the current noise weighs.
    #[must_use]
    pub fn observation_noise_variance(&self) -> T {
        let [r, l, lp] = self.x;
        let a = r + l * self.c.inv_dt;
        let b = lp * self.c.inv_dt;
        self.c.sigma_v2 + self.c.sigma_i2 * (a * a + b * b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Δ = 0.5, σ_v = 1, σ_i = 0.1, n_σ = 1, r̄₀ = 2, σ_r0 = 1, l̄₀ = 1,
    /// σ_l0 = 1, N = 2, no process noise (numbers a hand can follow).
    fn small<T: Scalar>(t: fn(f64) -> T) -> Settings<T> {
        Settings {
            sample_period: t(0.5),
            voltage_noise: t(1.0),
            current_noise: t(0.1),
            turns: t(2.0),
            initial_resistance: t(2.0),
            initial_resistance_std: t(1.0),
            initial_inductance: t(1.0),
            initial_inductance_std: t(1.0),
            resistance_rate_std: t(0.0),
            inductance_accel_std: t(0.0),
            ci_sigmas: t(1.0),
        }
    }

    /// [SE Alg. 1] by hand (the derivation is in the designer's
    /// `observe_semera.rs`): k = 1 (u = 3, ι = 1) under the expert rule, then
    /// k = 2 (u = 2, ι = 2) valid with r̂ = 5/6, l̂ = 2/3, λ̂ = 4/3, φ̂ = 2/3,
    /// R̂ = 6 and Σ_{3/2}(1,1) = 1/2; in both floats.
    fn by_hand<T: Scalar + core::fmt::Debug>(t: fn(f64) -> T, back: fn(T) -> f64, tol: f64) {
        let close = |a: T, b: f64| (back(a) - b).abs() <= tol * b.abs().max(1.0);
        let mut s = Semera::new(&small(t));
        let e = s.step(t(3.0), t(1.0));
        assert!(!e.valid);
        assert_eq!(
            [e.r, e.l, e.lambda, e.phi, e.reluctance].map(back),
            [2.0, 1.0, 1.0, 0.5, 4.0]
        );
        for (x, want) in s
            .state()
            .into_iter()
            .zip([11.0 / 6.0, 2.0 / 3.0, 2.0 / 3.0])
        {
            assert!(close(x, want), "x̂_{{2/1}}: {x:?} vs {want}");
        }
        let e = s.step(t(2.0), t(2.0));
        assert!(e.valid);
        let want = [5.0 / 6.0, 2.0 / 3.0, 4.0 / 3.0, 2.0 / 3.0, 6.0];
        for (got, want) in [e.r, e.l, e.lambda, e.phi, e.reluctance]
            .into_iter()
            .zip(want)
        {
            assert!(close(got, want), "{got:?} vs {want}");
        }
        let [[p11, p12, _], [p21, ..], _] = s.covariance();
        assert!(close(p11, 0.5) && close(p12, -1.0 / 3.0) && back(p12) == back(p21));
    }

    #[test]
    fn algorithm_1_by_hand_in_both_floats() {
        by_hand(|x| x, |x| x, 1e-15);
        #[allow(clippy::as_conversions, clippy::cast_possible_truncation)]
        by_hand(|x| x as f32, f64::from, 1e-6);
    }

    /// A NaN or infinite sample predicts only: same state as a sample at
    /// ι = 0 would not give (the innovation is skipped), the expert rule, and
    /// the step after a non-finite current is not valid (its H uses it).
    #[test]
    fn non_finite_samples_are_missing_in_f32() {
        #[allow(clippy::as_conversions, clippy::cast_possible_truncation)]
        let mut s = Semera::new(&small(|x| x as f32));
        let _ = s.step(3.0, 1.0);
        let before = (s.state(), s.covariance());
        for (v, i, next_valid) in [(f32::NAN, 1.0, true), (1.0, f32::INFINITY, false)] {
            let mut t = s.clone();
            let e = t.step(v, i);
            assert!(!e.valid && (e.r, e.l) == (2.0, 1.0) && e.reluctance == 4.0);
            assert_eq!((t.state(), t.covariance()), before, "prediction only");
            assert_eq!(t.step(2.0, 2.0).valid, next_valid);
            assert!(t.state().iter().all(|x| x.is_finite()));
        }
    }

    /// R_k of [SE 15]: σ_v² + σ_i²·((r + l/Δ)² + (l_prev/Δ)²) at x̄₀ = [2, 1, 1].
    #[test]
    fn observation_noise_variance_is_15() {
        let s = Semera::new(&small(|x| x));
        assert_eq!(s.observation_noise_variance(), 1.0 + 0.01 * (16.0 + 4.0));
    }
}
