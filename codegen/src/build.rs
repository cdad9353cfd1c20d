//! From a description file to the emitted module: the last step of the
//! pipeline behind `reldesign build`, the `build.rs` call and the `design!`
//! macro. The design itself (references, feasibility, tables, gains,
//! guards) is `designer::design::Design`; this renders it: the header, the
//! file's one `params!` macro, the controller and the observers.

use std::path::{Path, PathBuf};

use designer::description::{parse_file, Estimator, FloatType};
use designer::design::{Design, LawDesign, PlanError};

use crate::backstepping::{emit_backstepping, BacksteppingInput};
use crate::controller::emit_controller;
use crate::emit::params_macro;
use crate::error::ControllerError;
use crate::error::EmitError;
use crate::header::Header;
use crate::hold::{emit_hold, HoldInput};
use crate::observer::{
    emit_ekf, emit_kalman_macro, emit_ukf, wrap_module, ObserverError, ObserverInput,
};
use crate::operations::ControllerInput;
use crate::semera::{emit_semera, SemeraError, SemeraInput};
use crate::sliding::emit_sliding_mode;
use crate::Float;

/// Why a description could not be built into code.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error("{0}")]
    Description(#[from] designer::description::DescriptionError),
    /// The design failed (`designer::design::plan`).
    #[error("{file}: {source}")]
    Plan { file: String, source: PlanError },
    #[error("{file}: the {estimator} observer: {message}")]
    Observer {
        file: String,
        estimator: &'static str,
        message: String,
    },
    #[error("{file}: code generation: {source}")]
    Emit {
        file: String,
        source: ControllerError,
    },
    #[error("{file}: the parameters: {source}")]
    Params { file: String, source: EmitError },
    #[error("{file}: [controller] self_calibration: {message}")]
    Calibration { file: String, message: String },
    #[error("{0}")]
    Io(String),
}

/// The emitted module (deterministic bytes): the header, the `params!`
/// macro when a module uses it, `kalman!` with filters, the controller (its
/// `law!` macro and float modules, if any), then `pub mod estimators`
/// (SEMERA, integral), `pub mod ekf`, `pub mod ukf` (each with its
/// `model!`).
pub fn emit(design: &Design) -> Result<String, BuildError> {
    let d = &design.description;
    let file = || d.source.file_name.clone();
    let mut modules = Vec::new();
    // file-level macros besides `params!` (the filters' `kalman!` settings,
    // the self-calibration's `calibration!`)
    let mut macros = Vec::new();
    let calibration = emitted_calibration(design)?;
    if let Some(c) = &calibration {
        let text = crate::calibration::calibration_macro(&d.name, c).map_err(|source| {
            BuildError::Params {
                file: file(),
                source,
            }
        })?;
        macros.push(text);
    }
    if let Some(c) = &design.controller {
        let floats = d
            .controller
            .as_ref()
            .map(|c| floats(&c.floats))
            .unwrap_or_default();
        let input = ControllerInput {
            model: &design.model,
            design: c,
            floats,
            calibration: calibration.as_ref(),
        };
        let emitted = match c.law {
            LawDesign::FeedbackLinearization { .. } | LawDesign::ModelSlidingMode { .. } => {
                emit_controller(&input)
            }
            LawDesign::SlidingMode { .. } => emit_sliding_mode(&input),
        };
        modules.push(emitted.map_err(|source| BuildError::Emit {
            file: file(),
            source,
        })?);
    }
    if let Some(h) = &design.hold {
        let floats = d
            .controller
            .as_ref()
            .map(|c| floats(&c.floats))
            .unwrap_or_default();
        let input = HoldInput {
            model: &design.model,
            design: h,
            floats,
        };
        modules.push(emit_hold(&input).map_err(|source| BuildError::Emit {
            file: file(),
            source,
        })?);
    }
    if let Some(b) = &design.backstepping {
        let floats = d
            .controller
            .as_ref()
            .map(|c| floats(&c.floats))
            .unwrap_or_default();
        let input = BacksteppingInput {
            model: &design.model,
            design: b,
            floats,
        };
        modules.push(
            emit_backstepping(&input).map_err(|source| BuildError::Emit {
                file: file(),
                source,
            })?,
        );
    }
    if let Some(input) = SemeraInput::from_description(d) {
        let items = emit_semera(&input).map_err(|e: SemeraError| BuildError::Observer {
            file: file(),
            estimator: "semera/integral",
            message: e.to_string(),
        })?;
        modules.push(wrap_module(
            "estimators",
            "The model-free electrical estimators (semera-electromagnetic-estimation):\nSEMERA [SE Alg. 1] and the integral estimator [SE Alg. 2].",
            &items,
        ));
    }
    if let (Some(discrete), Some(o)) = (&design.kalman, &d.observer) {
        let input = ObserverInput {
            name: &d.name,
            discrete,
            floats: floats(&o.floats),
            // the filters read θ where the innovations update adapts it
            calibration: calibration
                .as_ref()
                .filter(|c| c.method == designer::calibrate::Method::Innovations),
        };
        macros.push(emit_kalman_macro(&input).map_err(|e| BuildError::Observer {
            file: file(),
            estimator: "ekf/ukf",
            message: e.to_string(),
        })?);
        type Emitter = fn(&ObserverInput) -> Result<String, ObserverError>;
        let kinds: [(Estimator, &str, &str, Emitter); 2] = [
            (Estimator::Ekf, "ekf", "The extended Kalman filter on the discretised model (jiles-atherton-actuator-model [JA 84–87]).", emit_ekf),
            (Estimator::Ukf, "ukf", "The unscented Kalman filter on the discretised model (jiles-atherton-actuator-model [JA 84–87]).", emit_ukf),
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
            modules.push(wrap_module(name, doc, &items));
        }
    }
    let mut out = header(design);
    if modules.iter().any(|m| invokes_params(m)) {
        let text = params_macro(&design.model).map_err(|source| BuildError::Params {
            file: file(),
            source,
        })?;
        out.push('\n');
        out.push_str(&text);
    }
    for module in macros.into_iter().chain(modules) {
        out.push('\n');
        out.push_str(&module);
    }
    Ok(out)
}

