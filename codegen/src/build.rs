//! From a description file to the emitted controller module: the pipeline
//! behind `reldesign build`, the `build.rs` call and the `design!` macro.
//!
//! description → model → feedback linearization (α, β, T, T⁻¹) → per
//! operation a reference (polynomial or energy-optimal) → feasibility (54),
//! (56), (57) → reference table → emitted Rust. An infeasible design is an
//! error that says which condition fails, where, and what to try.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use designer::description::{parse_file, Description, Estimator, FloatType, Operation, Shape};
use designer::design::{
    check_feasibility, energy_optimal, fit_segments, DesignError, Feasibility, Linearization,
    OptimalError, OptimalSpec, OptimalTrajectory, Polynomial, Reference, SegmentTolerance,
    Segments,
};
use designer::model::Model;
use designer::observe::discrete::{DiscreteModel, KalmanSettings, ResistanceSettings};

use crate::controller::{emit_controller, gains, ControllerError, ControllerInput, OperationTable};
use crate::header::Header;
use crate::observer::{emit_ekf, emit_ukf, wrap_module, ObserverError, ObserverInput};
use crate::semera::{emit_semera, SemeraError, SemeraInput};
use crate::Float;

/// Why a description could not be built into code.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error("{0}")]
    Description(#[from] designer::description::DescriptionError),
    #[error(
        "{file}: nothing to build: add [trajectory] and [controller] sections, or an [observer] section (see the README)"
    )]
    NothingToBuild { file: String },
    /// (`[controller]` without `[trajectory]` is refused by the parser.)
    #[error("{file}: [trajectory] alone builds nothing: add a [controller] section to track it (see the README)")]
    TrajectoryWithoutController { file: String },
    #[error("{file}: the {estimator} observer: {message}")]
    Observer {
        file: String,
        estimator: &'static str,
        message: String,
    },
    #[error("{file}: {source}")]
    Design { file: String, source: DesignError },
    #[error("{file}: the {operation} reference is infeasible (perfect-tracking-soft-landing §4):\n{report}")]
    Infeasible {
        file: String,
        operation: &'static str,
        report: String,
    },
    #[error("{file}: the {operation} energy-optimal trajectory: {message}")]
    Optimal {
        file: String,
        operation: &'static str,
        message: String,
    },
    #[error("{file}: the {operation} reference table: {message}")]
    Table {
        file: String,
        operation: &'static str,
        message: String,
    },
    #[error("{file}: code generation: {source}")]
    Emit {
        file: String,
        source: ControllerError,
    },
    #[error("{0}")]
    Io(String),
}

/// One designed operation: its reference, feasibility and table.
pub struct DesignedOperation {
    pub operation: Operation,
    pub z0: f64,
    pub zf: f64,
    pub feasibility: Feasibility,
    pub table: Segments,
    /// The energy-optimal solution when the shape is `energy-optimal`.
    pub optimal: Option<OptimalTrajectory>,
}

/// A complete design, ready to emit: the controller and/or the observers.
pub struct Design {
    pub description: Description,
    pub model: Model,
    /// From `[trajectory]` + `[controller]`.
    pub controller: Option<ControllerDesign>,
    /// The EKF/UKF discretised model, from `[observer]` with "ekf" or "ukf".
    pub kalman: Option<DiscreteModel>,
}

/// The designed feedback-linearizing controller.
pub struct ControllerDesign {
    pub linearization: Linearization,
    pub gains: [f64; 3],
    pub operations: Vec<DesignedOperation>,
}

pub fn operation_name(op: Operation) -> &'static str {
    match op {
        Operation::Closing => "closing",
        Operation::Opening => "opening",
    }
}

impl Design {
    /// Designs everything the description's `[trajectory]`, `[controller]`
    /// and `[observer]` ask for.
    pub fn new(description: &Description) -> Result<Design, BuildError> {
        let file = description.source.file_name.clone();
        let mut model = Model::build(description);
        let controller = match (&description.trajectory, &description.controller) {
            (Some(_), Some(_)) => Some(design_controller(description, &mut model)?),
            (None, None) => None,
            _ => return Err(BuildError::TrajectoryWithoutController { file }),
        };
        let kalman = design_kalman(description, &model)?;
        if controller.is_none() && description.observer.is_none() {
            return Err(BuildError::NothingToBuild { file });
        }
        Ok(Design {
            description: description.clone(),
            model,
            controller,
            kalman,
        })
    }
}

