//! Observers: estimates of what the sensorless controller needs (z, v, a, φ,
//! the mode) from the coil voltage and current alone.
//!
//! | file | concept |
//! | --- | --- |
//! | `semera.rs` | SEMERA: model-free Kalman estimation of r, l, λ (semera Algorithm 1) |
//! | `integral.rs` | the integral estimator with resistance update (semera Algorithm 2, (47)) |
//! | `observability.rs` | the observability determinant (32) over a recorded current |
//! | `discrete.rs` | the discretised model of jiles-atherton-actuator-model (84)–(87) |
//! | `filter.rs` | state and steps the EKF and UKF share (input, projection, Q, restart) |
//! | `ekf.rs` | extended Kalman filter on the discretised model (symbolic Jacobians) |
//! | `ukf.rs` | unscented Kalman filter on the discretised model |

pub mod discrete;
pub mod ekf;
mod filter;
pub mod integral;
pub mod observability;
pub mod semera;
pub mod ukf;
