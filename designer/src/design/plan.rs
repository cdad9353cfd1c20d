//! From a description to a complete design, ready to emit: the pipeline
//! behind `reldesign build`, the `build.rs` call and the `design!` macro up
//! to (not including) code generation.
//!
//! description → model → feedback linearization (α, β, T, T⁻¹) → per
//! operation a reference (polynomial or energy-optimal) → feasibility [PT 54],
//! [PT 56], [PT 57] → reference table → (sliding mode: u_max > max u* [SM 48])
//! → the decisions of `law/decisions.rs`; and the
//! discretised model [JA 84–87] of the EKF/UKF. An infeasible design is an
//! error that says which condition fails, where, and what to try.

use crate::description::{
    Description, Drive, Estimator, Law, Operation, Shape, SlidingSurface, Trajectory,
};
use crate::model::Model;
use crate::observe::discrete::{DiscreteModel, KalmanSettings, ResistanceSettings};

use super::analysis::robustness::{operation_end, ErrorBounds, Evaluator};
use super::derive::linearization::Linearization;
use super::error::PlanError;
use super::law::backstepping::design::{design_backstepping, BacksteppingDesign};
use super::law::decisions::{
    gains, ControllerDesign, ControllerSpec, DesignedOperation, LawDesign,
};
use super::law::hold::{design_hold, HoldDesign};
use super::trajectory::approach::Approached;
use super::trajectory::feasibility::check as check_feasibility;
use super::trajectory::fit_segments::{fit_segments, SegmentTolerance};
use super::trajectory::optimal::problem::{OptimalError, OptimalSpec};
use super::trajectory::optimal::{energy_optimal, OptimalTrajectory};
use super::trajectory::reference::{Polynomial, Reference};
use super::trajectory::takeoff::{shortest_takeoff, Shortest, Takeoff, Verdict};

/// Instants of the sliding-mode supply check per operation.
const ROBUSTNESS_SAMPLES: usize = 4000;

/// A complete design, ready to emit: the controller and/or the observers.
pub struct Design {
    pub description: Description,
    pub model: Model,
    /// From `[trajectory]` + `[controller]`.
    pub controller: Option<ControllerDesign>,
    /// From `[controller]` with law "model-sliding-mode" and `position`.
    pub hold: Option<HoldDesign>,
    /// From `[controller]` with law "backstepping".
    pub backstepping: Option<BacksteppingDesign>,
    /// The EKF/UKF discretised model, from `[observer]` with "ekf" or "ukf".
    pub kalman: Option<DiscreteModel>,
}

impl Design {
    /// Designs everything the description's `[trajectory]`, `[controller]`
    /// and `[observer]` ask for.
    pub fn new(description: &Description) -> Result<Design, PlanError> {
        let mut model = Model::build(description);
        let held = description.controller.as_ref().and_then(|c| match c.law {
            Law::ModelSlidingMode(s) => s.position.map(|z| (s, z)),
            _ => None,
        });
        let mut backstepping = None;
        let (controller, hold) = match (&description.trajectory, &description.controller, held) {
            (None, Some(c), _) if matches!(c.law, Law::Backstepping(_)) => {
                if let Law::Backstepping(keys) = c.law {
                    backstepping = Some(design_backstepping(description, &mut model, &keys)?);
                }
                (None, None)
            }
            (None, Some(_), Some((surface, z))) => (
                None,
                Some(design_hold(description, &mut model, &surface, z)?),
            ),
            (Some(_), Some(_), _) => (Some(design_controller(description, &mut model)?), None),
            (None, None, _) => (None, None),
            _ => return Err(PlanError::TrajectoryWithoutController),
        };
        let kalman = design_kalman(description, &model)?;
        let designed = controller.is_some() || hold.is_some() || backstepping.is_some();
        if !designed && description.observer.is_none() {
            return Err(PlanError::NothingToBuild);
        }
        Ok(Design {
            description: description.clone(),
            model,
            controller,
            hold,
            backstepping,
            kalman,
        })
    }
}

