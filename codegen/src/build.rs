//! From a description file to the emitted controller module: the pipeline
//! behind `reldesign build`, the `build.rs` call and the `design!` macro.
//!
//! description → model → feedback linearization (α, β, T, T⁻¹) → per
//! operation a reference (polynomial or energy-optimal) → feasibility (54),
//! (56), (57) → reference table → emitted Rust. An infeasible design is an
//! error that says which condition fails, where, and what to try.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use designer::description::{parse_file, Description, FloatType, Operation, Shape};
use designer::design::{
    check_feasibility, energy_optimal, fit_segments, DesignError, Feasibility, Linearization,
    OptimalSpec, OptimalTrajectory, Polynomial, Reference, SegmentTolerance, Segments,
};
use designer::model::Model;

use crate::controller::{emit_controller, gains, ControllerError, ControllerInput, OperationTable};
use crate::Float;

/// Why a description could not be built into code.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error("{0}")]
    Description(#[from] designer::description::DescriptionError),
    #[error(
        "{file}: nothing to build: add [trajectory] and [controller] sections (see the README)"
    )]
    NothingToBuild { file: String },
    #[error("{file}: {source}")]
    Design { file: String, source: DesignError },
    #[error("{file}: the {operation} reference is infeasible (perfect-tracking-soft-landing §4):\n{report}")]
    Infeasible {
        file: String,
        operation: &'static str,
        report: String,
    },
    #[error("{file}: the {operation} energy-optimal trajectory: {message}\nhint: if the motion cannot be done with |u| ≤ trajectory.u_bound the problem has no solution: try a larger u_bound (up to the supply limit) or a longer motion (landing − takeoff); `shape = \"polynomial\"` shows which feasibility condition the motion violates")]
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

/// A complete design, ready to emit.
pub struct Design {
    pub description: Description,
    pub model: Model,
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
    /// Designs everything the description's `[trajectory]` and `[controller]` ask for.
    pub fn new(description: &Description) -> Result<Design, BuildError> {
        let file = description.source.file_name.clone();
        let (Some(trajectory), Some(controller)) =
            (&description.trajectory, &description.controller)
        else {
            return Err(BuildError::NothingToBuild { file });
        };
        let mut model = Model::build(description);
        let linearization =
            Linearization::derive(&mut model).map_err(|source| BuildError::Design {
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
                        let spec = OptimalSpec::new(
                            z0,
                            zf,
                            trajectory.takeoff,
                            trajectory.landing,
                            bounds.0,
                            bounds.1,
                        );
                        let solution =
                            energy_optimal(&mut model, &linearization, &spec).map_err(|e| {
                                BuildError::Optimal {
                                    file: file.clone(),
                                    operation: name,
                                    message: e.to_string(),
                                }
                            })?;
                        (Box::new(solution.clone()), Some(solution))
                    }
                };
            let feasibility =
                check_feasibility(&mut model, &linearization, reference.as_ref(), bounds, 4000);
            if !feasibility.is_feasible() {
                return Err(BuildError::Infeasible {
                    file,
                    operation: name,
                    report: feasibility.report(),
                });
            }
            let breaks: Vec<f64> = optimal
                .iter()
                .flat_map(|o| o.switches.iter().map(|s| s.t))
                .collect();
            let fit = fit_segments(reference.as_ref(), &breaks, &SegmentTolerance::default())
                .map_err(|e| BuildError::Table {
                    file: file.clone(),
                    operation: name,
                    message: e.to_string(),
                })?;
            operations.push(DesignedOperation {
                operation,
                z0,
                zf,
                feasibility,
                table: fit.table,
                optimal,
            });
        }
        Ok(Design {
            description: description.clone(),
            gains: gains(&controller.gains),
            model,
            linearization,
            operations,
        })
    }

    /// The emitted module (deterministic bytes).
    pub fn emit(&self) -> Result<String, BuildError> {
        let d = &self.description;
        let (Some(trajectory), Some(controller)) = (&d.trajectory, &d.controller) else {
            return Err(BuildError::NothingToBuild {
                file: d.source.file_name.clone(),
            });
        };
        let input = ControllerInput {
            name: &d.name,
            graph: &self.model.graph,
            params: self.model.params.iter().collect(),
            states: [
                self.model.states[0],
                self.model.states[1],
                self.model.states[2],
            ],
            linearization: &self.linearization,
            gains: self.gains,
            sample_period: controller.sample_period,
            u_min: d.supply.u_min,
            u_max: d.supply.u_max,
            takeoff: trajectory.takeoff,
            landing: trajectory.landing,
            operations: self
                .operations
                .iter()
                .map(|o| OperationTable {
                    operation: o.operation,
                    z0: o.z0,
                    zf: o.zf,
                    segments: &o.table,
                })
                .collect(),
            floats: controller
                .floats
                .iter()
                .map(|f| match f {
                    FloatType::F32 => Float::F32,
                    FloatType::F64 => Float::F64,
                })
                .collect(),
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
        let _ = writeln!(
            s,
            "gains K = [{:e}, {:e}, {:e}] (eq. 48)",
            self.gains[0], self.gains[1], self.gains[2]
        );
        let _ = writeln!(
            s,
            "{}",
            self.linearization.singularity_text(&self.model.graph)
        );
        for o in &self.operations {
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
            }
            let _ = write!(s, "{}", o.feasibility.report());
            let _ = writeln!(s, "  reference table: {} segments", o.table.segments.len());
        }
        s
    }
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
