//! `diagnose` and `fit`: the library calls of `reldesign diagnose` and
//! `reldesign fit` on a record given as a CSV path or as columns. The
//! diagnosis is reported by `identify::diagnose::report`, the command line's
//! own JSON, text and extended description.

use std::path::{Path, PathBuf};

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use reldesign_identify::diagnose::report::{report, Paths};
use reldesign_identify::diagnose::{diagnose_causes, Cause, Options};
use reldesign_identify::edit::write_physics;
use reldesign_identify::params::{self, Domain};
use reldesign_identify::{current_wnrmse, fit as fit_record, FitOptions, FitParam};

use crate::{measured, Actuator, ReldesignError};

/// One record's diagnosis: what `reldesign diagnose` prints and writes.
#[pyclass(frozen, module = "reldesign")]
pub struct Diagnosis {
    json: String,
    text: String,
    extended: String,
    causes: Vec<String>,
    gain: f64,
    /// (path, value, standard error, baseline)
    parameters: Vec<(String, f64, f64, Option<f64>)>,
    file: String,
}

#[pymethods]
impl Diagnosis {
    /// The causes found, strongest first (empty: none named).
    #[getter]
    fn causes(&self) -> Vec<String> {
        self.causes.clone()
    }

    /// The whole selection's gain, 1 − extended/baseline wNRMSE.
    #[getter]
    fn gain(&self) -> f64 {
        self.gain
    }

    /// The fitted parameters: {path: {"value", "std_error", "baseline"}}.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for (path, value, std_error, baseline) in &self.parameters {
            let entry = PyDict::new(py);
            entry.set_item("value", value)?;
            entry.set_item("std_error", std_error)?;
            entry.set_item("baseline", baseline)?;
            out.set_item(path, entry)?;
        }
        Ok(out)
    }

    /// The extended description (TOML text, the original's comments kept).
    #[getter]
    fn extended(&self) -> &str {
        &self.extended
    }

    /// The record's file (or the name given to its columns).
    #[getter]
    fn file(&self) -> &str {
        &self.file
    }

    /// The JSON object of `reldesign diagnose --json`, as text.
    #[getter]
    fn json(&self) -> &str {
        &self.json
    }

    /// The JSON object of `reldesign diagnose --json`, as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (&self.json,))
    }

    /// The text report of `reldesign diagnose`.
    fn report(&self) -> &str {
        &self.text
    }

    fn __repr__(&self) -> String {
        format!(
            "Diagnosis(file={:?}, causes={:?}, gain={:.4})",
            self.file, self.causes, self.gain
        )
    }
}

/// Diagnoses a record (a CSV `path`, or `columns` named `name`) against the
/// actuator; `out_dir` names where the extended model is written, as
/// `--out` does (`write`: write it, with the report and the JSON).
#[pyfunction]
#[pyo3(signature = (actuator, path = None, columns = None, name = "record.csv", out_dir = None, holdout = 0.25, causes = None, write = false))]
#[allow(clippy::too_many_arguments)]
fn diagnose(
    py: Python<'_>,
    actuator: &Actuator,
    path: Option<PathBuf>,
    columns: Option<Vec<(String, PyReadonlyArray1<'_, f64>)>>,
    name: &str,
    out_dir: Option<PathBuf>,
    holdout: f64,
    causes: Option<Vec<String>>,
    write: bool,
) -> PyResult<Diagnosis> {
    if !(0.0..=0.5).contains(&holdout) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "holdout {holdout}: expected a fraction in [0, 0.5]"
        )));
    }
    let mut options = Options {
        holdout,
        ..Options::default()
    };
    if let Some(names) = causes.filter(|c| !c.is_empty()) {
        options.causes = (names.iter())
            .map(|c| c.parse::<Cause>())
            .collect::<Result<_, _>>()
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    }
    let data = measured(path.as_deref(), name, columns)?;
    let data_path = path.unwrap_or_else(|| PathBuf::from(name));
    let description = &actuator.description;
    let outputs = Paths::new(out_dir.as_deref(), &data_path);
    let r = py
        .allow_threads(|| {
            let answer =
                diagnose_causes(description, &data, &options).map_err(|e| e.to_string())?;
            report(description, &data, &data_path, &outputs, &answer)
        })
        .map_err(ReldesignError::new_err)?;
    let json = r.json.to_string();
    if write {
        write_files(&outputs, &r.extended_toml, &r.text, &json)?;
    }
    let causes = match r.json.get("causes") {
        Some(serde_json::Value::Array(names)) => (names.iter())
            .filter_map(|n| n.as_str().map(str::to_owned))
            .collect(),
        _ => Vec::new(),
    };
    Ok(Diagnosis {
        causes,
        gain: r.gain,
        parameters: (r.parameters.iter())
            .map(|p| (p.path.clone(), p.value, p.std_error, p.baseline))
            .collect(),
        extended: r.extended_toml,
        text: r.text,
        json,
        file: data_path.display().to_string(),
    })
}

