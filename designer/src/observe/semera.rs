//! SEMERA: stochastic electromagnetic estimation of the resistance r, the
//! apparent inductance l and the flux linkage λ of a reluctance actuator from
//! sampled coil voltage and current alone (semera-electromagnetic-estimation,
//! [SE §II], [SE Alg. 1]), configured from a description.
//!
//! The algorithm is `reldesign_runtime::semera`, here in f64: the emitted
//! estimators are the same code in f32/f64, so they agree with this reference
//! by construction. Its module docs give the filter line by line (state
//! [r, l, l_prev], H_k of [SE 11], the gain [SE 43], the l block's Joseph-form
//! update that keeps f32 stable, the CI detector and the expert rule) and
//! the choices the paper leaves open (ι₀ = 0, non-finite samples as missing
//! measurements).

use reldesign_runtime::semera as algorithm;

use crate::description::{Description, SemeraSettings};

/// Everything [`Semera::new`] needs: `[observer]` σ_v, σ_i, Δ, the coil's N
/// and `[observer.semera]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SemeraConfig {
    /// Δ [s].
    pub sample_period: f64,
    /// σ_v [V].
    pub voltage_noise: f64,
    /// σ_i [A].
    pub current_noise: f64,
    /// N, the coil's turns (for φ = λ/N and R = N²/l).
    pub turns: f64,
    /// [SE Table II] / [SE Table V].
    pub filter: SemeraSettings,
}

impl SemeraConfig {
    /// The configuration of a description with `[observer.semera]`.
    pub fn from_description(d: &Description) -> Option<SemeraConfig> {
        let o = d.observer.as_ref()?;
        Some(SemeraConfig {
            sample_period: o.sample_period,
            voltage_noise: o.voltage_noise,
            current_noise: o.current_noise,
            turns: d.coil.turns,
            filter: o.semera?,
        })
    }

    /// The runtime's settings (the values the emitted code holds as consts).
    pub fn settings(&self) -> algorithm::Settings<f64> {
        let f = &self.filter;
        algorithm::Settings {
            sample_period: self.sample_period,
            voltage_noise: self.voltage_noise,
            current_noise: self.current_noise,
            turns: self.turns,
            initial_resistance: f.initial_resistance,
            initial_resistance_std: f.initial_resistance_std,
            initial_inductance: f.initial_inductance,
            initial_inductance_std: f.initial_inductance_std,
            resistance_rate_std: f.resistance_rate_std,
            inductance_accel_std: f.inductance_accel_std,
            ci_sigmas: f.ci_sigmas,
        }
    }
}

/// The estimate of one sample (SEMERA and the integral estimator alike):
/// r̂, l̂, λ̂, φ̂ = λ̂/N, R̂ = N²/l̂ and the CI detector's `valid`.
pub type Estimate = algorithm::Estimate<f64>;

/// The SEMERA estimator ([SE Alg. 1]) in f64.
#[derive(Debug, Clone, PartialEq)]
pub struct Semera(algorithm::Semera<f64>);

impl Semera {
    /// [SE Alg. 1], lines 1–3: x̂_{1/0} = x̄₀ [SE 25], Σ_{1/0} = P₀ [SE 26], ι₀ = 0.
    pub fn new(config: &SemeraConfig) -> Semera {
        Semera(algorithm::Semera::new(&config.settings()))
    }

    /// One sample k: the measured voltage u_k = `v` [V] and current ι_k = `i`
    /// [A] ([SE Alg. 1], lines 5–16).
    pub fn step(&mut self, v: f64, i: f64) -> Estimate {
        self.0.step(v, i)
    }

    /// x̂_{k+1/k} = [r, l, l_prev]: the a priori state for the next sample.
    pub fn state(&self) -> [f64; 3] {
        self.0.state()
    }

    /// Σ_{k+1/k} as a full 3×3 matrix.
    pub fn covariance(&self) -> [[f64; 3]; 3] {
        self.0.covariance()
    }

    /// R_k of [SE 15] at the a priori state for the next sample (a diagnostic:
    /// the gain [SE 43] takes σ_v² alone).
    pub fn observation_noise_variance(&self) -> f64 {
        self.0.observation_noise_variance()
    }
}
