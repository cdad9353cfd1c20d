//! Controller design: derivations on top of the model, grouped by concern.
//!
//! - `derive/`: Lie derivatives, relative degree, the feedback-linearizing
//!   chain for y = z (α, β, T, T⁻¹, the jerk terms): what every law and
//!   trajectory builds on;
//! - `trajectory/`: the references (polynomial, energy-optimal on the
//!   collocation BVP solver), their feasibility [PT 54], [PT 56], [PT 57],
//!   the motion limits, the reference tables;
//! - `law/`: each law's design as plain data: the tracking laws
//!   ([`ControllerDesign`]), the position hold ([`HoldDesign`]), the
//!   switched backstepping and its region ([`BacksteppingDesign`]);
//! - `analysis/`: the sliding-mode law's supply bound [SM 48–52] along a
//!   reference and over a whole design (nominal, Monte Carlo);
//! - `error.rs`: why a description could not be designed ([`PlanError`]);
//! - `plan.rs`: description → [`Design`] (controller and Kalman model), the
//!   pipeline up to code generation; `report.rs`: its report;
//! - `runtime.rs`: a design as the runtime runs it (its `Plan`, `Law`,
//!   `Surface` traits), for the designer's closed loops.
//!
//! The folders' files name one another by module path
//! (`super::derive::linearization::Linearization`), never through the
//! re-exports below, so `tests/tests/tidy.rs` can check that no two of
//! them use each other (directly or through a chain).

mod analysis;
mod derive;
mod error;
mod law;
mod plan;
mod report;
mod runtime;
mod trajectory;

pub use analysis::monte_carlo::{Analysis, Draw, MonteCarlo, Nominal, RobustnessError, Variation};
pub use analysis::robustness::{operation_end, ErrorBounds, Evaluator, Robustness, Sample};
pub use derive::lie::{lie, vanishing_factors, AffineSystem, OutputDerivatives};
pub use derive::linearization::{DesignError, FluxSquared, Linearization};
pub use error::PlanError;
pub use law::backstepping::derivation::{
    Backstepping, BacksteppingError, SYMBOLS as BACKSTEPPING_SYMBOLS,
};
pub use law::backstepping::design::{design_backstepping, BacksteppingDesign};
pub use law::backstepping::lmi::{eigenvalues, Lmi2, Sdp2, SdpOutcome, Sym2};
pub use law::backstepping::region::{
    decay_limit, design_region, level, quadratic, Level, Region, RegionError, Target, REST_MARGIN,
};
pub use law::decisions::{
    gains, model_sliding_gains, triple_pole_settling_product, ControllerDesign, ControllerSpec,
    DesignedOperation, LawDesign,
};
pub use law::hold::{design_hold, HoldDesign};
pub(crate) use plan::lowest_input;
pub use plan::{design_controller, design_kalman, design_reference, Design, SharedReference};
pub use runtime::{
    runtime_switching, RuntimeBackstepping, RuntimeController, RuntimeHold, RuntimePlan,
};
pub use trajectory::approach::Approached;
pub use trajectory::bvp::{
    jacobian_discrepancy, solve_bvp, solve_collocation, BvpError, BvpOptions, BvpProblem,
    BvpSolution,
};
pub use trajectory::feasibility::{check as check_feasibility, Condition, Feasibility};
pub use trajectory::fit_segments::{
    fit_segments, knot_jumps, table_errors, FitError, SegmentFit, SegmentTolerance, Signal,
    Signals, TableErrors, ACCEPT,
};
pub use trajectory::limits::{motion_limits, CostPoint, MotionLimits};
pub use trajectory::optimal::problem::{
    CostateGuess, HamiltonianSystem, OptimalError, OptimalSpec,
};
pub use trajectory::optimal::robust::{
    contact_figures, ContactDesign, ContactFigures, CONTACT_WEIGHT,
};
pub use trajectory::optimal::{energy_optimal, OptimalTrajectory, Switch};
pub use trajectory::reference::{Flat, Polynomial, Reference};
pub use trajectory::segments::{Segment, Segments};
pub use trajectory::takeoff::{Shortest, Takeoff, Verdict};