/// `<stem>.extended.toml`, `<stem>.report.txt` and `<stem>.json` beside the
/// extended model's path.
fn write_files(outputs: &Paths, toml: &str, text: &str, json: &str) -> PyResult<()> {
    let beside = |suffix: &str| {
        let name = outputs.extended.file_name().map_or_else(
            || "data".to_owned(),
            |n| {
                n.to_string_lossy()
                    .trim_end_matches(".extended.toml")
                    .to_owned()
            },
        );
        outputs.extended.with_file_name(format!("{name}.{suffix}"))
    };
    if let Some(dir) = outputs
        .extended
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
    {
        std::fs::create_dir_all(dir).map_err(|e| io_error(dir, e))?;
    }
    for (path, bytes) in [
        (outputs.extended.clone(), toml),
        (beside("report.txt"), text),
        (beside("json"), json),
    ] {
        std::fs::write(&path, bytes).map_err(|e| io_error(&path, e))?;
    }
    Ok(())
}

fn io_error(path: &Path, e: std::io::Error) -> PyErr {
    pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", path.display()))
}

/// The parameter's search range: given, or the command line's default (a
/// decade either side of its value; [0, 1] for a fraction).
fn bounds(
    d: &designer::description::Description,
    path: &str,
    range: Option<(f64, f64)>,
) -> Result<FitParam, String> {
    let value = params::get(d, path).map_err(|e| e.to_string())?;
    let (lower, upper) = match range {
        Some((lo, hi)) if lo < hi => (lo, hi),
        Some(_) => return Err(format!("{path}: expected bounds (lo, hi) with lo < hi")),
        None => match params::domain(d, path).map_err(|e| e.to_string())? {
            Domain::Unit => (0.0, 1.0),
            Domain::UnitOpen => (0.0, 0.999),
            _ if value == 0.0 => {
                return Err(format!(
                    "{path}: its value is 0, which gives no scale for default bounds; give (lo, hi)"
                ))
            }
            _ if value > 0.0 => (value / 10.0, value * 10.0),
            _ => (value * 10.0, value / 10.0),
        },
    };
    Ok(FitParam {
        path: path.to_owned(),
        lower,
        upper,
    })
}

/// Fits description parameters to a record (`reldesign fit`): `params` maps
/// each key path to its bounds (or None for the default range). Returns a
/// dict: values, initial, relative standard errors, wNRMSE before and
/// after, the fitted description's TOML text.
#[pyfunction]
#[pyo3(signature = (actuator, params, path = None, columns = None, name = "record.csv", starts = 1, max_iterations = 50, use_flux = true, seed = 1))]
#[allow(clippy::too_many_arguments)]
fn fit<'py>(
    py: Python<'py>,
    actuator: &Actuator,
    params: Vec<(String, Option<(f64, f64)>)>,
    path: Option<PathBuf>,
    columns: Option<Vec<(String, PyReadonlyArray1<'py, f64>)>>,
    name: &str,
    starts: usize,
    max_iterations: usize,
    use_flux: bool,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let description = &actuator.description;
    let fitted = (params.iter())
        .map(|(p, range)| bounds(description, p, *range))
        .collect::<Result<Vec<_>, _>>()
        .map_err(pyo3::exceptions::PyValueError::new_err)?;
    if fitted.is_empty() {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "give at least one parameter to fit",
        ));
    }
    let data = measured(path.as_deref(), name, columns)?;
    let options = FitOptions {
        starts: starts.max(1),
        max_iterations,
        use_flux,
        seed,
        ..FitOptions::default()
    };
    let (before, r, text) = py
        .allow_threads(|| {
            let before = current_wnrmse(description, &data).map_err(|e| e.to_string())?;
            let r = fit_record(description, &data, &fitted, &options, &|_| {})
                .map_err(|e| e.to_string())?;
            let source = &description.source;
            let text = write_physics(&source.text, &source.file_name, &r.description)
                .map_err(|e| e.to_string())?;
            Ok::<_, String>((before, r, text))
        })
        .map_err(ReldesignError::new_err)?;
    let out = PyDict::new(py);
    let values = PyDict::new(py);
    let initial = PyDict::new(py);
    for (p, v) in &r.values {
        values.set_item(p, v)?;
        initial.set_item(p, params::get(description, p).ok())?;
    }
    let errors = PyDict::new(py);
    for (n, e) in r
        .sensitivity
        .names
        .iter()
        .zip(&r.sensitivity.relative_std_errors)
    {
        errors.set_item(n, e)?;
    }
    out.set_item("values", values)?;
    out.set_item("initial", initial)?;
    out.set_item("relative_std_errors", errors)?;
    out.set_item("wnrmse_current_before", before)?;
    out.set_item("wnrmse_current", r.wnrmse_current)?;
    out.set_item("wnrmse_flux", r.wnrmse_flux)?;
    out.set_item("nrmse_position", r.nrmse_position)?;
    out.set_item("iterations", r.iterations)?;
    out.set_item("status", format!("{:?}", r.status))?;
    out.set_item("description", text)?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Diagnosis>()?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)
}
