//! The path back from data: identification (`reldesign fit`: parameters of
//! a description fitted to a bench recording, jiles-atherton-actuator-model
//! [JA §4–5]), diagnosis (`reldesign diagnose`: what a model gets wrong on
//! measured data, and why) and the TOML editor that writes results back.
//!
//! Its own crate so that what a firmware crate's build script pulls in (the
//! designer and the code generator) stays small: nalgebra, rayon's fits and
//! toml_edit live here.
//!
//! - [`measured`]: the recording (t, v, i and optional z, φ, λ).
//! - [`weighted`]: the |φ̇|-weighted NRMSE [JA 81], its weights and the flux
//!   estimated from the data.
//! - [`params`]: description parameters addressed by TOML key path.
//! - [`lm`]: a bounded Levenberg–Marquardt least-squares solver.
//! - [`edges`]: where inside its sample interval each voltage step fell
//!   (the replays' input).
//! - [`em_fit`]: the fit of [JA 80] by replaying the measured voltage.
//! - [`sensitivity`]: forward parameter sensitivities of a replay (the
//!   fit's analytic Jacobian).
//! - [`staged_fit`]: a fit's starts on the record's first pulses, the
//!   best then on the whole (the diagnosis's ranking; its first pulses are
//!   the polish's first stage too).
//! - [`edge_fit`]: the fit with the voltage edges' instants among its
//!   parameters.
//! - [`identifiability`]: what the data can and cannot separate (SVD of the
//!   scaled Jacobian), and the reduced model's parameters [JA 55], [JA 57], [JA 60].
//! - [`gap_fit`]: the gap model fitted to a reluctance table [JA 75–77].
//! - [`diagnose`]: the diagnosis of a recording against a description.
//! - [`edit`]: physics written back over the original TOML text, comments kept.

// The designer's modules, under the names this crate's files use.
use designer::{description, model, record, replay, sim, sym};

pub mod diagnose;
pub mod edge_fit;
pub mod edges;
pub mod edit;
pub mod em_fit;
pub mod gap_fit;
pub mod identifiability;
pub mod lm;
pub mod measured;
pub use designer::description::params;
pub mod sensitivity;
pub mod staged_fit;
pub mod weighted;

pub use em_fit::{
    current_wnrmse, fit, linearisation, residuals_at, simulate_outputs, FitError, FitOptions,
    FitParam, FitProgress, FitReport, Sensitivities, SimOutputs,
};
pub use identifiability::{reduced_parameters, ReducedParameters, Sensitivity};
pub use measured::Measured;
pub use weighted::{flux_from_data, flux_rate_weights, wnrmse};
