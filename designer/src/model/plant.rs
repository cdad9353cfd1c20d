//! The model as a [`Plant`] for the hybrid simulator: compiled tapes of f and
//! of the coil outputs, the mechanical limits, state scales and domain.
//!
//! Replaying an experiment evaluates the coil at every output time, so the
//! plant keeps a second, minimal tape for that: only the coil quantity that is
//! not the input itself (the current under voltage drive, the voltage under
//! current drive), evaluated for all output times at once.
//!
//! **Switching.** Every `sign(s)` in f (the Jiles–Atherton branch
//! δ = sign(φ̇)) becomes an extra input of the f tape, a branch, and `s` a
//! switching function with a tape of its own (see [`Plant::switches`]): the
//! simulator holds the branch during a step and switches at the located zero
//! crossing, so that it integrates a smooth field. [`Plant::deriv`] feeds the
//! live signs.
//!
//! **Beyond the stops.** The model is only defined on [z_min, z_max] (the
//! McLyman logarithm is not, below z_min), but the stages of a step that
//! crosses a stop, before the impact is located, evaluate f beyond it. There f
//! is continued by its tangent in z at the stop, f(z_c) + (z − z_c)·∂f/∂z(z_c):
//! a C¹ continuation, so that such a step's error estimate stays meaningful
//! (a constant continuation is only C⁰ and gets the step rejected). The coil
//! outputs and switching functions use the value at the stop.
//!
//! Every tape has its own scratch buffer, so successive evaluations skip what
//! depends only on unchanged inputs (see [`Tape::eval`]).

use std::cell::RefCell;
use std::collections::HashMap;

use crate::description::{Core, Drive};
use crate::sim::{Branches, Limits, Plant, State, MAX_DIM, MAX_SWITCHES};
use crate::sym::{Func, Id, Node, Tape};

use super::Model;

/// Tape inputs: states, u, t, then one branch per switching function.
const MAX_INPUTS: usize = MAX_DIM + 2 + MAX_SWITCHES;

/// A tape with a scratch buffer of its own.
struct Compiled {
    tape: Tape,
    scratch: RefCell<Vec<f64>>,
}

impl Compiled {
    fn new(tape: Tape) -> Self {
        let scratch = RefCell::new(tape.scratch());
        Self { tape, scratch }
    }

    /// Evaluates with the first `n_inputs` of `inputs`.
    fn eval(&self, inputs: &[f64], out: &mut [f64]) {
        let n = self.tape.n_inputs();
        self.tape
            .eval(&inputs[..n], &mut self.scratch.borrow_mut(), out);
    }
}