/// `[trajectory]` + `[controller]`: linearization, references, feasibility,
/// tables, decisions.
pub fn design_controller(
    description: &Description,
    model: &mut Model,
) -> Result<ControllerDesign, PlanError> {
    let (Some(trajectory), Some(controller)) = (&description.trajectory, &description.controller)
    else {
        return Err(PlanError::NothingToBuild);
    };
    let linearization = Linearization::derive(model)?;
    let mut operations = Vec::new();
    for &operation in &trajectory.operations {
        operations.push(design_operation(
            description,
            model,
            &linearization,
            operation,
        )?);
    }
    let law = match controller.law {
        Law::FeedbackLinearization(g) => LawDesign::FeedbackLinearization { gains: gains(&g) },
        Law::SlidingMode(surface) => {
            check_sliding_supply(model, &linearization, &operations, &surface, trajectory)?;
            LawDesign::SlidingMode {
                lambda1: surface.lambda1,
                lambda2: surface.lambda2,
                nonnegative_current: surface.nonnegative_current,
            }
        }
        Law::ModelSlidingMode(s) => LawDesign::ModelSlidingMode { p: s.p, k: s.k },
        // holds positions, not a [trajectory] (the description refuses both)
        Law::Backstepping(_) => return Err(PlanError::NothingToBuild),
    };
    let spec = ControllerSpec {
        law,
        sample_period: controller.sample_period,
        u_min: lowest_input(description),
        u_max: description.supply.u_max,
        takeoff: trajectory.takeoff,
        landing: trajectory.landing,
        // after t_f the creep goes on at the approach's speed, unless set
        creep_speed: (controller.creep_speed).or(trajectory.approach().map(|a| a.speed)),
        landed_band: controller.landed_band,
        estimated: controller.estimator.is_some(),
    };
    ControllerDesign::decide(model, linearization, &spec, operations)
}

/// The controller's lowest input: the supply's, or 0 for the model-based
/// sliding mode, which saturates to [0, u_max] [JA 94].
pub(crate) fn lowest_input(description: &Description) -> f64 {
    match description.controller.as_ref().map(|c| c.law) {
        Some(Law::ModelSlidingMode(_)) => description.supply.u_min.max(0.0),
        _ => description.supply.u_min,
    }
}

/// A reference of `[trajectory]`, shareable across threads.
pub type SharedReference = Box<dyn Reference + Send + Sync>;

/// The reference of `operation` as `[trajectory]` asks (polynomial or
/// energy-optimal), not checked for feasibility; the energy-optimal solution
/// too, where that is the shape.
pub fn design_reference(
    description: &Description,
    model: &mut Model,
    linearization: &Linearization,
    operation: Operation,
) -> Result<(SharedReference, Option<OptimalTrajectory>), PlanError> {
    let Some(trajectory) = &description.trajectory else {
        return Err(PlanError::NothingToBuild);
    };
    let (bounds, polynomial) = design_bounds(description, trajectory, operation);
    // with a standoff, the move ends short of the stop, and the approach follows
    let approach = trajectory.approach();
    let move_to = approach.map_or(polynomial, |a| {
        let (zf, tf) = a.move_end(polynomial.z0, polynomial.zf, polynomial.tf);
        Polynomial {
            zf,
            tf,
            ..polynomial
        }
    });
    let (moving, optimal) = design_move(
        description,
        trajectory,
        model,
        linearization,
        operation,
        bounds,
        move_to,
    )?;
    let Some(approach) = approach else {
        return Ok((moving, optimal));
    };
    let approached = Approached {
        moving,
        approach,
        stop: polynomial.zf,
        landing: polynomial.tf,
    };
    Ok((Box::new(approached), optimal))
}