/// `[trajectory]` + `[controller]`: linearization, references, feasibility, tables.
fn design_controller(
    description: &Description,
    model: &mut Model,
) -> Result<ControllerDesign, BuildError> {
    let file = description.source.file_name.clone();
    let (Some(trajectory), Some(controller)) = (&description.trajectory, &description.controller)
    else {
        return Err(BuildError::NothingToBuild { file });
    };
    let linearization = Linearization::derive(model).map_err(|source| BuildError::Design {
        file: file.clone(),
        source,
    })?;
    let mech = &description.mechanics;
    let bounds = (
        description.supply.u_min.max(-trajectory.u_bound),
        trajectory.u_bound,
    );
    let mut operations = Vec::new();
    for &operation in &trajectory.operations {
        let (z0, zf) = match operation {
            Operation::Closing => (mech.z_max, mech.z_min),
            Operation::Opening => (mech.z_min, mech.z_max),
        };
        let name = operation_name(operation);
        let polynomial = Polynomial {
            z0,
            zf,
            t0: trajectory.takeoff,
            tf: trajectory.landing,
        };
        let (reference, optimal): (Box<dyn Reference>, Option<OptimalTrajectory>) =
            match trajectory.shape {
                Shape::Polynomial => (Box::new(polynomial), None),
                Shape::EnergyOptimal => {
                    let spec = OptimalSpec {
                        u_max_limit: description.supply.u_max,
                        ..OptimalSpec::new(
                            z0,
                            zf,
                            trajectory.takeoff,
                            trajectory.landing,
                            bounds.0,
                            bounds.1,
                        )
                    };
                    let solution = energy_optimal(model, &linearization, &spec).map_err(|e| {
                        BuildError::Optimal {
                            file: file.clone(),
                            operation: name,
                            message: optimal_message(&e, description),
                        }
                    })?;
                    (Box::new(solution.clone()), Some(solution))
                }
            };
        let feasibility =
            check_feasibility(model, &linearization, reference.as_ref(), bounds, 4000);
        if !feasibility.is_feasible() {
            let mut report = feasibility.report();
            if optimal.is_none() {
                report.push_str(&polynomial_remedy(
                    model,
                    &linearization,
                    &polynomial,
                    bounds,
                ));
            }
            return Err(BuildError::Infeasible {
                file,
                operation: name,
                report,
            });
        }
        let breaks: Vec<f64> = optimal.iter().flat_map(|o| o.breaks()).collect();
        let fit = fit_segments(reference.as_ref(), &breaks, &SegmentTolerance::default()).map_err(
            |e| BuildError::Table {
                file: file.clone(),
                operation: name,
                message: e.to_string(),
            },
        )?;
        operations.push(DesignedOperation {
            operation,
            z0,
            zf,
            feasibility,
            table: fit.table,
            optimal,
        });
    }
    Ok(ControllerDesign {
        gains: gains(&controller.gains),
        linearization,
        operations,
    })
}