/// A model compiled for numerical work (parameters bound to their values).
pub struct ModelPlant {
    /// f(x, u, t, branches): f with each `sign(s_j)` replaced by a branch input.
    f: Compiled,
    /// ∂f/∂z (same inputs), for the continuation beyond the stops.
    f_z: Compiled,
    /// f[1] alone (same inputs), for the lift-off guard.
    accel: Compiled,
    /// f[2..] (same inputs): the field while resting on a stop.
    resting: Compiled,
    /// For each switching function, the component of f equal to it, if any.
    switching_components: [Option<usize>; MAX_SWITCHES],
    /// The switching functions s_j(x, u, t) (no outputs without switching).
    switching: Compiled,
    /// [coil current, coil voltage, F_mag]
    outputs: Compiled,
    /// The coil quantity that is not the input: current (voltage drive) or
    /// voltage (current drive).
    electrical: Compiled,
    drive: Drive,
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
        let locked = lock_signs(model);
        let [f, f_z, accel, resting] = compile_field(model, &locked);
        let drive = model.description.supply.drive;
        let electrical = match drive {
            Drive::Voltage => model.current,
            Drive::Current => model.voltage,
        };
        let outputs = [model.current, model.voltage, model.f_mag];
        ModelPlant {
            f,
            f_z,
            accel,
            resting,
            switching_components: switching_components(&locked),
            switching: Compiled::new(model.compile(&locked.switching)),
            outputs: Compiled::new(model.compile(&outputs)),
            electrical: Compiled::new(model.compile(&[electrical])),
            drive,
            dim: model.dim(),
            limits: limits(model),
            scale: state_scale(model),
            flux_bound: match model.description.core {
                Core::Saturating { phi_sat, .. } => Some(phi_sat),
                _ => None,
            },
        }
    }

    /// Tape inputs (x, u, t, then `branch`) with z held at the nearest stop.
    fn inputs(&self, t: f64, x: &State, u: f64, branch: &Branches) -> [f64; MAX_INPUTS] {
        let d = self.dim;
        // Element by element (no stores at a run-time offset that the
        // caller then reads back as wide loads: they stalled store
        // forwarding, 7 % of a diagnosis).
        std::array::from_fn(|i| match i {
            0 => x[0].clamp(self.limits.z_min, self.limits.z_max),
            i if i < d => x[i],
            i if i == d => u,
            i if i == d + 1 => t,
            i => branch.get(i - d - 2).copied().unwrap_or(0.0),
        })
    }

    /// Coil current, coil voltage and magnetic force at (t, x, u).
    pub fn coil(&self, t: f64, x: &State, u: f64) -> CoilOutputs {
        let mut out = [0.0; 3];
        self.outputs
            .eval(&self.inputs(t, x, u, &NO_BRANCH), &mut out);
        CoilOutputs {
            current: out[0],
            voltage: out[1],
            f_mag: out[2],
        }
    }

    /// (coil current, coil voltage) at (t, x, u): one of them is `u` itself,
    /// the other comes from a tape of its own (cheaper than [`coil`](Self::coil)).
    pub fn current_and_voltage(&self, t: f64, x: &State, u: f64) -> (f64, f64) {
        let mut out = [0.0];
        self.electrical
            .eval(&self.inputs(t, x, u, &NO_BRANCH), &mut out);
        self.with_input(out[0], u)
    }

    /// (current, voltage) from the non-input one and the input.
    fn with_input<T>(&self, other: T, u: T) -> (T, T) {
        match self.drive {
            Drive::Voltage => (other, u),
            Drive::Current => (u, other),
        }
    }

    /// [`current_and_voltage`](Self::current_and_voltage) at every point
    /// `(t[k], x[k], u[k])`, evaluated in groups (much faster for many points).
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn currents_and_voltages(&self, t: &[f64], x: &[State], u: &[f64]) -> (Vec<f64>, Vec<f64>) {
        assert!(
            t.len() == x.len() && t.len() == u.len(),
            "one t, x and u per point"
        );
        let (lo, hi) = (self.limits.z_min, self.limits.z_max);
        let z: Vec<f64> = x.iter().map(|x| x[0].clamp(lo, hi)).collect();
        let states = x.as_flattened();
        let mut columns = vec![(z.as_slice(), 1, 0)];
        columns.extend((1..self.dim).map(|i| (states, MAX_DIM, i)));
        columns.extend([(u, 1, 0), (t, 1, 0)]);
        let mut other = vec![0.0; t.len()];
        self.electrical.tape.eval_many(&columns, &mut other);
        self.with_input(other, u.to_vec())
    }

    /// Instructions per evaluation of f on a held branch (for benchmarks and
    /// reports).
    pub fn f_tape_len(&self) -> usize {
        self.f.tape.len()
    }
}

/// The tapes of f, ∂f/∂z, f[1] and f[2..], all of (x, u, t, branches).
fn compile_field(model: &mut Model, locked: &Locked) -> [Compiled; 4] {
    let z = model.states[0];
    let f_z: Vec<Id> = locked.f.iter().map(|&e| model.graph.diff(e, z)).collect();
    let mut inputs = model.tape_inputs();
    inputs.extend(&locked.branches);
    let exprs: [&[Id]; 4] = [&locked.f, &f_z, &locked.f[1..2], &locked.f[2..]];
    exprs.map(|e| {
        let bound = model.bind_params(e);
        let tape = Tape::compile(&model.graph, &inputs, &bound)
            .expect("f only uses states, u, t, branches and parameters");
        Compiled::new(tape)
    })
}

/// For each switching function s_j, the component of f equal to it, if any:
/// s_j = f_i exactly when f_i is the very expression (then it holds no
/// branch: a sign inside s_j would have been replaced in f_i).
fn switching_components(locked: &Locked) -> [Option<usize>; MAX_SWITCHES] {
    let mut components = [None; MAX_SWITCHES];
    for (c, s) in components.iter_mut().zip(&locked.switching) {
        *c = (2..locked.f.len()).find(|&i| locked.f[i] == *s);
    }
    components
}