/// The move of `polynomial`'s ends and times in `[trajectory]`'s shape.
fn design_move(
    description: &Description,
    trajectory: &Trajectory,
    model: &mut Model,
    linearization: &Linearization,
    operation: Operation,
    bounds: (f64, f64),
    polynomial: Polynomial,
) -> Result<(SharedReference, Option<OptimalTrajectory>), PlanError> {
    match trajectory.shape {
        Shape::Polynomial => Ok((Box::new(polynomial), None)),
        Shape::EnergyOptimal => {
            let spec = OptimalSpec {
                u_max_limit: description.supply.u_max,
                contact_uncertainty: trajectory.contact_uncertainty,
                ..OptimalSpec::new(
                    polynomial.z0,
                    polynomial.zf,
                    polynomial.t0,
                    polynomial.tf,
                    bounds.0,
                    bounds.1,
                )
            };
            let solution =
                energy_optimal(model, linearization, &spec).map_err(|e| PlanError::Optimal {
                    operation: operation.name(),
                    message: optimal_message(&e, description),
                })?;
            Ok((Box::new(solution.clone()), Some(solution)))
        }
    }
}

/// The input bounds the reference is designed within, and the polynomial
/// reference of `operation` (the shape's fallback and remedy).
fn design_bounds(
    description: &Description,
    trajectory: &Trajectory,
    operation: Operation,
) -> ((f64, f64), Polynomial) {
    let mech = &description.mechanics;
    let bounds = (
        lowest_input(description).max(-trajectory.u_bound),
        trajectory.u_bound,
    );
    let (z0, zf) = match operation {
        Operation::Closing => (mech.z_max, mech.z_min),
        Operation::Opening => (mech.z_min, mech.z_max),
    };
    let polynomial = Polynomial {
        z0,
        zf,
        t0: trajectory.takeoff,
        tf: trajectory.landing,
    };
    (bounds, polynomial)
}

/// One operation of `[trajectory]`: its reference (polynomial or
/// energy-optimal), feasibility, takeoff and table.
fn design_operation(
    description: &Description,
    model: &mut Model,
    linearization: &Linearization,
    operation: Operation,
) -> Result<DesignedOperation, PlanError> {
    let Some(trajectory) = &description.trajectory else {
        return Err(PlanError::NothingToBuild);
    };
    let name = operation.name();
    let (bounds, polynomial) = design_bounds(description, trajectory, operation);
    let (z0, zf) = (polynomial.z0, polynomial.zf);
    let supply = supply_takeoff(description, model, operation, trajectory)?;
    let (reference, optimal) = design_reference(description, model, linearization, operation)?;
    let feasibility = check_feasibility(model, linearization, reference.as_ref(), bounds, 4000);
    if !feasibility.is_feasible() {
        let mut report = feasibility.report();
        if optimal.is_none() {
            report.push_str(&polynomial_remedy(
                model,
                linearization,
                &polynomial,
                bounds,
            ));
        }
        return Err(PlanError::Infeasible {
            operation: name,
            report,
        });
    }
    let planned = optimal
        .as_ref()
        .map_or(trajectory.takeoff, |o| o.arc.0.max(trajectory.takeoff));
    let takeoff = check_takeoff(operation, supply, reference.as_ref(), planned)?;
    let mut breaks: Vec<f64> = optimal.iter().flat_map(|o| o.breaks()).collect();
    if let Some(approach) = trajectory.approach() {
        breaks.extend(approach.knots(trajectory.landing));
    }
    let fit =
        fit_segments(reference.as_ref(), &breaks, &SegmentTolerance::default()).map_err(|e| {
            PlanError::Table {
                operation: name,
                message: e.to_string(),
            }
        })?;
    Ok(DesignedOperation {
        operation,
        z0,
        zf,
        feasibility,
        table: fit.table,
        optimal,
        takeoff: Some(takeoff),
    })
}

