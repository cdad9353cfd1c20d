//! The extended Kalman filter on the discretised model [JA 84–87], with the
//! Jacobians the symbolic core derives (`DiscreteModel::transition_jacobian`,
//! `measurement_jacobian`): the f64 reference of the emitted EKF
//! (`reldesign_build::emit_ekf`). It is the runtime's filter
//! (`reldesign_runtime::observe::Ekf`, where the algorithm and its docs
//! live), the one the emitted code instantiates, on the model's tapes
//! instead of straight-line code.

use reldesign_runtime::observe as rt;

use super::discrete::TapeModel;
use super::filter::Reference;

/// The f64 reference EKF.
pub type Ekf = Reference<
    rt::Ekf<TapeModel<3>, f64, 3>,
    rt::Ekf<TapeModel<4>, f64, 4>,
    rt::Ekf<TapeModel<5>, f64, 5>,
>;
