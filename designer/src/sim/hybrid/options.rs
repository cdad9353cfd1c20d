//! The simulator's settings, its failures, and the checks of the plant, the
//! options and the initial state before anything is integrated.

use thiserror::Error;

use super::quadrature::{plant_state, Ext, Quadrature, EXT, MAX_QUAD};
use crate::sim::rk::{Dopri5, RkError};
use crate::sim::{Limits, Mode, Plant, State, MAX_DIM};

/// Integration settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Relative tolerance (default 1e-8).
    pub rtol: f64,
    /// Absolute tolerance per plant state (default `rtol × plant.scale()`).
    pub atol: Option<State>,
    /// Largest step (default ∞).
    pub max_step: f64,
    /// Smallest step before giving up (default 0: only the ulp floor).
    pub min_step: f64,
    /// First step at the start and after every event (default: Hairer's
    /// heuristic at the start; after an event the step size in force, which
    /// fits the motion just before it better than the heuristic does).
    pub first_step: Option<f64>,
    /// Accepted plus rejected steps before giving up (default 1 000 000).
    pub max_steps: usize,
    /// Impacts at the same limit closer than this stick (default 1e-12 s).
    pub zeno_time: f64,
    /// Relative event-time tolerance: `event_tol·max(1, |t|)` (default 1e-13).
    pub event_tol: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            atol: None,
            max_step: f64::INFINITY,
            min_step: 0.0,
            first_step: None,
            max_steps: 1_000_000,
            zeno_time: 1e-12,
            event_tol: 1e-13,
        }
    }
}

/// Why a simulation failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SimError {
    #[error("invalid options: {0}")]
    Options(&'static str),
    #[error("invalid plant: {0}")]
    Plant(&'static str),
    #[error("invalid output times: {0}")]
    OutputTimes(&'static str),
    #[error("invalid initial state: {0}")]
    InitialState(&'static str),
    #[error("the input is not finite at t = {t}")]
    NonFiniteInput { t: f64 },
    #[error(transparent)]
    Integrator(#[from] RkError),
    #[error("more than {max} steps before t = {t}")]
    TooManySteps { t: f64, max: usize },
    #[error("more than {n} events at the single instant t = {t} (Zeno behaviour)")]
    EventLoop { t: f64, n: usize },
}

/// Validates the plant's dimension, quadrature count and limits.
pub(super) fn check_plant(pd: usize, nq: usize, lim: &Limits) -> Result<(), SimError> {
    if !(2..=MAX_DIM).contains(&pd) {
        return Err(SimError::Plant(
            "dim must lie in 2..=MAX_DIM (z and v first)",
        ));
    }
    if nq > MAX_QUAD {
        return Err(SimError::Plant("more quadratures than MAX_QUAD"));
    }
    if !(lim.z_min.is_finite() && lim.z_max.is_finite() && lim.z_min < lim.z_max) {
        return Err(SimError::Plant("limits must be finite with z_min < z_max"));
    }
    if !(lim.restitution >= 0.0 && lim.restitution.is_finite()) {
        return Err(SimError::Plant("restitution must be finite and ≥ 0"));
    }
    if !(lim.bounce_threshold >= 0.0) {
        return Err(SimError::Plant("bounce threshold must be ≥ 0"));
    }
    Ok(())
}

/// Builds the integrator with the tolerances of `opts`.
pub(super) fn make_rk<P: Plant, Q: Quadrature>(
    plant: &P,
    quad: &Q,
    opts: &Options,
) -> Result<Dopri5<EXT>, SimError> {
    let (pd, nq) = (plant.dim(), quad.len());
    if !(opts.rtol.is_finite() && opts.rtol >= 0.0) {
        return Err(SimError::Options("rtol must be finite and ≥ 0"));
    }
    if !(opts.max_step > 0.0 && opts.min_step >= 0.0 && opts.min_step.is_finite()) {
        return Err(SimError::Options(
            "max_step must be > 0 and min_step finite and ≥ 0",
        ));
    }
    if opts.first_step.is_some_and(|h| !(h > 0.0 && h.is_finite())) {
        return Err(SimError::Options("first_step must be positive and finite"));
    }
    if !(opts.zeno_time >= 0.0 && opts.event_tol >= 0.0) {
        return Err(SimError::Options("zeno_time and event_tol must be ≥ 0"));
    }
    let plant_atol = opts
        .atol
        .unwrap_or_else(|| plant.scale().map(|s| opts.rtol * s.abs()));
    let q_scale = quad.scale();
    let mut atol = [0.0; EXT];
    atol[..pd].copy_from_slice(&plant_atol[..pd]);
    for j in 0..nq {
        atol[pd + j] = opts.rtol * q_scale[j].abs();
    }
    if atol[..pd + nq].iter().any(|a| !(a.is_finite() && *a > 0.0)) {
        return Err(SimError::Options(
            "absolute tolerances must be positive and finite (check atol, rtol and the scales)",
        ));
    }
    let rk = Dopri5::new(pd + nq, opts.rtol, atol)
        .with_max_step(opts.max_step)
        .with_min_step(opts.min_step)
        .with_first_step(opts.first_step);
    Ok(rk)
}

/// Validates `x0` for `mode0` (a stuck mode pins `z` to its limit and `v` to 0).
pub(super) fn check_initial<P: Plant>(
    plant: &P,
    x: &mut Ext,
    mode0: Mode,
    lim: &Limits,
) -> Result<(), SimError> {
    let pd = plant.dim();
    if x[..pd].iter().any(|v| !v.is_finite()) {
        return Err(SimError::InitialState("not finite"));
    }
    match mode0 {
        Mode::StuckMin => (x[0], x[1]) = (lim.z_min, 0.0),
        Mode::StuckMax => (x[0], x[1]) = (lim.z_max, 0.0),
        Mode::Free => {
            if x[0] < lim.z_min || x[0] > lim.z_max {
                return Err(SimError::InitialState("z outside [z_min, z_max]"));
            }
        }
    }
    if !plant.in_domain(&plant_state(x, pd)) {
        return Err(SimError::InitialState("outside the plant's domain"));
    }
    Ok(())
}