/// `[observer.kalman]` → the discretised model (84)–(87) of the EKF/UKF.
fn design_kalman(
    description: &Description,
    model: &Model,
) -> Result<Option<DiscreteModel>, BuildError> {
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
        .map_err(|e| BuildError::Observer {
            file: description.source.file_name.clone(),
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
    format!(
        "  the polynomial needs trajectory.landing − trajectory.takeoff ≥ {:.4} ms (it is {:.4} ms); \
         shape = \"energy-optimal\" may need less (`reldesign limits` gives its shortest motion)\n",
        hi * 1e3,
        duration * 1e3
    )
}

/// What an energy-optimal failure means for the description's keys.
fn optimal_message(e: &OptimalError, description: &Description) -> String {
    let unit = match description.supply.drive {
        designer::description::Drive::Voltage => "V",
        designer::description::Drive::Current => "A",
    };
    let supply = description.supply.u_max;
    match e {
        OptimalError::BoundTooLow {
            needed,
            given,
            duration,
            ..
        } => format!(
            "no motion of {:.4} ms keeps the input within trajectory.u_bound = {given:.4} {unit}: \
             it needs trajectory.u_bound ≥ {:.4} {unit} (the supply allows {supply:.4} {unit}), \
             or a longer motion (trajectory.landing − trajectory.takeoff)",
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
             it needs trajectory.landing − trajectory.takeoff ≥ {:.4} ms",
            given * 1e3,
            if *u_max < supply {
                " (a larger trajectory.u_bound, up to the supply, does not help)"
            } else {
                ""
            },
            needed * (1.0 + 1e-3) * 1e3,
        ),
        other => other.to_string(),
    }
}

/// Where the energy-optimal motion is shorter than [t₀, t_f]: when it moves,
/// where it rests, and why.
fn rest_text(opt: &OptimalTrajectory) -> Option<String> {
    let (t0, tf) = (opt.spec.t0, opt.spec.tf);
    let (ta, tb) = opt.arc;
    if ta <= t0 && tb >= tf {
        return None;
    }
    let (place, u) = if tb < tf {
        (
            format!("lands at {:.4} ms and rests", tb * 1e3),
            opt.rest_inputs[1],
        )
    } else {
        (
            format!("rests until {:.4} ms, then moves", ta * 1e3),
            opt.rest_inputs[0],
        )
    };
    Some(format!(
        "the motion {place} (holding input {u:.4}): it lasts {:.4} ms, and any longer interval \
         is spent at rest, which costs less than moving slower ({:.6e} of J)",
        (tb - ta) * 1e3,
        opt.rest_cost,
    ))
}

impl Design {
    /// The emitted module (deterministic bytes): the controller (if any),
    /// then `pub mod estimators` (SEMERA, integral), `pub mod ekf`, `pub mod ukf`.
    pub fn emit(&self) -> Result<String, BuildError> {
        let d = &self.description;
        let mut out = match &self.controller {
            Some(c) => self.emit_controller(c)?,
            None => self.header(),
        };
        let file = || d.source.file_name.clone();
        let floats = d
            .observer
            .as_ref()
            .map(|o| floats(&o.floats))
            .unwrap_or_default();
        if let Some(input) = SemeraInput::from_description(d) {
            let items = emit_semera(&input).map_err(|e: SemeraError| BuildError::Observer {
                file: file(),
                estimator: "semera/integral",
                message: e.to_string(),
            })?;
            out.push('\n');
            out.push_str(&wrap_module(
                "estimators",
                "The model-free electrical estimators (semera-electromagnetic-estimation):\nSEMERA (Algorithm 1) and the integral estimator (Algorithm 2).",
                &items,
            ));
        }
        if let (Some(discrete), Some(o)) = (&self.kalman, &d.observer) {
            let input = ObserverInput {
                name: &d.name,
                discrete,
                floats,
            };
            type Emitter = fn(&ObserverInput) -> Result<String, ObserverError>;
            let kinds: [(Estimator, &str, &str, Emitter); 2] = [
                (Estimator::Ekf, "ekf", "The extended Kalman filter on the discretised model (jiles-atherton-actuator-model (84)–(87)).", emit_ekf),
                (Estimator::Ukf, "ukf", "The unscented Kalman filter on the discretised model (jiles-atherton-actuator-model (84)–(87)).", emit_ukf),
            ];
            for (kind, name, doc, emit) in kinds {
                if !o.estimators.contains(&kind) {
                    continue;
                }
                let items = emit(&input).map_err(|e| BuildError::Observer {
                    file: file(),
                    estimator: name,
                    message: e.to_string(),
                })?;
                out.push('\n');
                out.push_str(&wrap_module(name, doc, &items));
            }
        }
        Ok(out)
    }

    /// The file header when there is no controller (which writes its own).
    fn header(&self) -> String {
        let d = &self.description;
        Header {
            what: &format!("observers of `{}`", d.name),
            generator_version: env!("CARGO_PKG_VERSION"),
            source_file: file_label(&d.source.file_name),
            source_text: &d.source.text,
        }
        .text()
    }

    fn emit_controller(&self, c: &ControllerDesign) -> Result<String, BuildError> {
        let d = &self.description;
        let (Some(trajectory), Some(controller)) = (&d.trajectory, &d.controller) else {
            return Err(BuildError::NothingToBuild {
                file: d.source.file_name.clone(),
            });
        };
        let input = ControllerInput {
            name: &d.name,
            graph: &self.model.graph,
            params: self.model.params.iter().map(crate::Param::from).collect(),
            states: [
                self.model.states[0],
                self.model.states[1],
                self.model.states[2],
            ],
            linearization: &c.linearization,
            gains: c.gains,
            sample_period: controller.sample_period,
            u_min: d.supply.u_min,
            u_max: d.supply.u_max,
            takeoff: trajectory.takeoff,
            landing: trajectory.landing,
            creep_speed: controller.creep_speed,
            operations: c
                .operations
                .iter()
                .map(|o| OperationTable {
                    operation: o.operation,
                    z0: o.z0,
                    zf: o.zf,
                    segments: &o.table,
                })
                .collect(),
            floats: floats(&controller.floats),
            source_file: file_label(&d.source.file_name),
            source_text: &d.source.text,
            generator_version: env!("CARGO_PKG_VERSION"),
        };
        emit_controller(&input).map_err(|source| BuildError::Emit {
            file: d.source.file_name.clone(),
            source,
        })
    }

    /// A human-readable design report (what `reldesign build` prints).
    pub fn report(&self) -> String {
        let mut s = String::new();
        if let Some(c) = &self.controller {
            let _ = writeln!(
                s,
                "gains K = [{:e}, {:e}, {:e}] (eq. 48)",
                c.gains[0], c.gains[1], c.gains[2]
            );
            let _ = writeln!(s, "{}", c.linearization.singularity_text(&self.model.graph));
            for o in &c.operations {
                let _ = writeln!(
                    s,
                    "\n{} ({:e} m → {:e} m):",
                    operation_name(o.operation),
                    o.z0,
                    o.zf
                );
                if let Some(opt) = &o.optimal {
                    let _ = writeln!(
                        s,
                        "  energy-optimal: J = ∫u² dt = {:.6e} V²·s, max |u| = {:.4} V, mesh {} nodes, residual {:.2e}, {} saturation switch(es)",
                        opt.cost,
                        opt.max_abs_input,
                        opt.t.len(),
                        opt.max_residual,
                        opt.switches.len()
                    );
                    if let Some(rest) = rest_text(opt) {
                        let _ = writeln!(s, "  {rest}");
                    }
                    if let Some(what) = &opt.smoothed_gap {
                        let _ = writeln!(s, "  note: {what}");
                    }
                }
                let _ = write!(s, "{}", o.feasibility.report());
                let _ = writeln!(s, "  reference table: {} segments", o.table.segments.len());
            }
        }
        if let Some(o) = &self.description.observer {
            let names: Vec<&str> = o
                .estimators
                .iter()
                .map(|e| match e {
                    Estimator::Semera => "semera",
                    Estimator::Integral => "integral",
                    Estimator::Ekf => "ekf",
                    Estimator::Ukf => "ukf",
                })
                .collect();
            let _ = writeln!(
                s,
                "\nobservers: {} at T_s = {:e} s (σ_v = {:e} V, σ_i = {:e} A)",
                names.join(", "),
                o.sample_period,
                o.voltage_noise,
                o.current_noise
            );
        }
        s
    }
}

/// The emitted float types.
fn floats(list: &[FloatType]) -> Vec<Float> {
    list.iter()
        .map(|f| match f {
            FloatType::F32 => Float::F32,
            FloatType::F64 => Float::F64,
        })
        .collect()
}

/// The file name as it should appear in generated headers (no directories,
/// so the bytes do not depend on where the repository is checked out).
fn file_label(name: &str) -> &str {
    Path::new(name)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(name)
}

/// Parses, designs and emits: the text of the generated module.
pub fn build_file(path: &Path) -> Result<(Design, String), BuildError> {
    let description = parse_file(path)?;
    let design = Design::new(&description)?;
    let code = design.emit()?;
    Ok((design, code))
}

/// For `build.rs` (prost-build style): designs `path` and writes the module
/// to `$OUT_DIR/<name>.rs`, printing `cargo:rerun-if-changed`. Include it with
/// `include!(concat!(env!("OUT_DIR"), "/<name>.rs"));`.
pub fn compile(path: impl AsRef<Path>) -> Result<PathBuf, BuildError> {
    let path = path.as_ref();
    println!("cargo:rerun-if-changed={}", path.display());
    let out_dir = std::env::var_os("OUT_DIR").ok_or_else(|| {
        BuildError::Io("OUT_DIR is not set: call compile() from a build script".into())
    })?;
    let (design, code) = build_file(path)?;
    let target = PathBuf::from(out_dir).join(format!("{}.rs", design.description.name));
    write_if_changed(&target, &code)?;
    Ok(target)
}

/// Writes `text` unless the file already holds exactly it (keeps mtimes, so
/// cargo does not rebuild for nothing); atomic via a temporary and rename.
pub fn write_if_changed(target: &Path, text: &str) -> Result<(), BuildError> {
    if std::fs::read_to_string(target).is_ok_and(|old| old == text) {
        return Ok(());
    }
    let tmp = target.with_extension(format!("rs.tmp{}", std::process::id()));
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, target))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            BuildError::Io(format!("{}: cannot write: {e}", target.display()))
        })
}
