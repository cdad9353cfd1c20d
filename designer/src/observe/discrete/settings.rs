//! The Kalman filters' settings (`[observer]`, `[observer.kalman]`) and
//! why a discretised model cannot be built.

use reldesign_runtime::observe::Weights;

use crate::description::{FluxStep, Observer, MAX_FLUX_SUBSTEPS};

/// Coil-resistance estimation (`estimate_resistance = true` in
/// `[observer.kalman]`): R as a random-walk state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResistanceSettings {
    /// σ_Ṙ [Ω/s] (> 0): the random walk's rate; w_R has σ = σ_Ṙ·T_s per step.
    pub rate_std: f64,
    /// Initial σ of R [Ω] (> 0) around the description's value.
    pub initial_std: f64,
}

impl ResistanceSettings {
    /// The settings of `[observer.kalman]`, `None` unless it estimates R.
    pub fn from_observer(o: &Observer) -> Option<ResistanceSettings> {
        let r = o.kalman.as_ref()?.resistance?;
        Some(ResistanceSettings {
            rate_std: r.rate_std,
            initial_std: r.initial_std,
        })
    }
}

/// The Kalman filters' settings (`[observer.kalman]` with σ_v, σ_i and T_s
/// of `[observer]`). Standard deviations are per sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanSettings {
    /// T_s [s] (> 0).
    pub sample_period: f64,
    /// σ_v [V] (> 0): noise of the measured coil voltage.
    pub voltage_noise: f64,
    /// σ_i [A] (> 0): noise of the measured coil current.
    pub current_noise: f64,
    /// σ of w_z [m] per step (> 0).
    pub process_z: f64,
    /// σ of w_φ [Wb] per step (> 0).
    pub process_phi: f64,
    /// σ of w_Hc [A/m] per step (> 0); exactly with the Jiles–Atherton core.
    pub process_hc: Option<f64>,
    /// Initial σ of z and z_prev [m] (> 0).
    pub initial_z_std: f64,
    /// Initial σ of φ [Wb] (> 0).
    pub initial_phi_std: f64,
    /// Initial σ of H_c [A/m] (> 0); exactly with the Jiles–Atherton core.
    pub initial_hc_std: Option<f64>,
    /// UKF spread α (> 0).
    pub ukf_alpha: f64,
    /// UKF β (≥ 0; 2 is optimal for Gaussian priors).
    pub ukf_beta: f64,
    /// UKF κ (n + κ > 0).
    pub ukf_kappa: f64,
    /// How the flux (and H_c) advance over a sample.
    pub flux_step: FluxStep,
}

/// Why a discretised model or filter could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KalmanError {
    #[error("observer.kalman: {name} = {value:e}: expected {expected}")]
    BadSetting {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error("observer.kalman: {0} is required with the Jiles–Atherton core (state H_c)")]
    MissingFieldSetting(&'static str),
    #[error("observer.kalman: {0} applies only to the Jiles–Atherton core (the model has no H_c)")]
    UnusedFieldSetting(&'static str),
    #[error("the symbol `{0}` the discretised model needs is already taken by the model")]
    NameTaken(String),
    #[error("observer.kalman: {name} = {value:e}: expected a finite number > 0")]
    BadResistanceSetting { name: &'static str, value: f64 },
    #[error("estimate_resistance: the model has no coil resistance parameter `R`")]
    NoResistance,
    #[error(
        "observer.sample_period = {sample_period:e} s is too long for the coil: the flux's \
         electrical time constant is τ = {tau:.3e} s at z = {z:e} m (φ = 0), and the \
         forward-Euler flux step [JA 84c] diverges once T_s > 2τ; sample at least every \
         τ/5 = {:.3e} s for an accurate step, or set observer.kalman.flux_step = \
         \"exponential\" (stable at any T_s)",
        tau / 5.0
    )]
    SampleTooLong {
        sample_period: f64,
        tau: f64,
        z: f64,
    },
}

impl KalmanSettings {
    /// The settings of the description's `[observer]` and
    /// `[observer.kalman]`; `None` without a kalman section.
    pub fn from_observer(o: &Observer) -> Option<KalmanSettings> {
        let k = o.kalman.as_ref()?;
        Some(KalmanSettings {
            sample_period: o.sample_period,
            voltage_noise: o.voltage_noise,
            current_noise: o.current_noise,
            process_z: k.process_z,
            process_phi: k.process_phi,
            process_hc: k.process_hc,
            initial_z_std: k.initial_z_std,
            initial_phi_std: k.initial_phi_std,
            initial_hc_std: k.initial_hc_std,
            ukf_alpha: k.ukf_alpha,
            ukf_beta: k.ukf_beta,
            ukf_kappa: k.ukf_kappa,
            flux_step: k.flux_step,
        })
    }

    /// Checks every value (with or without the H_c state).
    pub fn validate(&self, has_field_state: bool) -> Result<(), KalmanError> {
        let check = |name: &'static str, value: f64, ok: bool, expected: &'static str| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(KalmanError::BadSetting {
                    name,
                    value,
                    expected,
                })
            }
        };
        let positive = |name, v: f64| check(name, v, v > 0.0, "a finite number > 0");
        positive("sample_period", self.sample_period)?;
        positive("voltage_noise", self.voltage_noise)?;
        positive("current_noise", self.current_noise)?;
        positive("process_z", self.process_z)?;
        positive("process_phi", self.process_phi)?;
        positive("initial_z_std", self.initial_z_std)?;
        positive("initial_phi_std", self.initial_phi_std)?;
        positive("ukf_alpha", self.ukf_alpha)?;
        check(
            "ukf_beta",
            self.ukf_beta,
            self.ukf_beta >= 0.0,
            "a finite number >= 0",
        )?;
        if let FluxStep::Exponential { substeps } = self.flux_step {
            if !(1..=MAX_FLUX_SUBSTEPS).contains(&substeps) {
                return Err(KalmanError::BadSetting {
                    name: "flux_substeps",
                    value: f64::from(substeps),
                    expected: "an integer in 1..=MAX_FLUX_SUBSTEPS (64)",
                });
            }
        }
        let n = if has_field_state { 4.0 } else { 3.0 };
        check(
            "ukf_kappa",
            self.ukf_kappa,
            n + self.ukf_kappa > 0.0,
            "n + kappa > 0 (n = number of states)",
        )?;
        for (name, v) in [
            ("process_hc", self.process_hc),
            ("initial_hc_std", self.initial_hc_std),
        ] {
            match (has_field_state, v) {
                (true, Some(v)) => positive(name, v)?,
                (true, None) => return Err(KalmanError::MissingFieldSetting(name)),
                (false, Some(_)) => return Err(KalmanError::UnusedFieldSetting(name)),
                (false, None) => {}
            }
        }
        Ok(())
    }

    /// The unscented transform's constants for n states.
    pub fn unscented(&self, n: usize) -> Weights<f64> {
        let n = n as f64;
        let a2 = self.ukf_alpha * self.ukf_alpha;
        let lambda = a2 * (n + self.ukf_kappa) - n;
        let spread = n + lambda;
        let mean0 = lambda / spread;
        Weights {
            gamma: spread.sqrt(),
            mean0,
            cov0: mean0 + (1.0 - a2 + self.ukf_beta),
            other: 0.5 / spread,
        }
    }
}
