//! The model as a [`Plant`] for the hybrid simulator: compiled tapes of f and
//! of the coil outputs, the mechanical limits, state scales and domain.

use std::cell::RefCell;

use crate::description::{Core, Drive};
use crate::sim::{Limits, Plant, State, MAX_DIM};
use crate::sym::Tape;

use super::Model;

/// A model compiled for numerical work (parameters bound to their values).
pub struct ModelPlant {
    f: Tape,
    /// [coil current, coil voltage, F_mag]
    outputs: Tape,
    scratch_f: RefCell<Vec<f64>>,
    scratch_out: RefCell<Vec<f64>>,
    dim: usize,
    limits: Limits,
    scale: State,
    /// |φ| must stay below this (saturating core).
    flux_bound: Option<f64>,
}

/// Coil quantities at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoilOutputs {
    pub current: f64,
    pub voltage: f64,
    pub f_mag: f64,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlantError {
    #[error("state has {got} entries, the model has {expected} states")]
    WrongDimension { expected: usize, got: usize },
}

impl ModelPlant {
    pub fn new(model: &mut Model) -> ModelPlant {
        let f_exprs = model.f.clone();
        let f = model.compile(&f_exprs);
        let outputs = model.compile(&[model.current, model.voltage, model.f_mag]);
        let d = &model.description;
        let m = &d.mechanics;
        let limits = Limits {
            z_min: m.z_min,
            z_max: m.z_max,
            restitution: m.restitution,
            bounce_threshold: m.bounce_threshold,
        };
        let flux_bound = match d.core {
            Core::Saturating { phi_sat, .. } => Some(phi_sat),
            _ => None,
        };
        ModelPlant {
            scratch_f: RefCell::new(f.scratch()),
            scratch_out: RefCell::new(outputs.scratch()),
            f,
            outputs,
            dim: model.dim(),
            limits,
            scale: state_scale(model),
            flux_bound,
        }
    }

    /// Tape inputs (x, u, t). The model is defined on [z_min, z_max] (the
    /// McLyman logarithm is not, far below z_min): integrator stages that
    /// overshoot a limit within the step that locates the impact see the
    /// field extended by its value at the limit.
    fn inputs(&self, t: f64, x: &State, u: f64) -> [f64; MAX_DIM + 2] {
        let mut inputs = [0.0; MAX_DIM + 2];
        inputs[..self.dim].copy_from_slice(&x[..self.dim]);
        inputs[0] = x[0].clamp(self.limits.z_min, self.limits.z_max);
        inputs[self.dim] = u;
        inputs[self.dim + 1] = t;
        inputs
    }

    /// Coil current, coil voltage and magnetic force at (t, x, u).
    pub fn coil(&self, t: f64, x: &State, u: f64) -> CoilOutputs {
        let inputs = self.inputs(t, x, u);
        let mut out = [0.0; 3];
        self.outputs.eval(
            &inputs[..self.dim + 2],
            &mut self.scratch_out.borrow_mut(),
            &mut out,
        );
        CoilOutputs {
            current: out[0],
            voltage: out[1],
            f_mag: out[2],
        }
    }

    /// Instructions per evaluation of f (for benchmarks and reports).
    pub fn f_tape_len(&self) -> usize {
        self.f.len()
    }
}

impl Plant for ModelPlant {
    fn dim(&self) -> usize {
        self.dim
    }

    fn deriv(&self, t: f64, x: &State, u: f64, dx: &mut State) {
        let inputs = self.inputs(t, x, u);
        self.f.eval(
            &inputs[..self.dim + 2],
            &mut self.scratch_f.borrow_mut(),
            &mut dx[..self.dim],
        );
    }

    fn in_domain(&self, x: &State) -> bool {
        x[..self.dim].iter().all(|v| v.is_finite())
            && self.flux_bound.is_none_or(|b| x[2].abs() < b)
    }

    fn scale(&self) -> State {
        self.scale
    }

    fn limits(&self) -> Limits {
        self.limits
    }
}

/// Typical magnitudes of z, v, φ, H_c for absolute tolerances: the stroke, a
/// stroke per millisecond, the flux the largest input sustains at z_min (or
/// φ_sat), and the core field of the largest current.
fn state_scale(model: &Model) -> State {
    let d = &model.description;
    let stroke = d.mechanics.z_max - d.mechanics.z_min;
    let u_abs = d.supply.u_min.abs().max(d.supply.u_max.abs()).max(1e-12);
    let i_max = match d.supply.drive {
        Drive::Voltage => u_abs / d.coil.resistance,
        Drive::Current => u_abs,
    };
    let ampere_turns = d.coil.turns * i_max;
    let flux = match &d.core {
        Core::Saturating { phi_sat, .. } => *phi_sat,
        Core::Linear { r0 } => ampere_turns / r0.max(1.0),
        Core::JilesAtherton(ja) => MU0_SAT * ja.m_sat * ja.area,
    };
    let field = match &d.core {
        Core::JilesAtherton(ja) => ampere_turns / ja.length,
        _ => 1.0,
    };
    [stroke, stroke * 1e3, flux, field]
}

/// μ0, for the saturation flux density μ0·M_sat of the scale estimate.
const MU0_SAT: f64 = super::gap::MU0;