/// The sliding-mode law's necessary condition u_max > max u* [SM 48] along
/// each designed reference (the tables the emitted code tracks).
fn check_sliding_supply(
    model: &Model,
    lin: &Linearization,
    operations: &[DesignedOperation],
    surface: &SlidingSurface,
    trajectory: &Trajectory,
) -> Result<(), PlanError> {
    let evaluator = Evaluator::new(model, lin);
    let params = evaluator.values(model).map_err(PlanError::UnboundSymbol)?;
    let u_max = model.description.supply.u_max;
    let t_end = operation_end(trajectory.takeoff, trajectory.landing);
    for op in operations {
        let r = evaluator.analyse(
            &op.table,
            t_end,
            ROBUSTNESS_SAMPLES,
            surface,
            &ErrorBounds::default(),
            &params,
        );
        // (the negative side, u_min below the reference's inputs, is the
        // feasibility check [PT 54] the reference already passed)
        if r.feasible && u_max > r.max_u_star {
            continue;
        }
        let hint = match trajectory.shape {
            Shape::EnergyOptimal => format!(
                "; the energy-optimal reference uses inputs up to trajectory.u_bound = {}: \
                 a smaller u_bound leaves the switching law a margin",
                trajectory.u_bound
            ),
            Shape::Polynomial => String::new(),
        };
        return Err(PlanError::SlidingSupply {
            operation: op.operation.name(),
            max_u_star: r.max_u_star,
            at: r.max_u_star_t,
            u_max,
            hint,
        });
    }
    Ok(())
}

/// `[observer.kalman]` → the discretised model [JA 84–87] of the EKF/UKF.
pub fn design_kalman(
    description: &Description,
    model: &Model,
) -> Result<Option<DiscreteModel>, PlanError> {
    let Some(o) = &description.observer else {
        return Ok(None);
    };
    let wanted = o
        .estimators
        .iter()
        .any(|e| matches!(e, Estimator::Ekf | Estimator::Ukf));
    let (true, Some(settings)) = (wanted, KalmanSettings::from_observer(o)) else {
        return Ok(None);
    };
    DiscreteModel::with_resistance(model, &settings, ResistanceSettings::from_observer(o))
        .map(Some)
        .map_err(|e| PlanError::Observer {
            estimator: "ekf/ukf",
            message: e.to_string(),
        })
}

