//! Kalman filters on the discretised model of a single-coil actuator
//! (jiles-atherton-actuator-model [JA §6.1], [JA 84–87]), written once for every
//! model and float type: the extended filter [`Ekf`] and the unscented
//! filter [`Ukf`], generic over the float `T`, the number of states N and the
//! model `M`. Generated code supplies the model (its functions on a
//! zero-sized type, its settings as constants: [`Stateless`]); the designer
//! instantiates the same filters with a tape-backed f64 model as its
//! reference.
//!
//! | file | concept |
//! | --- | --- |
//! | `model.rs` | the model traits and the settings |
//! | `filter.rs` | the posterior, the input, the stop rule, the estimate [JA 85–87] |
//! | `ekf.rs` | the extended Kalman filter (Joseph form) |
//! | `ukf.rs` | the unscented Kalman filter (sigma points, repaired factorisations) |

mod ekf;
mod filter;
mod model;
mod ukf;

pub use ekf::Ekf;
pub use filter::{mode_of, resting_stop, Estimate};
pub use model::{
    Configured, DiscreteModel, Linearisation, Linearised, Prediction, Reading, Sampled, Settings,
    Stateless, Weights,
};
pub use ukf::{Jitter, Ukf};

/// Compile-time checks of a filter's sizes: N states, P sigma points.
struct Sizes<const N: usize, const P: usize>;

impl<const N: usize, const P: usize> Sizes<N, P> {
    /// x = [z, z_prev, φ, …].
    const STATES: () = assert!(N >= 3, "the state is [z, z_prev, φ, …]");
    /// The unscented transform's 2N + 1 points.
    const POINTS: () = assert!(P == 2 * N + 1, "a UKF on N states has 2N + 1 sigma points");
}