/// Whether an emitted module declares the parameters with `params!(…)`.
/// The self-calibration the file carries (`designer::calibrate::choose`):
/// the innovations update of a design whose law the UKF drives (in the `ukf`
/// module), or the replay of a design whose law reads measured states (in
/// the controller's modules, `replay.rs`).
fn emitted_calibration(
    design: &Design,
) -> Result<Option<designer::calibrate::CalibrationDesign>, BuildError> {
    let d = &design.description;
    let Some(c) = d.controller.as_ref().filter(|c| c.self_calibration) else {
        return Ok(None);
    };
    let fail = |message: String| BuildError::Calibration {
        file: d.source.file_name.clone(),
        message,
    };
    let calibration =
        designer::calibrate::choose(design, c.sample_period).map_err(|e| fail(e.to_string()))?;
    if calibration.method == designer::calibrate::Method::Replay {
        return Ok(Some(calibration));
    }
    let ukf = d
        .observer
        .as_ref()
        .is_some_and(|o| o.estimators.contains(&Estimator::Ukf));
    if !ukf {
        return Err(fail(
            "the emitted update runs the unscented Kalman filter: add \"ukf\" to [observer] estimators"
                .to_owned(),
        ));
    }
    Ok(Some(calibration))
}

fn invokes_params(module: &str) -> bool {
    module
        .lines()
        .any(|line| line.trim_start().starts_with("params!("))
}

/// The file header: what the file holds, from which source.
fn header(design: &Design) -> String {
    let d = &design.description;
    let what = match design.controller.as_ref().map(|c| c.law) {
        None if design.backstepping.is_some() => format!(
            "position controller of `{}` (backstepping through the force, [SB 19])",
            d.name
        ),
        None if design.hold.is_some() => format!(
            "position hold of `{}` (model-based sliding mode, [JA 89])",
            d.name
        ),
        Some(LawDesign::FeedbackLinearization { .. }) => format!(
            "perfect-tracking soft-landing controller of `{}` (feedback linearization, [PT 50])",
            d.name
        ),
        Some(LawDesign::SlidingMode { .. }) => format!(
            "soft-landing controller of `{}` (model-free sliding mode, [SM 34])",
            d.name
        ),
        Some(LawDesign::ModelSlidingMode { .. }) => format!(
            "soft-landing controller of `{}` (model-based sliding mode, [JA 89])",
            d.name
        ),
        None => format!("observers of `{}`", d.name),
    };
    Header {
        what: &what,
        generator_version: env!("CARGO_PKG_VERSION"),
        source_file: file_label(&d.source.file_name),
        source_text: &d.source.text,
    }
    .text()
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
    let design = Design::new(&description).map_err(|source| BuildError::Plan {
        file: description.source.file_name.clone(),
        source,
    })?;
    let code = emit(&design)?;
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
