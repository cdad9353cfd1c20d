//! `design`: the controller and observers designed from a description and
//! their code emitted, the library calls of `reldesign build`; the report is
//! `designer::design_json`'s, the command line's `--report-json`.

use designer::design::Design as Planned;
use pyo3::prelude::*;

use crate::{Actuator, ReldesignError};

/// A description's design: its report and its emitted `no_std` Rust code.
#[pyclass(frozen, module = "reldesign")]
pub struct Design {
    json: String,
    text: String,
    code: String,
}

#[pymethods]
impl Design {
    /// The design figures of `reldesign build --report-json`, as JSON text.
    #[getter]
    fn report_json(&self) -> &str {
        &self.json
    }

    /// The design figures of `reldesign build --report-json`, as a dict.
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (&self.json,))
    }

    /// The design report `reldesign build` prints on stderr.
    fn report_text(&self) -> &str {
        &self.text
    }

    /// The emitted Rust source (`reldesign build --out FILE.rs`).
    fn emit(&self) -> &str {
        &self.code
    }
}

/// Designs the controller of the description's `[trajectory]` and
/// `[controller]` sections and emits its code (`reldesign build`).
#[pyfunction]
fn design(py: Python<'_>, actuator: &Actuator) -> PyResult<Design> {
    let description = &actuator.description;
    py.allow_threads(|| {
        let file = &description.source.file_name;
        let planned = Planned::new(description).map_err(|e| format!("{file}: {e}"))?;
        let code = reldesign_build::emit(&planned).map_err(|e| e.to_string())?;
        Ok::<_, String>(Design {
            json: designer::design_json::report_json(&planned),
            text: planned.report().to_string(),
            code,
        })
    })
    .map_err(ReldesignError::new_err)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Design>()?;
    m.add_function(wrap_pyfunction!(design, m)?)
}
