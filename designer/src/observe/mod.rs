//! Observers: estimates of what the sensorless controller needs (z, v, a, φ,
//! the mode) from the coil voltage and current alone.
//!
//! | file | concept |
//! | --- | --- |
//! | `semera.rs` | SEMERA: model-free Kalman estimation of r, l, λ ([SE Alg. 1]) |
//! | `integral.rs` | the integral estimator with resistance update ([SE Alg. 2], [SE 47]) |
//! | `observability.rs` | the observability determinant [SE 32] over a recorded current |
//! | `discrete/` | the discretised model of jiles-atherton-actuator-model [JA 84–87], its settings and tapes, the tape-backed model of the runtime's filters, the estimate |
//! | `filter.rs` | a runtime filter at the model's number of states, with the designer's estimate |
//! | `ekf.rs` | the reference extended Kalman filter: the runtime's EKF on the tapes |
//! | `ukf.rs` | the reference unscented Kalman filter: the runtime's UKF on the tapes |

pub mod discrete;
pub mod ekf;
pub mod filter;
pub mod integral;
pub mod observability;
pub mod semera;
pub mod ukf;
