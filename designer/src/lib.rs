//! reldesign's designer: everything between an actuator description and the
//! equations a controller, observer or simulator needs.
//!
//! - [`sym`]: the symbolic core (hash-consed expression DAG, simplification,
//!   differentiation, CSE, flat-tape evaluation). Knows nothing of actuators.
//! - [`design`]: controller design: derivations, trajectories, laws, analyses.
//! - [`design_json`]: the design figures as JSON (`build --report-json`).
//! - [`backstepping_loop`]: the backstepping position controller in a sampled loop (`loop`).
//! - [`closed_loop`]: the designed controller in a sampled loop on a plant (`loop`, `sweep`).
//! - [`description`]: the validated actuator description (`valve.toml`).
//! - [`model`]: the actuator's state-space model, built symbolically.
//! - [`observe`]: observers (SEMERA, integral estimator, EKF, UKF).
//! - [`precision`]: how well a sensorless design knows its armature at each approach.
//! - [`random`]: seeded SplitMix64 draws (Monte Carlo, simulated noise).
//! - [`record`]: recorded signals in the measured-data CSV format.
//! - [`replay`]: an input replayed through the hybrid model (`simulate`).
//! - [`sim`]: the hybrid-automaton simulator (knows nothing of magnetics).

pub mod backstepping_loop;
pub mod bisect;
pub mod calibrate;
pub mod closed_loop;
pub mod description;
pub mod design;
pub mod design_json;
pub mod model;
pub mod observe;
mod parallel;
pub mod precision;
pub mod random;
pub mod record;
pub mod replay;
pub mod sim;
/// The symbolic core, its own crate (`reldesign-sym`): it knows nothing of actuators.
pub use reldesign_sym as sym;
