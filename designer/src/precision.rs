//! How well a sensorless design knows its armature when each approach starts,
//! and how hard that lets it meet the stop.
//!
//! The filter runs on the measurements of the design's noise-free closed loop
//! on its own model; its covariance there is what the measurement noise of
//! `[observer]` leaves (it predicts the spread of z − ẑ over noise draws:
//! `tests/tests/estimate_precision.rs`). A flux σ_φ off moves the armature's
//! acceleration by |∂a/∂φ|·σ_φ (at constant z, the plant's own right-hand
//! side), and over the standoff δ that meets the stop at
//! v ≈ √(v_c² + 2·|∂a/∂φ|·σ_φ·δ): the law keeps the estimate at v_c, not the
//! armature. Only the measurement noise is in it; a plant that differs from
//! the description adds its own error.

use crate::closed_loop::{loop_spacing, run_spaced_loop, LoopError, LoopRun, Noise};
use crate::description::{Approach, Estimator, Operation};
use crate::design::{Design, LawDesign};
use crate::model::{Model, ModelPlant};
use crate::observe::discrete::DiscreteModel;
use crate::observe::filter::{Reference, Runtime};
use crate::observe::{ekf::Ekf, ukf::Ukf};
use crate::sim::{Plant, State, MAX_DIM};

/// One operation's approach, as its sensorless design sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct ApproachPrecision {
    pub operation: Operation,
    /// When the approach starts [s after the operation's start]: t_f − 5·δ/(4·v_c).
    pub at: f64,
    /// The filter's standard deviation of z there [m].
    pub sigma_z: f64,
    /// The filter's standard deviation of φ there [Wb], and φ itself.
    pub sigma_phi: f64,
    pub phi: f64,
    /// |∂a/∂φ| at constant z there [m/s²/Wb].
    pub accel_per_flux: f64,
    pub approach: Approach,
    /// √(v_c² + 2·|∂a/∂φ|·σ_φ·δ) [m/s].
    pub impact: f64,
}

/// Per designed operation, where the feedback-linearizing law reads an
/// estimate and the trajectory has an approach (what the impact's reasoning
/// and its check cover); empty otherwise.
pub fn at_approaches(design: &Design) -> Result<Vec<ApproachPrecision>, LoopError> {
    let (Some(c), Some(t), Some(discrete)) = (
        &design.controller,
        &design.description.trajectory,
        &design.kalman,
    ) else {
        return Ok(Vec::new());
    };
    let estimator = (design.description.controller.as_ref()).and_then(|c| c.estimator);
    let linearizing = matches!(c.law, LawDesign::FeedbackLinearization { .. });
    let (Some(estimator), Some(approach), true) = (estimator, t.approach(), linearizing) else {
        return Ok(Vec::new());
    };
    let quiet = Noise {
        seed: 0,
        sigma: Some([0.0, 0.0]),
    };
    let window = loop_spacing(design, None);
    let run = run_spaced_loop(
        design,
        None,
        c.sample_period,
        None,
        window,
        quiet,
        &Default::default(),
    )?;
    let spread = covariance_along(&run, discrete, estimator);
    let mut model = Model::build(&design.description);
    let plant = ModelPlant::new(&mut model);
    let at = t.landing - approach.duration();
    let found = run.operations.iter().filter_map(|&(operation, start)| {
        // the sample at the approach's start, rounding aside
        let k = (run.measured.iter()).position(|m| m.t >= start + at - 1e-9 * c.sample_period)?;
        let j = run
            .trajectory
            .t
            .iter()
            .position(|&s| s >= run.measured[k].t)?;
        let x = run.trajectory.x[j];
        let (sigma_z, sigma_phi) = spread[k];
        let accel_per_flux = accel_per_flux(&plant, &x);
        let impact =
            (approach.speed.powi(2) + 2.0 * accel_per_flux * sigma_phi * approach.standoff).sqrt();
        Some(ApproachPrecision {
            operation,
            at,
            sigma_z,
            sigma_phi,
            phi: x[2],
            accel_per_flux,
            approach,
            impact,
        })
    });
    Ok(found.collect())
}

