//! The integral estimator (semera-electromagnetic-estimation §II-D,
//! Algorithm 2): the flux linkage as the running integral (46) of u − r̄·ι,
//! reset at the start of each energizing operation, where the resistance is
//! recomputed from the finished operation by (47); l̂ = λ̂/ι (48) under the
//! same confidence-interval detector as SEMERA. The f64 reference of the
//! emitted `Integral` (`codegen/src/semera.rs`): same operations, same order.
//!
//! Algorithm 2, one [`Integral::step`] per sample k:
//!
//! - line 5: S_u += u_k, S_ι += ι_k;
//! - line 6: λ̂_k = λ₀ + Δ·(S_u − r̄·S_ι);
//! - lines 7–9: l̂_k = λ̂_k/ι_k if |ι_k| and |ι_{k−1}| exceed n_σ·σ_i, else l̄₀;
//! - lines 10–11: at the start of an energizing operation, r̄ = S_u/S_ι (47)
//!   and S_u = S_ι = 0;
//! - line 12: r̂_k = r̄.
//!
//! Choices the paper leaves open, made here (and in the emitted code):
//!
//! - **The start of an energizing operation** is detected from the measured
//!   voltage: it rises above `energize_threshold` between samples k − 1 and k
//!   (u_k above, the previous finite sample not). In the backward difference
//!   (2) u_k stands for the voltage over ((k−1)Δ, kΔ], so the operation
//!   started at sample k − 1, where the flux is still λ₀: that is Algorithm
//!   2's reset sample, and the reset (lines 10–11 of k − 1) is done when the
//!   rise is seen, before sample k is summed. Only r̂_{k−1} differs from
//!   Algorithm 2 run with hindsight: it is reported at k. With data sampled at
//!   the instants of a step (u_k = v(kΔ), the edge sample already high) this
//!   placement keeps (47) unbiased too and λ̂ exact after the voltage falls
//!   (where l̂ = λ̂/ι is most sensitive); λ̂ is then one sample's u·Δ high
//!   while the voltage is on.
//! - **(47) needs a whole operation**: S_u/S_ι is used only when the summed
//!   current lies outside its noise interval, S_ι > n_σ·σ_i·√m for the m
//!   samples summed (the CI detector applied to the sum), and the quotient is
//!   finite and positive. This skips the first reset of a record that starts
//!   at rest (0/0, or noise over noise) and keeps r̄.
//! - `new` starts at rest: ι₀ = 0 and no previous voltage above the
//!   threshold (a record that starts energized starts an operation at k = 1).
//! - A non-finite v or i is a missing sample: nothing is added to the sums;
//!   its estimate follows the rule above (λ̂ from the sums; l̂ = l̄₀ when ι is
//!   NaN).

use crate::description::{Description, IntegralSettings};

use super::semera::Estimate;

/// Everything [`Integral::new`] needs: `[observer]` σ_i, Δ, the coil's N
/// and `[observer.integral]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegralConfig {
    /// Δ [s].
    pub sample_period: f64,
    /// σ_i [A].
    pub current_noise: f64,
    /// N, the coil's turns (for φ = λ/N and R = N²/l).
    pub turns: f64,
    pub settings: IntegralSettings,
}

impl IntegralConfig {
    /// The configuration of a description with `[observer.integral]`.
    pub fn from_description(d: &Description) -> Option<IntegralConfig> {
        let o = d.observer.as_ref()?;
        Some(IntegralConfig {
            sample_period: o.sample_period,
            current_noise: o.current_noise,
            turns: d.coil.turns,
            settings: o.integral?,
        })
    }
}

/// The integral estimator (Algorithm 2), f64 reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Integral {
    dt: f64,
    lambda0: f64,
    l0: f64,
    /// n_σ·σ_i
    ci: f64,
    /// (n_σ·σ_i)²
    ci_sq: f64,
    threshold: f64,
    inv_turns: f64,
    turns_sq: f64,
    /// r̄
    r_bar: f64,
    /// S_u
    sum_u: f64,
    /// S_ι
    sum_i: f64,
    /// m: samples in the sums
    count: f64,
    /// ι_{k−1}
    i_prev: f64,
    /// The last finite voltage sample.
    v_prev: f64,
}

impl Integral {
    /// Algorithm 2, lines 1–2: r̄ = r̄₀, S_u = S_ι = 0 (at rest).
    pub fn new(config: &IntegralConfig) -> Integral {
        let s = &config.settings;
        let ci = s.ci_sigmas * config.current_noise;
        Integral {
            dt: config.sample_period,
            lambda0: s.initial_flux_linkage,
            l0: s.initial_inductance,
            ci,
            ci_sq: ci * ci,
            threshold: s.energize_threshold,
            inv_turns: 1.0 / config.turns,
            turns_sq: config.turns * config.turns,
            r_bar: s.initial_resistance,
            sum_u: 0.0,
            sum_i: 0.0,
            count: 0.0,
            i_prev: 0.0,
            v_prev: 0.0,
        }
    }

    /// One sample k: measured voltage u_k = `v` [V], current ι_k = `i` [A].
    pub fn step(&mut self, v: f64, i: f64) -> Estimate {
        // lines 10–11 of sample k − 1: the voltage rose between k − 1 and k, so
        // the operation started at k − 1; reset (47) before sample k is summed
        if v > self.threshold && self.v_prev <= self.threshold {
            if self.sum_i > 0.0 && self.sum_i * self.sum_i > self.ci_sq * self.count {
                let r = self.sum_u / self.sum_i;
                if r > 0.0 && r.is_finite() {
                    self.r_bar = r;
                }
            }
            self.sum_u = 0.0;
            self.sum_i = 0.0;
            self.count = 0.0;
        }
        // line 5 (a non-finite sample is missing: nothing is summed)
        if v.is_finite() && i.is_finite() {
            self.sum_u += v;
            self.sum_i += i;
            self.count += 1.0;
            self.v_prev = v;
        }
        // line 6: (46)
        let lambda = self.lambda0 + self.dt * (self.sum_u - self.r_bar * self.sum_i);
        // lines 7–9: CI detector, (48) or the expert rule
        let valid = i.abs() > self.ci && self.i_prev.abs() > self.ci;
        let l = if valid { lambda / i } else { self.l0 };
        self.i_prev = i;
        // line 12
        Estimate {
            r: self.r_bar,
            l,
            lambda,
            phi: lambda * self.inv_turns,
            reluctance: self.turns_sq / l,
            valid,
        }
    }

    /// r̄, the resistance in use.
    pub fn resistance(&self) -> f64 {
        self.r_bar
    }
}
