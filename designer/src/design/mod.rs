//! Controller design: derivations on top of the model.
//!
//! - `lie.rs`: input-affine systems, Lie derivatives, relative degree (generic);
//! - `linearization.rs`: exact feedback linearization for y = z: α, β, T, T⁻¹,
//!   the jerk terms;
//! - `reference.rs`: soft-landing position references (polynomial);
//! - `backstepping.rs`: backstepping through the force for y = z
//!   [SB §III]: F_d, Ḟ = f_F + g_F·u, the law u [SB 19];
//! - `lmi.rs`: small SDPs of 2×2 LMIs, as second-order cone programs (generic);
//! - `region.rs`: the backstepping law's certified region [SB lemma 1],
//!   [SB Theorem 3], extended to the spring's rest;
//! - `backstepping_design.rs`: the backstepping controller as plain data,
//!   [`BacksteppingDesign`];
//! - `feasibility.rs`: conditions [PT 54], [PT 56], [PT 57] along a reference;
//! - `bvp.rs` (and `bvp/`): a collocation two-point BVP solver (generic);
//! - `optimal.rs`: the energy-optimal reference (Pontryagin, [PT 58–66]);
//! - `optimal_guess.rs`: rest states and the polynomial initial guess of an arc;
//! - `optimal_search.rs`: rest, move, rest: the optimum within the stroke [PT 57];
//! - `limits.rs`: the shortest motion and J against the motion time (`limits`);
//! - `segments.rs`: a reference as a compact table of polynomial segments;
//! - `decisions.rs`: the controller's design decisions (gains, guard, landed
//!   band, press, creep) as plain data, [`ControllerDesign`];
//! - `hold.rs`: the position hold of the model-based sliding mode [JA §6.2]
//!   as plain data, [`HoldDesign`];
//! - `plan.rs`: description → [`Design`] (controller and Kalman model), the
//!   pipeline up to code generation;
//! - `report.rs`: the design report of `reldesign build`;
//! - `robustness.rs`: the sliding-mode law's supply bound along a reference
//!   [SM 48–52];
//! - `monte_carlo.rs`: that bound for a whole design, nominal and over
//!   parameter bounds;
//! - `runtime.rs`: a design as the runtime runs it (its `Plan`, `Law`,
//!   `Surface` traits), for the designer's closed loops.

mod backstepping;
mod backstepping_design;
mod bvp;
mod decisions;
mod feasibility;
mod fit_segments;
mod hold;
mod lie;
mod limits;
mod linearization;
mod lmi;
mod monte_carlo;
mod optimal;
mod optimal_guess;
mod optimal_search;
mod plan;
mod reference;
mod region;
mod report;
mod robustness;
mod runtime;
mod segments;

pub use backstepping::{Backstepping, BacksteppingError, SYMBOLS as BACKSTEPPING_SYMBOLS};
pub use backstepping_design::{design_backstepping, BacksteppingDesign};
pub use bvp::{
    jacobian_discrepancy, solve_bvp, solve_collocation, BvpError, BvpOptions, BvpProblem,
    BvpSolution,
};
pub use decisions::{
    gains, model_sliding_gains, triple_pole_settling_product, ControllerDesign, ControllerSpec,
    DesignedOperation, LawDesign,
};
pub use feasibility::{check as check_feasibility, Condition, Feasibility};
pub use fit_segments::{
    fit_segments, knot_jumps, table_errors, FitError, SegmentFit, SegmentTolerance, Signal,
    Signals, TableErrors, ACCEPT,
};
pub use hold::{design_hold, HoldDesign};
pub use lie::{lie, vanishing_factors, AffineSystem, OutputDerivatives};
pub use limits::{motion_limits, CostPoint, MotionLimits};
pub use linearization::{DesignError, FluxSquared, Linearization};
pub use lmi::{eigenvalues, Lmi2, Sdp2, SdpOutcome, Sym2};
pub use monte_carlo::{Analysis, Draw, MonteCarlo, Nominal, RobustnessError, Variation};
pub use optimal::{
    energy_optimal, CostateGuess, HamiltonianSystem, OptimalError, OptimalSpec, OptimalTrajectory,
    Switch,
};
pub(crate) use plan::lowest_input;
pub use plan::{
    design_controller, design_kalman, design_reference, Design, PlanError, SharedReference,
};
pub use reference::{Flat, Polynomial, Reference};
pub use region::{
    decay_limit, design_region, level, quadratic, Level, Region, RegionError, Target, REST_MARGIN,
};
pub use robustness::{operation_end, ErrorBounds, Evaluator, Robustness, Sample};
pub use runtime::{
    runtime_switching, RuntimeBackstepping, RuntimeController, RuntimeHold, RuntimePlan,
};
pub use segments::{Segment, Segments};