/// What makes an infeasible polynomial feasible: the motion time it needs
/// (bisected to 0.5 % on the feasibility check), or that no time up to ×16 does.
fn polynomial_remedy(
    model: &mut Model,
    lin: &Linearization,
    polynomial: &Polynomial,
    bounds: (f64, f64),
) -> String {
    let duration = polynomial.tf - polynomial.t0;
    let mut feasible = |d: f64| {
        let p = Polynomial {
            tf: polynomial.t0 + d,
            ..*polynomial
        };
        check_feasibility(model, lin, &p, bounds, 1000).is_feasible()
    };
    let Some(mut hi) = [1.5, 2.5, 4.0, 8.0, 16.0]
        .into_iter()
        .map(|k| k * duration)
        .find(|&d| feasible(d))
    else {
        return "  no polynomial of up to 16× this motion time is feasible within these bounds: \
                see `reldesign limits` for what the device can do\n"
            .to_string();
    };
    let mut lo = duration;
    while hi - lo > 5e-3 * hi {
        let mid = 0.5 * (lo + hi);
        if feasible(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let alternative = if model.has_field_state() {
        "a wider input range (trajectory.u_bound, supply) allows a shorter one"
    } else {
        "shape = \"energy-optimal\" may need less (`reldesign limits` gives its shortest motion)"
    };
    format!(
        "  the polynomial needs trajectory.landing − trajectory.takeoff ≥ {:.4} ms (it is {:.4} ms); \
         {alternative}\n",
        hi * 1e3,
        duration * 1e3
    )
}

/// What an energy-optimal failure means for the description's keys.
fn optimal_message(e: &OptimalError, description: &Description) -> String {
    let unit = match description.supply.drive {
        Drive::Voltage => "V",
        Drive::Current => "A",
    };
    let supply = description.supply.u_max;
    // the move is the motion less the approach of `standoff`
    let approach = (description.trajectory.as_ref())
        .and_then(Trajectory::approach)
        .map_or(0.0, |a| a.duration());
    let move_note = if approach > 0.0 {
        format!(
            " (the move is the motion less the approach to the stop, 5·standoff/(4·approach_speed) = {:.4} ms)",
            approach * 1e3
        )
    } else {
        String::new()
    };
    match e {
        OptimalError::BoundTooLow {
            needed,
            given,
            duration,
            ..
        } => format!(
            "no motion of {:.4} ms keeps the input within trajectory.u_bound = {given:.4} {unit}: \
             it needs trajectory.u_bound ≥ {:.4} {unit} (the supply allows {supply:.4} {unit}), \
             or a longer motion (trajectory.landing − trajectory.takeoff){move_note}",
            duration * 1e3,
            needed * (1.0 + 1e-3),
        ),
        OptimalError::TooShort {
            needed,
            given,
            u_min,
            u_max,
            ..
        } => format!(
            "no motion of {:.4} ms exists with the input in [{u_min:.4}, {u_max:.4}] {unit}{}: \
             it needs trajectory.landing − trajectory.takeoff ≥ {:.4} ms{move_note}",
            given * 1e3,
            if *u_max < supply {
                " (a larger trajectory.u_bound, up to the supply, does not help)"
            } else {
                ""
            },
            (needed * (1.0 + 1e-3) + approach) * 1e3,
        ),
        other => other.to_string(),
    }
}

/// The shortest takeoff the supply allows `operation` (`trajectory/takeoff.rs`)
/// with the key and the input it was driven at; refused already where it is
/// not before t_f (no reference can be followed from a lift-off after its
/// end: the clearly impossible case, whatever the reference).
fn supply_takeoff(
    description: &Description,
    model: &Model,
    operation: Operation,
    trajectory: &Trajectory,
) -> Result<(&'static str, f64, Shortest), PlanError> {
    let (key, input) = match operation {
        Operation::Closing => ("u_max", description.supply.u_max),
        Operation::Opening => ("u_min", lowest_input(description)),
    };
    let timing = (trajectory.takeoff, trajectory.landing);
    let hold_input = description.supply.u_max;
    let shortest = shortest_takeoff(description, model, operation, input, hold_input, timing)
        .map_err(|message| PlanError::Optimal {
            operation: operation.name(),
            message: format!("the shortest takeoff: {message}"),
        })?;
    if shortest.at_least() < trajectory.landing {
        return Ok((key, input, shortest));
    }
    let bound = ErrorBounds::default();
    Err(PlanError::TakeoffTooShort {
        operation: operation.name(),
        key,
        input,
        needed: shortest.text(),
        planned_ms: trajectory.takeoff * 1e3,
        takeoff_ms: trajectory.takeoff * 1e3,
        velocity_error: 100.0,
        acceleration_error: 100.0,
        bound: bound.velocity.max(bound.acceleration) * 1e2,
    })
}

/// `operation`'s pre-movement stage against the shortest the supply allows
/// (`supply`, from [`supply_takeoff`]): `reference` planned to lift off at
/// `planned`; refused, with that time and the key, where the lift-off the
/// supply allows starts the motion with errors beyond the robustness
/// analysis's bounds [SM 52]; a later one within them is reported.
fn check_takeoff(
    operation: Operation,
    (key, input, shortest): (&'static str, f64, Shortest),
    reference: &dyn Reference,
    planned: f64,
) -> Result<Takeoff, PlanError> {
    let bounds = ErrorBounds::default();
    let takeoff = Takeoff::assess(
        key,
        input,
        shortest,
        reference,
        planned,
        (bounds.velocity, bounds.acceleration),
    );
    if takeoff.verdict() != Verdict::TooShort {
        return Ok(takeoff);
    }
    Err(PlanError::TakeoffTooShort {
        operation: operation.name(),
        key,
        input,
        needed: shortest.text(),
        planned_ms: planned * 1e3,
        takeoff_ms: reference.motion().0 * 1e3,
        velocity_error: takeoff.velocity_error * 1e2,
        acceleration_error: takeoff.acceleration_error * 1e2,
        bound: bounds.velocity.max(bounds.acceleration) * 1e2,
    })
}
