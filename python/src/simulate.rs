//! `simulate`: an input replayed through the hybrid model from rest at
//! z_max, the library call of `reldesign simulate` (same tolerance, same
//! columns `t, v, i, z, vz, phi[, Hc], mode`). The columns leave as numpy
//! arrays that own the Rust vectors (no copy).

use designer::model::{Model, ModelPlant};
use designer::replay::replay_plant;
use designer::sim::{Options, PiecewiseLinear};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{Actuator, ReldesignError};

/// Replays the input `u` (the voltage, or the current for a current-driven
/// description), linear between the samples at times `t`, from rest at
/// z_max; returns the columns at `t` as a dict of numpy arrays.
#[pyfunction]
#[pyo3(signature = (actuator, t, u, rtol = 1e-9))]
fn simulate<'py>(
    py: Python<'py>,
    actuator: &Actuator,
    t: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    rtol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let times = t.as_array().to_vec();
    let values = u.as_array().to_vec();
    let description = &actuator.description;
    let file = description.source.file_name.clone();
    let input = PiecewiseLinear::new(times.clone(), values)
        .map_err(|e| ReldesignError::new_err(format!("{file}: input: {e}")))?;
    let options = Options {
        rtol,
        ..Options::default()
    };
    let (replay, with_field) = py
        .allow_threads(|| {
            let mut model = Model::build(description);
            let plant = ModelPlant::new(&mut model);
            let replay = replay_plant(&plant, &model, &input, &times, &options);
            replay.map(|r| (r, model.has_field_state()))
        })
        .map_err(|e| ReldesignError::new_err(format!("{file}: simulation failed: {e}")))?;
    let tr = replay.trajectory;
    let column = |j: usize| tr.x.iter().map(|x| x[j]).collect::<Vec<f64>>();
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, tr.t.clone()))?;
    out.set_item("v", PyArray1::from_vec(py, replay.voltage))?;
    out.set_item("i", PyArray1::from_vec(py, replay.current))?;
    out.set_item("z", PyArray1::from_vec(py, column(0)))?;
    out.set_item("vz", PyArray1::from_vec(py, column(1)))?;
    out.set_item("phi", PyArray1::from_vec(py, column(2)))?;
    if with_field {
        out.set_item("Hc", PyArray1::from_vec(py, column(3)))?;
    }
    let mode: Vec<u8> = tr.mode.iter().map(|m| m.number()).collect();
    out.set_item("mode", PyArray1::from_vec(py, mode))?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate, m)?)
}
