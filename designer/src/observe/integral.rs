//! The integral estimator (semera-electromagnetic-estimation [SE §II-D],
//! [SE Alg. 2]), configured from a description: the flux linkage as the
//! running integral [SE 46] of u − r̄·ι, reset at the start of each energizing
//! operation, where the resistance is recomputed from the finished operation
//! by [SE 47]; l̂ = λ̂/ι [SE 48] under the same confidence-interval detector as
//! SEMERA.
//!
//! The algorithm is `reldesign_runtime::integral`, here in f64 (the emitted
//! estimators are the same code). Its module docs give [SE Alg. 2] line by
//! line and the choices the paper leaves open: where an energizing operation
//! starts (the measured voltage rising above `energize_threshold`), when [SE 47]
//! is trusted (a whole operation, S_ι above its noise interval), and
//! non-finite samples as missing.

use reldesign_runtime::integral as algorithm;

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

    /// The runtime's settings (the values the emitted code holds as consts).
    pub fn runtime_settings(&self) -> algorithm::Settings<f64> {
        let s = &self.settings;
        algorithm::Settings {
            sample_period: self.sample_period,
            current_noise: self.current_noise,
            turns: self.turns,
            initial_resistance: s.initial_resistance,
            initial_inductance: s.initial_inductance,
            initial_flux_linkage: s.initial_flux_linkage,
            ci_sigmas: s.ci_sigmas,
            energize_threshold: s.energize_threshold,
        }
    }
}

/// The integral estimator ([SE Alg. 2]) in f64.
#[derive(Debug, Clone, PartialEq)]
pub struct Integral(algorithm::Integral<f64>);

impl Integral {
    /// [SE Alg. 2], lines 1–2: r̄ = r̄₀, S_u = S_ι = 0 (at rest).
    pub fn new(config: &IntegralConfig) -> Integral {
        Integral(algorithm::Integral::new(&config.runtime_settings()))
    }

    /// One sample k: measured voltage u_k = `v` [V], current ι_k = `i` [A].
    pub fn step(&mut self, v: f64, i: f64) -> Estimate {
        self.0.step(v, i)
    }

    /// r̄, the resistance in use.
    pub fn resistance(&self) -> f64 {
        self.0.resistance()
    }
}