/// (σ_z, σ_φ) of a fresh filter of `[controller] estimator` fed the run's
/// measured voltage and current, at every sample.
fn covariance_along(
    run: &LoopRun,
    discrete: &DiscreteModel,
    estimator: Estimator,
) -> Vec<(f64, f64)> {
    match estimator {
        Estimator::Ekf => spread_along(Ekf::new(discrete), run),
        _ => spread_along(Ukf::new(discrete), run),
    }
}

/// (σ_z, σ_φ) of `filter` after each of the run's samples (the state's
/// entries 0 and 2 are z and φ for every filter dimension).
fn spread_along<A: Runtime<3>, B: Runtime<4>, C: Runtime<5>>(
    mut filter: Reference<A, B, C>,
    run: &LoopRun,
) -> Vec<(f64, f64)> {
    (run.measured.iter())
        .map(|m| {
            filter.step(m.voltage, m.current);
            let p = filter.covariance();
            (p[0][0].max(0.0).sqrt(), p[2][2].max(0.0).sqrt())
        })
        .collect()
}

/// |∂a/∂φ| at the plant state `x`, at rest, by central differences of the
/// plant's own right-hand side.
fn accel_per_flux(plant: &ModelPlant, x: &State) -> f64 {
    let accel = |phi: f64| {
        let mut s: State = [0.0; MAX_DIM];
        s[0] = x[0];
        s[2] = phi;
        let mut dx: State = [0.0; MAX_DIM];
        plant.deriv(0.0, &s, 0.0, &mut dx);
        dx[1]
    };
    let h = 1e-4 * x[2].abs().max(1e-9);
    ((accel(x[2] + h) - accel(x[2] - h)) / (2.0 * h)).abs()
}

/// The lines `reldesign build` prints for `found` ([`at_approaches`] of
/// `design`; `None` where it is empty), with each first impact against the
/// uncontrolled switching's on the description.
pub fn report(design: &Design, found: &[ApproachPrecision]) -> Result<Option<String>, LoopError> {
    use std::fmt::Write as _;
    let Some(o) = design.description.observer.as_ref() else {
        return Ok(None);
    };
    if found.is_empty() {
        return Ok(None);
    }
    let switching =
        crate::closed_loop::switching_baseline(&design.description, None, &Default::default())?;
    let mut s = format!(
        "sensorless precision (the filter's covariance along the noise-free loop on the description; σ_v = {:e} V, σ_i = {:e} A):\n",
        o.voltage_noise, o.current_noise
    );
    for p in found {
        let versus = (switching.iter())
            .find(|(op, _)| *op == p.operation)
            .and_then(|(_, v)| *v)
            .map_or(String::new(), |v| {
                format!(", {:.0}× softer than switching", v.abs() / p.impact)
            });
        // σ_φ relative to φ, unless φ is ~0 there
        let relative = 100.0 * p.sigma_phi / p.phi.abs();
        let sigma_phi = if relative.is_finite() && relative < 100.0 {
            format!("{relative:.2} % of {:.4e} Wb", p.phi)
        } else {
            format!("{:.3e} Wb", p.sigma_phi)
        };
        let _ = writeln!(
            s,
            "  {}: when the approach starts ({:.4} ms, {:e} m short of the stop) σ_z = {:.3e} m, σ_φ = {sigma_phi}; \
             a flux σ_φ off over the standoff meets the stop at ≈ {:.4e} m/s (v_c = {:e} m/s){versus}",
            p.operation.name(),
            p.at * 1e3,
            p.approach.standoff,
            p.sigma_z,
            p.impact,
            p.approach.speed,
        );
    }
    s.push_str(
        "  the measurement noise's share of each first impact; a valve that differs from the description adds its own \
         (docs/guide/self-calibration.md#the-currents-noise-bounds-the-landing)",
    );
    Ok(Some(s))
}
