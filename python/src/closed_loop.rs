//! `closed_loop` and `sweep`: the designed controller in a sampled loop on
//! the hybrid model (`reldesign loop`: the laws of `[trajectory]` and the
//! model-based sliding mode's hold; the backstepping law's run is the
//! command line's), and the design at several sample periods against the
//! uncontrolled switching (`reldesign sweep`). The same library calls
//! (`designer::closed_loop`) and the same defaults as the command line.

use designer::closed_loop::{
    check_sample_period, late_after, loop_spacing, resample_observer, run_hold, run_spaced_loop,
    sweep as sweep_periods, switching_baseline, Noise,
};
use designer::description::{Law, ModelSurface};
use designer::design::Design;
use designer::sim::Options;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::{Actuator, ReldesignError};

/// The sample periods `reldesign sweep` tries by default [s].
const DEFAULT_PERIODS: [f64; 7] = [1e-6, 2e-6, 5e-6, 1e-5, 2e-5, 5e-5, 1e-4];

fn failed(message: impl Into<String>) -> PyErr {
    ReldesignError::new_err(message.into())
}

/// Runs the designed controller in a sampled loop on the model of `plant`
/// (default: the description itself): `reldesign loop`. Returns the columns
/// `t, u, i, z, vz, phi[, Hc], mode, z_ref[, z_hat, v_hat, phi_hat[, Hc_hat]]`
/// as numpy arrays, and per operation its first impact, RMSE_z, bounces, the
/// highest bounce, when it arrived, whether the runtime pushed it there late
/// and whether the controller flagged it late (or the hold's settling).
#[pyfunction]
#[pyo3(signature = (actuator, plant = None, sample_period = None, duration = None, seed = 0, noise = None, initial_field = 0.0))]
#[allow(clippy::too_many_arguments)]
fn closed_loop<'py>(
    py: Python<'py>,
    actuator: &Actuator,
    plant: Option<PyRef<'py, Actuator>>,
    sample_period: Option<f64>,
    duration: Option<f64>,
    seed: u64,
    noise: Option<(f64, f64)>,
    initial_field: f64,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyList>)> {
    let description = &actuator.description;
    let file = description.source.file_name.clone();
    let Some(controller) = &description.controller else {
        return Err(failed(format!(
            "{file}: `loop` runs the designed controller: the description needs [trajectory] and [controller]"
        )));
    };
    for (name, x) in [("sample_period", sample_period), ("duration", duration)] {
        if x.is_some_and(|v| !(v.is_finite() && v > 0.0)) {
            return Err(failed(format!(
                "{name}: expected a positive number of seconds"
            )));
        }
    }
    if !initial_field.is_finite() {
        return Err(failed("initial_field: expected a finite number [A/m]"));
    }
    let sigma = match noise {
        None => None,
        Some((v, i)) if v >= 0.0 && i >= 0.0 && v.is_finite() && i.is_finite() => Some([v, i]),
        Some(other) => {
            return Err(failed(format!(
                "noise: expected σ_v, σ_i ≥ 0 [V, A], found {other:?}"
            )))
        }
    };
    if matches!(controller.law, Law::Backstepping(_)) {
        return Err(failed(format!(
            "{file}: law = \"backstepping\": its loop (switching, V, F_d) is the command line's `reldesign loop`"
        )));
    }
    let holds = matches!(
        controller.law,
        Law::ModelSlidingMode(ModelSurface {
            position: Some(_),
            ..
        })
    );
    let ts = sample_period.unwrap_or(controller.sample_period);
    let law = controller.law.name();
    let timing = (description.trajectory.as_ref()).map_or((0.0, 0.0), |t| (t.takeoff, t.landing));
    let plant = plant.as_ref().map(|p| &p.description);
    let noise = Noise { seed, sigma };
    let (run, with_field, late_after) = py
        .allow_threads(|| {
            if !holds {
                check_sample_period(description, ts).map_err(|e| format!("{file}: {e}"))?;
            }
            let mut designed = description.clone();
            if let Some(c) = &mut designed.controller {
                c.sample_period = ts;
            }
            if let (Some(o), Some(_)) = (&mut designed.observer, sample_period) {
                resample_observer(o, ts);
            }
            let design = Design::new(&designed).map_err(|e| format!("{file}: {e}"))?;
            let options = Options::default();
            let run = if holds {
                run_hold(&design, plant, ts, duration, noise, initial_field, &options)
            } else {
                let spacing = loop_spacing(&design, plant);
                run_spaced_loop(&design, plant, ts, duration, spacing, noise, &options)
            };
            run.map(|r| (r, design.model.dim() > 3, late_after(&design)))
                .map_err(|e| format!("{file}: {e}"))
        })
        .map_err(failed)?;
    let tr = &run.trajectory;
    let column = |j: usize| tr.x.iter().map(|x| x[j]).collect::<Vec<f64>>();
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, tr.t.clone()))?;
    out.set_item("u", PyArray1::from_vec(py, tr.u.clone()))?;
    out.set_item("i", PyArray1::from_vec(py, run.current.clone()))?;
    out.set_item("z", PyArray1::from_vec(py, column(0)))?;
    out.set_item("vz", PyArray1::from_vec(py, column(1)))?;
    out.set_item("phi", PyArray1::from_vec(py, column(2)))?;
    if with_field {
        out.set_item("Hc", PyArray1::from_vec(py, column(3)))?;
    }
    let mode: Vec<u8> = tr.mode.iter().map(|m| m.number()).collect();
    out.set_item("mode", PyArray1::from_vec(py, mode))?;
    out.set_item("z_ref", PyArray1::from_vec(py, run.z_ref.clone()))?;
    if let Some(e) = &run.estimates {
        out.set_item(
            "z_hat",
            PyArray1::from_vec(py, e.iter().map(|e| e.z).collect()),
        )?;
        out.set_item(
            "v_hat",
            PyArray1::from_vec(py, e.iter().map(|e| e.v).collect()),
        )?;
        out.set_item(
            "phi_hat",
            PyArray1::from_vec(py, e.iter().map(|e| e.phi).collect()),
        )?;
        if with_field {
            let hc = e.iter().map(|e| e.hc.unwrap_or(f64::NAN)).collect();
            out.set_item("Hc_hat", PyArray1::from_vec(py, hc))?;
        }
    }
    let summary = PyList::empty(py);
    if holds {
        let o = run.hold_outcome();
        let row = PyDict::new(py);
        row.set_item("law", law)?;
        row.set_item("sample_period", ts)?;
        row.set_item("settling_time", o.settling_time)?;
        row.set_item("steady_error", o.steady_error)?;
        row.set_item("steady_band", o.steady_band)?;
        summary.append(row)?;
    } else {
        for o in run.outcomes(timing.0, timing.1) {
            let row = PyDict::new(py);
            row.set_item("law", law)?;
            row.set_item("sample_period", ts)?;
            row.set_item("operation", o.operation.name())?;
            row.set_item("impact_velocity", o.impact_velocity)?;
            row.set_item("rmse_z", o.rmse_z)?;
            row.set_item("bounces", o.bounces)?;
            row.set_item("highest_bounce", o.highest_bounce)?;
            row.set_item("arrival", o.arrival)?;
            row.set_item("late", o.arrived_late(late_after))?;
            row.set_item("flagged_late", o.flagged_late)?;
            summary.append(row)?;
        }
    }
    Ok((out, summary))
}

