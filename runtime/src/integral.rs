//! The integral estimator (semera-electromagnetic-estimation [SE §II-D],
//! [SE Alg. 2]), generic over the float: the flux linkage as the running
//! integral [SE 46] of u − r̄·ι, reset at the start of each energizing operation,
//! where the resistance is recomputed from the finished operation by [SE 47];
//! l̂ = λ̂/ι [SE 48] under the same confidence-interval detector as SEMERA. The
//! emitted estimators and the designer's f64 reference are this code.
//!
//! [SE Alg. 2], one [`Integral::step`] per sample k:
//!
//! - line 5: S_u += u_k, S_ι += ι_k;
//! - line 6: λ̂_k = λ₀ + Δ·(S_u − r̄·S_ι);
//! - lines 7–9: l̂_k = λ̂_k/ι_k if |ι_k| and |ι_{k−1}| exceed n_σ·σ_i, else l̄₀;
//! - lines 10–11: at the start of an energizing operation, r̄ = S_u/S_ι [SE 47]
//!   and S_u = S_ι = 0;
//! - line 12: r̂_k = r̄.
//!
//! Choices the paper leaves open, made here:
//!
//! - **The start of an energizing operation** is detected from the measured
//!   voltage: it rises above `energize_threshold` between samples k − 1 and k
//!   (u_k above, the previous finite sample not). In the backward difference
//!   [SE 2] u_k stands for the voltage over ((k−1)Δ, kΔ], so the operation
//!   started at sample k − 1, where the flux is still λ₀: that is Algorithm
//!   2's reset sample, and the reset (lines 10–11 of k − 1) is done when the
//!   rise is seen, before sample k is summed. Only r̂_{k−1} differs from
//!   [SE Alg. 2] run with hindsight: it is reported at k. With data sampled at
//!   the instants of a step (u_k = v(kΔ), the edge sample already high) this
//!   placement keeps [SE 47] unbiased too and λ̂ exact after the voltage falls
//!   (where l̂ = λ̂/ι is most sensitive); λ̂ is then one sample's u·Δ high
//!   while the voltage is on.
//! - **[SE 47] needs a whole operation**: S_u/S_ι is used only when the summed
//!   current lies outside its noise interval, S_ι > n_σ·σ_i·√m for the m
//!   samples summed (the CI detector applied to the sum), and the quotient is
//!   finite and positive. This skips the first reset of a record that starts
//!   at rest (0/0, or noise over noise) and keeps r̄.
//! - `new` starts at rest: ι₀ = 0 and no previous voltage above the
//!   threshold (a record that starts energized starts an operation at k = 1).
//! - A non-finite v or i is a missing sample: nothing is added to the sums;
//!   its estimate follows the rule above (λ̂ from the sums; l̂ = l̄₀ when ι is
//!   NaN).
//!
//! No allocation, no panic path; the divisions are S_u/S_ι (checked), λ̂/ι
//! (only outside the noise interval), 1/N and N²/l̂.

use crate::linalg::Scalar;
use crate::math::Real;
use crate::semera::Estimate;

/// What [`Integral::new`] needs: the description's `[observer]` σ_i, Δ, the
/// coil's N and `[observer.integral]`, by TOML key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings<T> {
    /// `observer.sample_period`: Δ [s].
    pub sample_period: T,
    /// `observer.current_noise`: σ_i [A], the CI detector's unit.
    pub current_noise: T,
    /// `coil.turns`: N, for φ = λ/N and R = N²/l.
    pub turns: T,
    /// r̄₀ [Ω]: the resistance until the first update [SE 47].
    pub initial_resistance: T,
    /// l̄₀ [H]: the expert rule's l̂.
    pub initial_inductance: T,
    /// λ₀ [Wb]: the flux linkage at each reset [SE 46].
    pub initial_flux_linkage: T,
    /// n_σ: half-width of the current's noise interval in σ_i.
    pub ci_sigmas: T,
    /// [V]: the voltage rising above it starts an energizing operation.
    pub energize_threshold: T,
}

/// The step's constants, derived once from the [`Settings`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Constants<T> {
    /// Δ
    dt: T,
    /// λ₀
    lambda0: T,
    /// l̄₀
    l0: T,
    /// n_σ·σ_i: the CI detector's bound
    ci: T,
    /// (n_σ·σ_i)²: [SE 47] is used when S_ι² > (n_σ·σ_i)²·m
    ci_sq: T,
    /// the energizing threshold [V]
    threshold: T,
    /// 1/N
    inv_turns: T,
    /// N²
    turns_sq: T,
}

/// The integral estimator ([SE Alg. 2]).
#[derive(Clone, Debug, PartialEq)]
pub struct Integral<T> {
    c: Constants<T>,
    /// r̄
    r_bar: T,
    /// S_u
    sum_u: T,
    /// S_ι
    sum_i: T,
    /// m: samples in the sums
    count: T,
    /// ι_{k−1}
    i_prev: T,
    /// The last finite voltage sample.
    v_prev: T,
}

impl<T: Scalar> Integral<T> {
    /// At rest ([SE Alg. 2], lines 1–2): r̄ = r̄₀, S_u = S_ι = 0, ι₀ = 0.
    #[must_use]
    pub fn new(s: &Settings<T>) -> Self {
        let ci = s.ci_sigmas * s.current_noise;
        Integral {
            c: Constants {
                dt: s.sample_period,
                lambda0: s.initial_flux_linkage,
                l0: s.initial_inductance,
                ci,
                ci_sq: ci * ci,
                threshold: s.energize_threshold,
                inv_turns: T::ONE / s.turns,
                turns_sq: s.turns * s.turns,
            },
            r_bar: s.initial_resistance,
            sum_u: T::ZERO,
            sum_i: T::ZERO,
            count: T::ZERO,
            i_prev: T::ZERO,
            v_prev: T::ZERO,
        }
    }

