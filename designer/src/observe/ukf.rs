//! The unscented Kalman filter on the discretised model [JA 84–87], as in
//! jiles-atherton-actuator-model [JA §6.1]: the f64 reference of the emitted UKF
//! (`reldesign_build::emit_ukf`). It is the runtime's filter
//! (`reldesign_runtime::observe::Ukf`, where the algorithm and its docs
//! live: sigma points, repaired factorisations), the one the emitted code
//! instantiates, on the model's tapes instead of straight-line code.

use reldesign_runtime::observe as rt;

use super::discrete::TapeModel;
use super::filter::Reference;

/// The f64 reference UKF (2N + 1 sigma points).
pub type Ukf = Reference<
    rt::Ukf<TapeModel<3>, f64, 3, 7>,
    rt::Ukf<TapeModel<4>, f64, 4, 9>,
    rt::Ukf<TapeModel<5>, f64, 5, 11>,
>;