fn limits(model: &Model) -> Limits {
    let m = &model.description.mechanics;
    Limits {
        z_min: m.z_min,
        z_max: m.z_max,
        restitution: m.restitution,
        bounce_threshold: m.bounce_threshold,
    }
}

/// Branch inputs of tapes that have none.
const NO_BRANCH: Branches = [0.0; MAX_SWITCHES];

/// f with its `sign(·)` nodes held on branches (see [`lock_signs`]).
struct Locked {
    f: Vec<Id>,
    /// The argument of each replaced sign: its switching function.
    switching: Vec<Id>,
    /// The branch symbol of each replaced sign.
    branches: Vec<Id>,
}

/// Replaces the first [`MAX_SWITCHES`] `sign(s)` nodes of f by branch
/// symbols (any further ones stay live). Only signs: the held branch of a
/// `max`/`min` clamp (the Jiles–Atherton [JA 52]) is not a usable continuation
/// beyond its switch (it heads for a division by zero), and the model's
/// `select`s join smooth pieces or the two forms of one smooth function.
fn lock_signs(model: &mut Model) -> Locked {
    let f = model.f.clone();
    let g = &mut model.graph;
    let signs: Vec<(Id, Id)> = g
        .postorder(&f)
        .into_iter()
        .filter_map(|n| match *g.node(n) {
            Node::Func(Func::Sign, s) => Some((n, s)),
            _ => None,
        })
        .take(MAX_SWITCHES)
        .collect();
    let branches: Vec<Id> = (0..signs.len())
        .map(|j| g.symbol(&format!("sign_branch_{j}")))
        .collect();
    let map: HashMap<Id, Id> = signs
        .iter()
        .map(|&(n, _)| n)
        .zip(branches.iter().copied())
        .collect();
    Locked {
        f: g.substitute_all(&f, &map),
        switching: signs.iter().map(|&(_, s)| s).collect(),
        branches,
    }
}

impl Plant for ModelPlant {
    fn dim(&self) -> usize {
        self.dim
    }

    fn deriv(&self, t: f64, x: &State, u: f64, dx: &mut State) {
        let mut branch = [0.0; MAX_SWITCHES];
        self.switching(t, x, u, &mut branch);
        for b in &mut branch {
            *b = crate::sym::sign(*b);
        }
        self.deriv_branch(t, x, u, &branch, dx);
    }

    fn switches(&self) -> usize {
        self.switching.tape.n_outputs()
    }

    fn switching(&self, t: f64, x: &State, u: f64, s: &mut Branches) {
        let n = self.switches();
        if n > 0 {
            self.switching
                .eval(&self.inputs(t, x, u, &NO_BRANCH), &mut s[..n]);
        }
    }

    fn deriv_branch(&self, t: f64, x: &State, u: f64, branch: &Branches, dx: &mut State) {
        let inputs = self.inputs(t, x, u, branch);
        let d = self.dim;
        self.f.eval(&inputs, &mut dx[..d]);
        let beyond = x[0] - inputs[0];
        if beyond != 0.0 {
            let mut slope = [0.0; MAX_DIM];
            self.f_z.eval(&inputs, &mut slope[..d]);
            for (dxi, si) in dx[..d].iter_mut().zip(&slope) {
                *dxi += beyond * si;
            }
        }
    }

    fn deriv_resting(&self, t: f64, x: &State, u: f64, branch: &Branches, dx: &mut State) {
        let inputs = self.inputs(t, x, u, branch);
        if inputs[0] != x[0] {
            return self.deriv_branch(t, x, u, branch, dx);
        }
        self.resting.eval(&inputs, &mut dx[2..self.dim]);
    }

    fn switching_component(&self, j: usize) -> Option<usize> {
        self.switching_components.get(j).copied().flatten()
    }

    fn accel_branch(&self, t: f64, x: &State, u: f64, branch: &Branches) -> f64 {
        let inputs = self.inputs(t, x, u, branch);
        if inputs[0] != x[0] {
            let mut dx = [0.0; MAX_DIM];
            self.deriv_branch(t, x, u, branch, &mut dx);
            return dx[1];
        }
        let mut a = [0.0];
        self.accel.eval(&inputs, &mut a);
        a[0]
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

    /// Beyond the stops f is its tangent in z (see the module docs).
    fn smooth_beyond_limits(&self) -> bool {
        true
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