    /// One sample k: the measured coil voltage u_k = `v` [V] and current
    /// ι_k = `i` [A].
    #[must_use]
    pub fn step(&mut self, v: T, i: T) -> Estimate<T> {
        let c = &self.c;
        // lines 10–11 of sample k − 1: the voltage rose between k − 1 and k, so
        // the operation started at k − 1; reset [SE 47] before sample k is summed
        if v > c.threshold && self.v_prev <= c.threshold {
            // [SE 47] only when S_ι is more than noise: S_ι > n_σ·σ_i·√m
            if self.sum_i > T::ZERO && self.sum_i * self.sum_i > c.ci_sq * self.count {
                let r = self.sum_u / self.sum_i;
                if r > T::ZERO && r.finite() {
                    self.r_bar = r;
                }
            }
            self.sum_u = T::ZERO;
            self.sum_i = T::ZERO;
            self.count = T::ZERO;
        }
        // line 5 (a non-finite sample is missing: nothing is summed)
        if v.finite() && i.finite() {
            self.sum_u = self.sum_u + v;
            self.sum_i = self.sum_i + i;
            self.count = self.count + T::ONE;
            self.v_prev = v;
        }
        // line 6: [SE 46]
        let lambda = c.lambda0 + c.dt * (self.sum_u - self.r_bar * self.sum_i);
        // lines 7–9: the CI detector, [SE 48] or the expert rule
        let valid = Real::abs(i) > c.ci && Real::abs(self.i_prev) > c.ci;
        let l = if valid { lambda / i } else { c.l0 };
        self.i_prev = i;
        // line 12: r̂_k = r̄
        Estimate {
            r: self.r_bar,
            l,
            lambda,
            phi: lambda * c.inv_turns,
            reluctance: c.turns_sq / l,
            valid,
        }
    }

    /// r̄, the resistance in use [Ω].
    #[must_use]
    pub fn resistance(&self) -> T {
        self.r_bar
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Δ = 0.5, λ₀ = 0.1, r̄₀ = 2, l̄₀ = 1, σ_i = 0.1, n_σ = 1, threshold
    /// 5 V, N = 2.
    fn small<T: Scalar>(t: fn(f64) -> T) -> Settings<T> {
        Settings {
            sample_period: t(0.5),
            current_noise: t(0.1),
            turns: t(2.0),
            initial_resistance: t(2.0),
            initial_inductance: t(1.0),
            initial_flux_linkage: t(0.1),
            ci_sigmas: t(1.0),
            energize_threshold: t(5.0),
        }
    }

    /// [SE Alg. 2] by hand (derivation in the designer's `observe_semera.rs`):
    /// λ̂ = 4.1, 6.1, 4.1; l̂ = 1 (ι₀ = 0), 6.1/3, 2.05; then the voltage rises
    /// again: r̄ = 20/6 [SE 47], reset, λ̂ = 0.1 + 0.5·(10 − 1/6), l̂ = l̄₀.
    fn by_hand<T: Scalar + core::fmt::Debug>(t: fn(f64) -> T, back: fn(T) -> f64, tol: f64) {
        let close = |a: T, b: f64| (back(a) - b).abs() <= tol * b.abs().max(1.0);
        let mut g = Integral::new(&small(t));
        let want = [
            (10.0, 1.0, 2.0, 4.1, 1.0, false),
            (10.0, 3.0, 2.0, 6.1, 6.1 / 3.0, true),
            (0.0, 2.0, 2.0, 4.1, 2.05, true),
            (
                10.0,
                0.05,
                10.0 / 3.0,
                0.1 + 0.5 * (10.0 - 1.0 / 6.0),
                1.0,
                false,
            ),
        ];
        for (v, i, r, lambda, l, valid) in want {
            let e = g.step(t(v), t(i));
            assert_eq!(e.valid, valid, "at ({v}, {i})");
            assert!(
                close(e.r, r) && close(e.lambda, lambda) && close(e.l, l),
                "{e:?}"
            );
            assert!(
                close(e.phi, lambda / 2.0) && close(e.reluctance, 4.0 / l),
                "{e:?}"
            );
        }
        assert!(close(g.resistance(), 10.0 / 3.0));
    }

    #[test]
    fn algorithm_2_by_hand_in_both_floats() {
        by_hand(|x| x, |x| x, 1e-15);
        #[allow(clippy::as_conversions, clippy::cast_possible_truncation)]
        by_hand(|x| x as f32, f64::from, 1e-6);
    }

    /// A NaN voltage is missing, not a fall: the next high sample starts no
    /// operation, so nothing is reset; a NaN current adds nothing either.
    #[test]
    fn missing_samples_neither_sum_nor_reset() {
        let mut g = Integral::new(&small(|x| x));
        let _ = g.step(10.0, 1.0);
        let e = g.step(f64::NAN, 1.0);
        assert!(e.lambda == 4.1 && e.valid, "ι is measured: l̂ = λ̂/ι");
        let e = g.step(10.0, f64::NAN);
        assert!(e.lambda == 4.1 && !e.valid && e.l == 1.0);
        let e = g.step(10.0, 2.0);
        assert_eq!((e.r, e.lambda), (2.0, 0.1 + 0.5 * (20.0 - 2.0 * 3.0)));
    }
}
