//! `reldesign._reldesign`: the Python extension module (PyO3). Thin
//! bindings over the library calls the command line makes, with the same
//! messages and the same numbers; `reldesign/__init__.py` wraps them in
//! pandas DataFrames. Every long call releases the GIL
//! (`Python::allow_threads`) and keeps its own rayon parallelism inside.

use std::path::{Path, PathBuf};

use designer::description::{parse_file, parse_str, Description, DescriptionError as Invalid};
use designer::record::Record;
use numpy::PyReadonlyArray1;
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use reldesign_identify::Measured;

mod closed_loop;
mod design;
mod diagnose;
mod simulate;

create_exception!(
    _reldesign,
    DescriptionError,
    PyValueError,
    "A description that does not parse or validate: the message names the file, line, column and key, as `reldesign check` does."
);
create_exception!(
    _reldesign,
    RecordError,
    PyValueError,
    "A measured record (CSV or DataFrame) that cannot be read as `shared/spec/measured-data.md` asks."
);
create_exception!(
    _reldesign,
    ReldesignError,
    PyRuntimeError,
    "A simulation, diagnosis or design that failed; the message is the command line's."
);

/// A validated actuator description (`valve.toml`).
#[pyclass(frozen, module = "reldesign")]
pub struct Actuator {
    pub description: Description,
}

/// The command line's rendering of a description error (its miette hook:
/// the graphical report, lines not wrapped), without ANSI colour or links.
fn render(error: &Invalid) -> String {
    use miette::ReportHandler;
    struct Rendered<'a>(&'a miette::MietteHandler, &'a Invalid);
    impl std::fmt::Debug for Rendered<'_> {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            self.0.debug(self.1, f)
        }
    }
    let handler = miette::MietteHandlerOpts::new()
        .wrap_lines(false)
        .color(false)
        .terminal_links(false)
        .build();
    format!("{:?}", Rendered(&handler, error))
}

fn description_error(py: Python<'_>, error: &Invalid) -> PyErr {
    let err = DescriptionError::new_err(render(error));
    let value = err.value(py);
    let _ = value.setattr("file", error.file_name());
    let _ = value.setattr("line", error.line());
    let _ = value.setattr("column", error.column());
    let _ = value.setattr("key", error.key());
    let _ = value.setattr("reason", error.message());
    err
}

fn loaded(py: Python<'_>, result: Result<Description, Invalid>) -> PyResult<Actuator> {
    let description = result.map_err(|e| description_error(py, &e))?;
    for warning in &description.warnings {
        PyErr::warn(
            py,
            &py.get_type::<PyUserWarning>(),
            &std::ffi::CString::new(warning.to_string()).unwrap_or_default(),
            1,
        )?;
    }
    Ok(Actuator { description })
}

#[pymethods]
impl Actuator {
    /// Reads and validates a description file; raises `DescriptionError`
    /// naming the file, line, column and key of the first error.
    #[staticmethod]
    fn from_toml(py: Python<'_>, path: PathBuf) -> PyResult<Actuator> {
        loaded(py, parse_file(&path))
    }

    /// Parses and validates a description's text; `file_name` names it in
    /// messages (and in the extended description's header).
    #[staticmethod]
    #[pyo3(signature = (text, file_name = "<string>"))]
    fn from_str(py: Python<'_>, text: &str, file_name: &str) -> PyResult<Actuator> {
        loaded(py, parse_str(text, file_name))
    }

    /// The description's `name` (the emitted module's).
    #[getter]
    fn name(&self) -> &str {
        &self.description.name
    }

    /// The file name the description was read from (or given).
    #[getter]
    fn file_name(&self) -> &str {
        &self.description.source.file_name
    }

    /// The description's TOML text, as read.
    #[getter]
    fn text(&self) -> &str {
        &self.description.source.text
    }

    /// The validation's warnings (also issued as Python warnings on load).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.description
            .warnings
            .iter()
            .map(|w| w.to_string())
            .collect()
    }

    /// The drive of `[supply]`: "voltage" or "current" (the input `simulate` takes).
    #[getter]
    fn drive(&self) -> &'static str {
        match self.description.supply.drive {
            designer::description::Drive::Voltage => "voltage",
            designer::description::Drive::Current => "current",
        }
    }

    /// Pickled as its text (a Dask worker parses it again).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let rebuild = py.import("reldesign")?.getattr("_actuator_from_text")?;
        let args = (self.text(), self.file_name()).into_pyobject(py)?;
        PyTuple::new(py, [rebuild.into_any(), args.into_any()])
    }

    fn __repr__(&self) -> String {
        format!(
            "Actuator(name={:?}, file_name={:?})",
            self.description.name, self.description.source.file_name
        )
    }
}

/// A record's columns as the library's table (one row per sample; line
/// numbers as a CSV with a header would give them).
fn record_from_columns(
    name: &str,
    columns: Vec<(String, PyReadonlyArray1<'_, f64>)>,
) -> PyResult<Record> {
    let n = columns.first().map_or(0, |(_, a)| a.len().unwrap_or(0));
    let mut names = Vec::with_capacity(columns.len());
    let mut values = Vec::with_capacity(columns.len());
    for (column, array) in &columns {
        let a = array.as_array();
        if a.len() != n {
            return Err(RecordError::new_err(format!(
                "{name}: column `{column}` has {} samples, `{}` has {n}",
                a.len(),
                columns[0].0
            )));
        }
        names.push(column.clone());
        values.push(a);
    }
    let rows = (0..n)
        .map(|k| values.iter().map(|a| a[k]).collect())
        .collect();
    Ok(Record {
        columns: names,
        rows,
        lines: (2..n + 2).collect(),
        file_name: name.to_owned(),
    })
}

/// A measured record from a CSV path or from columns.
fn measured(
    path: Option<&Path>,
    name: &str,
    columns: Option<Vec<(String, PyReadonlyArray1<'_, f64>)>>,
) -> PyResult<Measured> {
    let result = match (path, columns) {
        (Some(path), _) => Measured::read(path),
        (None, Some(columns)) => Measured::from_record(&record_from_columns(name, columns)?),
        (None, None) => return Err(PyValueError::new_err("give a record: a path or columns")),
    };
    result.map_err(|e| RecordError::new_err(e.to_string()))
}

/// The extension module.
#[pymodule]
fn _reldesign(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<Actuator>()?;
    m.add("DescriptionError", py.get_type::<DescriptionError>())?;
    m.add("RecordError", py.get_type::<RecordError>())?;
    m.add("ReldesignError", py.get_type::<ReldesignError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    simulate::register(m)?;
    diagnose::register(m)?;
    design::register(m)?;
    closed_loop::register(m)?;
    Ok(())
}
