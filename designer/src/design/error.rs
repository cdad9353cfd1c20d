//! Why a description could not be designed ([`PlanError`]), and the name an
//! operation has in its messages. Below the pipeline (`plan.rs`) and every
//! law's design (`law/`), which all return it: each law states its failures
//! here without reading the pipeline that calls it.

use crate::description::Operation;

use super::derive::linearization::DesignError;
use super::law::backstepping::derivation::BacksteppingError;
use super::law::backstepping::region::RegionError;

/// Why a description could not be designed (the file name is the caller's).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error(
        "nothing to build: add [trajectory] and [controller] sections, or an [observer] section (see the README)"
    )]
    NothingToBuild,
    /// (`[controller]` without `[trajectory]` is refused by the parser.)
    #[error("[trajectory] alone builds nothing: add a [controller] section to track it (see the README)")]
    TrajectoryWithoutController,
    #[error("the {estimator} observer: {message}")]
    Observer {
        estimator: &'static str,
        message: String,
    },
    #[error("{0}")]
    Design(#[from] DesignError),
    #[error(
        "the {operation} reference is infeasible (perfect-tracking-soft-landing §4):\n{report}"
    )]
    Infeasible {
        operation: &'static str,
        report: String,
    },
    #[error("the {operation} energy-optimal trajectory: {message}")]
    Optimal {
        operation: &'static str,
        message: String,
    },
    #[error("the {operation} reference table: {message}")]
    Table {
        operation: &'static str,
        message: String,
    },
    #[error(
        "the {operation} pre-movement stage is too short: driven at the supply's limit \
         (supply.{key} = {input}) from its rest, the model's armature leaves its stop only \
         {needed}, but the reference starts to move at {planned_ms:.4} ms \
         (trajectory.takeoff = {takeoff_ms:.4} ms), so the motion would start with errors of \
         {velocity_error:.1} % of max|v_r| and {acceleration_error:.1} % of max|a_r|, beyond \
         the {bound:.0} % the design assumes [SM 52]; set trajectory.takeoff to at least that \
         (and trajectory.landing with it, to keep the motion time), or raise |supply.{key}|"
    )]
    TakeoffTooShort {
        operation: &'static str,
        key: &'static str,
        input: f64,
        needed: String,
        planned_ms: f64,
        takeoff_ms: f64,
        velocity_error: f64,
        acceleration_error: f64,
        bound: f64,
    },
    #[error("the controller has no operation")]
    NoOperation,
    #[error("the {0:?} operation is given twice")]
    DuplicateOperation(Operation),
    #[error("the reference table of the {0:?} operation is empty")]
    EmptyTable(Operation),
    #[error("the reference table of the {operation:?} operation spans [{first}, {end}] s, not the motion [t0, tf] = [{takeoff}, {landing}] s")]
    TableTiming {
        operation: Operation,
        first: f64,
        end: f64,
        takeoff: f64,
        landing: f64,
    },
    #[error("the design value `{name}` = {value} is not finite or out of range")]
    BadValue { name: String, value: f64 },
    #[error("the reference never needs a positive, finite flux: no guard threshold for φ → 0 can be derived")]
    NoFluxFloor,
    #[error(
        "the sliding-mode law cannot track the {operation} reference: it needs \
         u_max > max u* = {max_u_star:.4} (model-free-sliding-mode (48), worst at t = {:.4} ms \
         from the operation's start), but supply.u_max = {u_max}; give a longer motion \
         (trajectory.landing − trajectory.takeoff) or a larger supply.u_max{hint}; see \
         `reldesign robustness` for the sufficient bound (49)",
        at * 1e3
    )]
    SlidingSupply {
        operation: &'static str,
        max_u_star: f64,
        at: f64,
        u_max: f64,
        hint: String,
    },
    #[error(
        "controller.position = {position:e} m cannot be held: at rest there the flux would \
         need φ² = {flux_squared:e} Wb² (must be > 0: the magnet only attracts, so the spring \
         must push away from z_min there); choose a position where the spring pushes the \
         armature open"
    )]
    Unholdable { position: f64, flux_squared: f64 },
    #[error(
        "controller.position = {position:e} m needs a steady input of {input:.4} to hold \
         (R·i, or i with current drive, of the flux that balances the spring there), but \
         supply.u_max = {u_max}: \
         choose a position nearer z_max or a larger supply.u_max"
    )]
    HoldingInput {
        position: f64,
        input: f64,
        u_max: f64,
    },
    #[error("internal error: the symbol `{0}` of the linearization is unbound")]
    UnboundSymbol(String),
    #[error("the backstepping law's region: {0}")]
    Region(RegionError),
    #[error("the backstepping law: {0}")]
    Backstepping(BacksteppingError),
}

impl Operation {
    /// `closing` or `opening`, as reports and the description name it.
    pub fn name(self) -> &'static str {
        match self {
            Operation::Closing => "closing",
            Operation::Opening => "opening",
        }
    }
}

impl From<RegionError> for PlanError {
    fn from(e: RegionError) -> Self {
        PlanError::Region(e)
    }
}

impl From<BacksteppingError> for PlanError {
    fn from(e: BacksteppingError) -> Self {
        PlanError::Backstepping(e)
    }
}