/// The design redone at each sample period (default: the command line's
/// seven, 1 µs to 100 µs) and run in closed loop, against the uncontrolled
/// switching (u_max, then 0 V): `reldesign sweep --json`'s rows and
/// `switching`, as lists of dicts.
#[pyfunction]
#[pyo3(signature = (actuator, sample_periods = None, plant = None))]
fn sweep<'py>(
    py: Python<'py>,
    actuator: &Actuator,
    sample_periods: Option<Vec<f64>>,
    plant: Option<PyRef<'py, Actuator>>,
) -> PyResult<(Bound<'py, PyList>, Bound<'py, PyList>)> {
    let description = &actuator.description;
    let file = description.source.file_name.clone();
    let periods = sample_periods.unwrap_or_else(|| DEFAULT_PERIODS.to_vec());
    if let Some(ts) = periods.iter().find(|ts| !(ts.is_finite() && **ts > 0.0)) {
        return Err(failed(format!(
            "sample_periods: expected positive numbers of seconds, found {ts}"
        )));
    }
    let Some(c) = &description.controller else {
        return Err(failed(format!(
            "{file}: `sweep` runs the designed controller: the description needs [trajectory] and [controller]"
        )));
    };
    let law = c.law.name();
    let plant = plant.as_ref().map(|p| &p.description);
    let (rows, baseline) = py
        .allow_threads(|| {
            let options = Options::default();
            let rows = sweep_periods(description, plant, &periods, &options)?;
            let baseline = switching_baseline(description, plant, &options)?;
            Ok((rows, baseline))
        })
        .map_err(|e: designer::closed_loop::LoopError| failed(format!("{file}: {e}")))?;
    let out = PyList::empty(py);
    for r in &rows {
        for o in &r.outcomes {
            let row = PyDict::new(py);
            row.set_item("law", law)?;
            row.set_item("design", &file)?;
            row.set_item("sample_period", r.sample_period)?;
            row.set_item("operation", o.operation.name())?;
            row.set_item("impact_velocity", o.impact_velocity)?;
            row.set_item("rmse_z", o.rmse_z)?;
            row.set_item("bounces", o.bounces)?;
            out.append(row)?;
        }
    }
    let switching = PyList::empty(py);
    for (operation, velocity) in baseline {
        let row = PyDict::new(py);
        row.set_item("operation", operation.name())?;
        row.set_item("impact_velocity", velocity)?;
        switching.append(row)?;
    }
    Ok((out, switching))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(closed_loop, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)
}
