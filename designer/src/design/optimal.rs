//! Energy-optimal soft-landing trajectory (perfect-tracking-soft-landing §4,
//! eqs. 58–66), by Pontryagin's principle and collocation.
//!
//! Minimise J = ∫ u² dt subject to ẋ = f(x, u), u_min ≤ u ≤ u_max,
//! x(t₀) = T⁻¹([z₀, 0, 0]), x(t_f) = T⁻¹([z_f, 0, 0]) (rest at both ends).
//! With H = u² + pᵀf(x, u) and f = f₀(x) + g(x)·u input-affine:
//!
//! - u* = clamp(−pᵀg/2, u_min, u_max) (H is convex in u; eq. 65);
//! - ẋ = ∂H/∂p = f(x, u*), ṗ = −∂H/∂x = −(∂f/∂x)ᵀp at u = u* (eq. 66): the
//!   term ∂H/∂u·∂u*/∂x vanishes (∂H/∂u = 0 where u* is interior, ∂u*/∂x = 0
//!   where it is clamped).
//!
//! Everything is derived by the symbolic core from the model's own f: the
//! costate symbols `p1`, `p2`, `p3`, u* as min(max(·)), the 6-state
//! Hamiltonian system and its 6×6 Jacobian (min/max differentiate to
//! selects). The two-point BVP is solved by [`solve_bvp`] with per-component
//! scaling (metres, m/s, webers and the costates differ by ~10 orders).
//!
//! **Initial guess** (flat parametrisation): the 5th-degree polynomial
//! reference z_r, x_r = T⁻¹(z_r, ż_r, z̈_r), u_r = α(x_r) + β(x_r)·z_r⁽³⁾; the
//! costate is the minimum-norm p with pᵀg = −2u_r (i.e. H stationary in u),
//! completed with [`CostateGuess::Chain`]: the costate equations solved
//! backwards along the integrator chain (the φ row gives p₂, the v row p₁,
//! with ṗ by finite differences on the mesh), or zero ([`CostateGuess::Zero`]).
//!
//! **Cost.** J is integrated on the collocation interpolant: u*(S(t)) with 5-
//! point Gauss–Legendre on every mesh interval, split at the switching times
//! (so the kinks of the clamp do not degrade the quadrature).
//!
//! **Reference for the controller.** z_r = z, ż_r = v, z̈_r = T₃(x) and the
//! jerk exactly from state and input: L_f³z(x) + L_g L_f²z(x)·u* (eq. 30).

// `!(x > 0)` is deliberate: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use std::cell::RefCell;
use std::collections::HashMap;

use crate::model::Model;
use crate::sym::{Id, Tape};

use super::bvp::{solve_bvp, BvpError, BvpOptions, BvpProblem, BvpSolution};
use super::linearization::Linearization;
use super::reference::{Flat, Polynomial, Reference};

/// How the costates p₁, p₂ of the initial guess are built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CostateGuess {
    /// Solve the costate equations along the integrator chain for p₂, p₁.
    Chain,
    /// p₁ = p₂ = 0 (only p₃ from pᵀg = −2u_r).
    Zero,
}

/// The optimal-control problem.
#[derive(Debug, Clone, PartialEq)]
pub struct OptimalSpec {
    pub z0: f64,
    pub zf: f64,
    pub t0: f64,
    pub tf: f64,
    /// Trajectory bounds on u (tighter than the supply, to leave a margin to
    /// the tracking controller).
    pub u_min: f64,
    pub u_max: f64,
    /// Collocation tolerance (RMS relative residual, scaled variables) and
    /// boundary tolerance.
    pub tol: f64,
    /// Nodes of the uniform initial mesh.
    pub nodes: usize,
    pub max_nodes: usize,
    pub costate_guess: CostateGuess,
}

impl OptimalSpec {
    /// Defaults: tol 1e-6, 151 initial nodes, at most 20000 nodes, chain costates.
    pub fn new(z0: f64, zf: f64, t0: f64, tf: f64, u_min: f64, u_max: f64) -> OptimalSpec {
        OptimalSpec {
            z0,
            zf,
            t0,
            tf,
            u_min,
            u_max,
            tol: 1e-6,
            nodes: 151,
            max_nodes: 20000,
            costate_guess: CostateGuess::Chain,
        }
    }
}

/// Why [`energy_optimal`] failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum OptimalError {
    #[error("the model has {0} states: the energy-optimal design needs the 3-state input-affine model [z, v, φ] (the Jiles–Atherton core is not input-affine)")]
    NotAffine(usize),
    #[error("invalid optimal-control problem: {0}")]
    InvalidSpec(String),
    #[error("the {which} state is infeasible: resting at z = {z:e} needs φ² = {flux_squared:e} (must be > 0, finite): the spring and preload cannot be balanced by a positive flux there")]
    InfeasibleBoundary {
        which: &'static str,
        z: f64,
        flux_squared: f64,
    },
    #[error("the initial guess is not finite at t = {t:e} ({what}): the polynomial reference leaves the domain of T⁻¹ (φ² ≤ 0); lengthen the motion")]
    Guess { t: f64, what: &'static str },
    #[error("the Hamiltonian boundary-value problem did not converge: {source}")]
    Bvp {
        #[source]
        source: BvpError,
    },
}

/// The symbolic Hamiltonian system compiled to tapes over
/// (z, v, φ, p₁, p₂, p₃, t), parameters bound, for fixed input bounds.
#[derive(Debug, Clone)]
pub struct HamiltonianSystem {
    /// [ẋ; ṗ] (6 outputs).
    pub rhs: Tape,
    /// ∂[ẋ; ṗ]/∂[x; p], row-major 6×6.
    pub jacobian: Tape,
    /// [u*, −pᵀg/2 (unclamped), a = T₃(x), jerk, H].
    pub aux: Tape,
    pub u_min: f64,
    pub u_max: f64,
    scratch: RefCell<(Vec<f64>, Vec<f64>)>,
}

/// Indices of [`HamiltonianSystem::aux`] outputs.
const AUX_U: usize = 0;
const AUX_RAW: usize = 1;
const AUX_A: usize = 2;
const AUX_JERK: usize = 3;
const AUX_H: usize = 4;

impl HamiltonianSystem {
    /// Derives the system symbolically from `model.f` and the linearization.
    pub fn derive(
        model: &mut Model,
        lin: &Linearization,
        u_min: f64,
        u_max: f64,
    ) -> Result<HamiltonianSystem, OptimalError> {
        if model.dim() != 3 || lin.system.input_field.len() != 3 {
            return Err(OptimalError::NotAffine(model.dim()));
        }
        if !(u_min < u_max) {
            return Err(OptimalError::InvalidSpec(format!(
                "u_min = {u_min} must be below u_max = {u_max}"
            )));
        }
        for name in ["p1", "p2", "p3"] {
            if model.params.symbol(name).is_some() {
                return Err(OptimalError::InvalidSpec(format!(
                    "a model parameter is named `{name}`, the costate symbol"
                )));
            }
        }
        let x: Vec<Id> = model.states.clone();
        let (u, t) = (model.input, model.time);
        let f = model.f.clone();
        let gfield = lin.system.input_field.clone();
        let g = &mut model.graph;
        let p = [g.symbol("p1"), g.symbol("p2"), g.symbol("p3")];
        // u* = clamp(−pᵀg/2, u_min, u_max)
        let pg_terms: Vec<Id> = p
            .iter()
            .zip(&gfield)
            .map(|(&pi, &gi)| g.mul(pi, gi))
            .collect();
        let pg = g.sum(&pg_terms);
        let raw = g.scale(-0.5, pg);
        let lo = g.constant(u_min);
        let hi = g.constant(u_max);
        let above = g.max(raw, lo);
        let ustar = g.min(above, hi);
        let to_ustar: HashMap<Id, Id> = std::iter::once((u, ustar)).collect();
        // ẋ = f(x, u*)
        let mut rhs: Vec<Id> = f.iter().map(|&fi| g.substitute(fi, &to_ustar)).collect();
        // ṗ = −(∂f/∂x)ᵀp at u*
        let a = g.jacobian(&f, &x);
        for k in 0..3 {
            let terms: Vec<Id> = (0..3).map(|i| g.mul(a[i][k], p[i])).collect();
            let s = g.sum(&terms);
            let s = g.substitute(s, &to_ustar);
            rhs.push(g.neg(s));
        }
        // H = u² + pᵀf
        let pf_terms: Vec<Id> = (0..3).map(|i| g.mul(p[i], rhs[i])).collect();
        let pf = g.sum(&pf_terms);
        let u2 = g.powi(ustar, 2);
        let h = g.add(u2, pf);
        let ju = g.mul(lin.lglf2h, ustar);
        let jerk = g.add(lin.lf3h, ju);
        let accel = lin.transform[2];
        let mut all = rhs.clone();
        all.extend([ustar, raw, accel, jerk, h]);
        let bound = model.bind_params(&all);
        let (rhs_b, aux_b) = bound.split_at(6);
        let y: Vec<Id> = x.iter().chain(p.iter()).copied().collect();
        let jac = model.graph.jacobian(rhs_b, &y);
        let jac_flat: Vec<Id> = jac.into_iter().flatten().collect();
        let mut inputs = y.clone();
        inputs.push(t);
        let compile = |outs: &[Id]| {
            Tape::compile(&model.graph, &inputs, outs).map_err(|e| {
                OptimalError::InvalidSpec(format!("the Hamiltonian system is not closed: {e}"))
            })
        };
        let rhs = compile(rhs_b)?;
        let jacobian = compile(&jac_flat)?;
        let aux = compile(aux_b)?;
        let scratch = RefCell::new((rhs.scratch(), jacobian.scratch()));
        Ok(HamiltonianSystem {
            rhs,
            jacobian,
            aux,
            u_min,
            u_max,
            scratch,
        })
    }

    fn inputs(t: f64, y: &[f64]) -> [f64; 7] {
        [y[0], y[1], y[2], y[3], y[4], y[5], t]
    }

    /// [u*, −pᵀg/2, a, jerk, H] at (t, [x; p]).
    pub fn aux_at(&self, t: f64, y: &[f64]) -> [f64; 5] {
        let mut out = [0.0; 5];
        self.aux
            .eval(&Self::inputs(t, y), &mut self.aux.scratch(), &mut out);
        out
    }
}

struct Problem<'a> {
    sys: &'a HamiltonianSystem,
    x0: [f64; 3],
    xf: [f64; 3],
}

impl BvpProblem for Problem<'_> {
    fn dim(&self) -> usize {
        6
    }

    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let mut s = self.sys.scratch.borrow_mut();
        self.sys
            .rhs
            .eval(&HamiltonianSystem::inputs(t, y), &mut s.0, dy);
    }

    fn jacobian(&self, t: f64, y: &[f64], j: &mut [f64]) {
        let mut s = self.sys.scratch.borrow_mut();
        self.sys
            .jacobian
            .eval(&HamiltonianSystem::inputs(t, y), &mut s.1, j);
    }

    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]) {
        for k in 0..3 {
            r[k] = ya[k] - self.x0[k];
            r[3 + k] = yb[k] - self.xf[k];
        }
    }

    fn bc_jacobian(&self, _ya: &[f64], _yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        ja.iter_mut().for_each(|v| *v = 0.0);
        jb.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..3 {
            ja[k * 6 + k] = 1.0;
            jb[(3 + k) * 6 + k] = 1.0;
        }
    }
}

/// Where u* enters or leaves a bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Switch {
    pub t: f64,
    /// The bound (u_min or u_max).
    pub bound: f64,
    /// true: u* becomes saturated at `t`; false: it leaves saturation.
    pub entering: bool,
}

/// The energy-optimal trajectory.
#[derive(Debug, Clone)]
pub struct OptimalTrajectory {
    /// The final collocation mesh.
    pub t: Vec<f64>,
    /// x = [z, v, φ] at the nodes.
    pub states: Vec<[f64; 3]>,
    /// p at the nodes.
    pub costates: Vec<[f64; 3]>,
    /// u* at the nodes.
    pub input: Vec<f64>,
    /// H at the nodes (constant for an autonomous model).
    pub hamiltonian: Vec<f64>,
    /// z_r, ż_r, z̈_r, z_r⁽³⁾ at the nodes (a = T₃(x), jerk = L_f³z + L_gL_f²z·u*).
    pub reference: Vec<Flat>,
    /// J = ∫u*² dt (Gauss–Legendre on the interpolant, split at the switches).
    pub cost: f64,
    /// ∫u_r² dt of the polynomial initial guess.
    pub guess_cost: f64,
    /// max |u_r| of the polynomial guess (it may violate the bounds).
    pub guess_max_abs_input: f64,
    pub max_abs_input: f64,
    pub switches: Vec<Switch>,
    pub x0: [f64; 3],
    pub xf: [f64; 3],
    pub max_residual: f64,
    pub bc_residual: f64,
    pub newton_iterations: usize,
    pub mesh_refinements: usize,
    /// The collocation solution (its cubic interpolant S(t)).
    pub solution: BvpSolution,
    pub spec: OptimalSpec,
    aux: Tape,
}

impl OptimalTrajectory {
    pub fn nodes(&self) -> usize {
        self.t.len()
    }

    /// [u*, −pᵀg/2, a, jerk, H] on the interpolant at t ∈ [t₀, t_f].
    fn aux_at(&self, t: f64) -> [f64; 5] {
        let y = self.solution.eval(t);
        let mut out = [0.0; 5];
        let inp = [y[0], y[1], y[2], y[3], y[4], y[5], t];
        self.aux.eval(&inp, &mut self.aux.scratch(), &mut out);
        out
    }

    /// u*(t) on the interpolant (0 outside [t₀, t_f] is *not* implied: the
    /// value at the nearest end is returned, which holds the rest state).
    pub fn input_at(&self, t: f64) -> f64 {
        self.aux_at(t.clamp(self.spec.t0, self.spec.tf))[AUX_U]
    }

    /// H on the interpolant.
    pub fn hamiltonian_at(&self, t: f64) -> f64 {
        self.aux_at(t)[AUX_H]
    }

    /// [x; p] on the interpolant.
    pub fn y_at(&self, t: f64) -> Vec<f64> {
        self.solution.eval(t)
    }

    /// A JSON summary (figures for reports and the oracle comparison).
    pub fn summary_json(&self) -> serde_json::Value {
        serde_json::json!({
            "cost": self.cost,
            "guess_cost": self.guess_cost,
            "guess_max_abs_input": self.guess_max_abs_input,
            "max_abs_input": self.max_abs_input,
            "switches": self.switches.iter().map(|s| serde_json::json!({
                "t": s.t, "bound": s.bound, "entering": s.entering,
            })).collect::<Vec<_>>(),
            "nodes": self.nodes(),
            "max_residual": self.max_residual,
            "bc_residual": self.bc_residual,
            "newton_iterations": self.newton_iterations,
            "x0": self.x0,
            "xf": self.xf,
        })
    }
}

impl Reference for OptimalTrajectory {
    /// Rest at z₀ before t₀ and at z_f after t_f, the optimal motion between.
    fn at(&self, t: f64) -> Flat {
        let (t0, tf) = (self.spec.t0, self.spec.tf);
        if t <= t0 || t >= tf {
            let z = if t <= t0 { self.spec.z0 } else { self.spec.zf };
            return Flat {
                z,
                v: 0.0,
                a: 0.0,
                jerk: 0.0,
            };
        }
        let y = self.solution.eval(t);
        let aux = self.aux_at(t);
        Flat {
            z: y[0],
            v: y[1],
            a: aux[AUX_A],
            jerk: aux[AUX_JERK],
        }
    }

    fn motion(&self) -> (f64, f64) {
        (self.spec.t0, self.spec.tf)
    }
}

/// 5-point Gauss–Legendre nodes and weights on [−1, 1].
const GL5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

fn gauss5(a: f64, b: f64, f: &mut dyn FnMut(f64) -> f64) -> f64 {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    GL5.iter().map(|&(x, w)| w * f(c + h * x)).sum::<f64>() * h
}

/// Derivative of samples on a (uniform or not) mesh: central differences
/// inside, second-order one-sided at the ends.
fn gradient(t: &[f64], y: &[f64]) -> Vec<f64> {
    let m = t.len();
    let mut d = vec![0.0; m];
    for i in 1..m - 1 {
        let (h0, h1) = (t[i] - t[i - 1], t[i + 1] - t[i]);
        d[i] = (h0 * h0 * y[i + 1] - h1 * h1 * y[i - 1] + (h1 * h1 - h0 * h0) * y[i])
            / (h0 * h1 * (h0 + h1));
    }
    let h = t[1] - t[0];
    d[0] = (-3.0 * y[0] + 4.0 * y[1] - y[2]) / (2.0 * h);
    let h = t[m - 1] - t[m - 2];
    d[m - 1] = (3.0 * y[m - 1] - 4.0 * y[m - 2] + y[m - 3]) / (2.0 * h);
    d
}

/// The initial guess: mesh, [x; p] per node, and ∫u_r² dt.
struct Guess {
    t: Vec<f64>,
    y: Vec<Vec<f64>>,
    /// Costates of the chain construction (for scaling even when not used).
    chain: Vec<[f64; 3]>,
    cost: f64,
    max_abs_u: f64,
}

fn initial_guess(
    model: &mut Model,
    lin: &Linearization,
    spec: &OptimalSpec,
) -> Result<Guess, OptimalError> {
    // (α, β, ∂f/∂x (9), g (3)) over (z, v, φ, u, t), and T⁻¹ over ξ.
    let a = model.jacobian();
    let mut outs = vec![lin.alpha, lin.beta];
    outs.extend(a.into_iter().flatten());
    outs.extend(lin.system.input_field.iter().copied());
    let tape = model.compile(&outs);
    let mut inv = lin.inverse.to_vec();
    inv.push(lin.flux_squared);
    let inv = model.bind_params(&inv);
    let inv_tape = Tape::compile(&model.graph, &lin.xi, &inv)
        .map_err(|e| OptimalError::InvalidSpec(format!("T⁻¹ is not closed: {e}")))?;
    let reference = Polynomial {
        z0: spec.z0,
        zf: spec.zf,
        t0: spec.t0,
        tf: spec.tf,
    };
    let duration = spec.tf - spec.t0;
    let eps = 1e-9 * duration;
    // x_r, u_r and the model Jacobian at time t
    let at = |t: f64| -> Result<([f64; 3], f64, Vec<f64>), OptimalError> {
        let r = reference.at(t);
        // the polynomial's jerk at the ends is its one-sided limit
        let jerk = reference.at(t.clamp(spec.t0 + eps, spec.tf - eps)).jerk;
        let mut xr = [0.0; 4];
        inv_tape.eval(&[r.z, r.v, r.a], &mut inv_tape.scratch(), &mut xr);
        if !(xr[3] > 0.0) || !xr[2].is_finite() {
            return Err(OptimalError::Guess {
                t, what: "φ² ≤ 0"
            });
        }
        let mut o = vec![0.0; tape.n_outputs()];
        tape.eval(&[xr[0], xr[1], xr[2], 0.0, t], &mut tape.scratch(), &mut o);
        let u = o[0] + o[1] * jerk;
        if !u.is_finite() {
            return Err(OptimalError::Guess { t, what: "u_r" });
        }
        // ∂f/∂x at u_r: f is affine in u, so recompute with u
        tape.eval(&[xr[0], xr[1], xr[2], u, t], &mut tape.scratch(), &mut o);
        Ok(([xr[0], xr[1], xr[2]], u, o[2..].to_vec()))
    };
    let m = spec.nodes.max(5);
    let t: Vec<f64> = (0..m)
        .map(|i| spec.t0 + duration * i as f64 / (m - 1) as f64)
        .collect();
    let mut xs = Vec::with_capacity(m);
    let mut us = Vec::with_capacity(m);
    let mut jacs = Vec::with_capacity(m);
    for &ti in &t {
        let (x, u, o) = at(ti)?;
        xs.push(x);
        us.push(u);
        jacs.push(o);
    }
    // ∫u_r² dt by composite Simpson on a fine grid (u_r is smooth)
    let fine = 2000;
    let mut cost = 0.0;
    let mut max_abs_u = 0.0f64;
    for k in 0..=fine {
        let tk = spec.t0 + duration * k as f64 / fine as f64;
        let w = if k == 0 || k == fine {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let u = at(tk)?.1;
        max_abs_u = max_abs_u.max(u.abs());
        cost += w * u * u;
    }
    cost *= duration / fine as f64 / 3.0;
    // p_g = −2u_r·g/|g|² (H stationary in u), then the chain
    let p_from_u: Vec<[f64; 3]> = jacs
        .iter()
        .zip(&us)
        .map(|(o, &u)| {
            let g = [o[9], o[10], o[11]];
            let g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
            [
                -2.0 * u * g[0] / g2,
                -2.0 * u * g[1] / g2,
                -2.0 * u * g[2] / g2,
            ]
        })
        .collect();
    let p3: Vec<f64> = p_from_u.iter().map(|p| p[2]).collect();
    let dp3 = gradient(&t, &p3);
    // ṗ₃ = −(A₀₂p₁ + A₁₂p₂ + A₂₂p₃) with A₀₂ = ∂ż/∂φ = 0
    let p2: Vec<f64> = (0..m)
        .map(|i| {
            let a = &jacs[i];
            -(dp3[i] + a[2 * 3 + 2] * p3[i]) / a[3 + 2]
        })
        .collect();
    let dp2 = gradient(&t, &p2);
    // ṗ₂ = −(A₀₁p₁ + A₁₁p₂ + A₂₁p₃)
    let p1: Vec<f64> = (0..m)
        .map(|i| {
            let a = &jacs[i];
            -(dp2[i] + a[3 + 1] * p2[i] + a[2 * 3 + 1] * p3[i]) / a[1]
        })
        .collect();
    let chain_ok = jacs
        .iter()
        .all(|a| a[2] == 0.0 && a[5] != 0.0 && a[1] != 0.0)
        && p1.iter().chain(&p2).all(|v| v.is_finite());
    let chain: Vec<[f64; 3]> = (0..m)
        .map(|i| {
            if chain_ok {
                [p1[i], p2[i], p3[i]]
            } else {
                p_from_u[i]
            }
        })
        .collect();
    let y = (0..m)
        .map(|i| {
            let p = match spec.costate_guess {
                CostateGuess::Chain => chain[i],
                CostateGuess::Zero => p_from_u[i],
            };
            vec![xs[i][0], xs[i][1], xs[i][2], p[0], p[1], p[2]]
        })
        .collect();
    Ok(Guess {
        t,
        y,
        chain,
        cost,
        max_abs_u,
    })
}

/// Rest state T⁻¹([z, 0, 0]).
fn rest_state(
    model: &mut Model,
    lin: &Linearization,
    z: f64,
    which: &'static str,
) -> Result<[f64; 3], OptimalError> {
    let mut inv = lin.inverse.to_vec();
    inv.push(lin.flux_squared);
    let inv = model.bind_params(&inv);
    let tape = Tape::compile(&model.graph, &lin.xi, &inv)
        .map_err(|e| OptimalError::InvalidSpec(format!("T⁻¹ is not closed: {e}")))?;
    let mut x = [0.0; 4];
    tape.eval(&[z, 0.0, 0.0], &mut tape.scratch(), &mut x);
    if !(x[3] > 0.0) || !x[3].is_finite() {
        return Err(OptimalError::InfeasibleBoundary {
            which,
            z,
            flux_squared: x[3],
        });
    }
    Ok([x[0], x[1], x[2]])
}

/// Solves the energy-optimal problem (eqs. 58–66) for `model`.
pub fn energy_optimal(
    model: &mut Model,
    lin: &Linearization,
    spec: &OptimalSpec,
) -> Result<OptimalTrajectory, OptimalError> {
    if !(spec.tf > spec.t0) || !(spec.zf != spec.z0) || !(spec.tol > 0.0) {
        return Err(OptimalError::InvalidSpec(format!(
            "need t_f > t₀, z_f ≠ z₀ and tol > 0 (got t₀ = {}, t_f = {}, z₀ = {}, z_f = {}, tol = {})",
            spec.t0, spec.tf, spec.z0, spec.zf, spec.tol
        )));
    }
    let sys = HamiltonianSystem::derive(model, lin, spec.u_min, spec.u_max)?;
    let x0 = rest_state(model, lin, spec.z0, "initial")?;
    let xf = rest_state(model, lin, spec.zf, "final")?;
    let guess = initial_guess(model, lin, spec)?;
    // scales
    let stroke = (spec.zf - spec.z0).abs();
    let duration = spec.tf - spec.t0;
    let max_of = |k: usize| guess.y.iter().map(|y| y[k].abs()).fold(0.0, f64::max);
    let phi_scale = max_of(2);
    let mut scale = vec![stroke, 2.0 * stroke / duration, phi_scale];
    for k in 0..3 {
        let s = guess.chain.iter().map(|p| p[k].abs()).fold(0.0, f64::max);
        scale.push(if s > 0.0 && s.is_finite() { s } else { 1.0 });
    }
    let bc_scale = [scale[0], scale[1], scale[2], scale[0], scale[1], scale[2]].to_vec();
    let opts = BvpOptions {
        tol: spec.tol,
        max_nodes: spec.max_nodes,
        scale: Some(scale),
        bc_scale: Some(bc_scale),
        ..BvpOptions::default()
    };
    let problem = Problem { sys: &sys, x0, xf };
    let sol = solve_bvp(&problem, &guess.t, &guess.y, &opts)
        .map_err(|source| OptimalError::Bvp { source })?;

    let aux: Vec<[f64; 5]> = sol
        .t
        .iter()
        .zip(&sol.y)
        .map(|(&t, y)| sys.aux_at(t, y))
        .collect();
    let mut traj = OptimalTrajectory {
        t: sol.t.clone(),
        states: sol.y.iter().map(|y| [y[0], y[1], y[2]]).collect(),
        costates: sol.y.iter().map(|y| [y[3], y[4], y[5]]).collect(),
        input: aux.iter().map(|a| a[AUX_U]).collect(),
        hamiltonian: aux.iter().map(|a| a[AUX_H]).collect(),
        reference: sol
            .y
            .iter()
            .zip(&aux)
            .map(|(y, a)| Flat {
                z: y[0],
                v: y[1],
                a: a[AUX_A],
                jerk: a[AUX_JERK],
            })
            .collect(),
        cost: 0.0,
        guess_cost: guess.cost,
        guess_max_abs_input: guess.max_abs_u,
        max_abs_input: 0.0,
        switches: Vec::new(),
        x0,
        xf,
        max_residual: sol.max_residual,
        bc_residual: sol.bc_residual,
        newton_iterations: sol.newton_iterations,
        mesh_refinements: sol.mesh_refinements,
        solution: sol,
        spec: spec.clone(),
        aux: sys.aux.clone(),
    };
    locate_switches(&mut traj);
    integrate_cost(&mut traj);
    Ok(traj)
}

/// Switching times: sign changes of (raw − u_max) and (raw − u_min) on the
/// interpolant, sampled at 8 sub-points per interval, refined by bisection.
fn locate_switches(traj: &mut OptimalTrajectory) {
    let (lo, hi) = (traj.spec.u_min, traj.spec.u_max);
    let sub = 8;
    let mut samples = Vec::new();
    for w in traj.t.windows(2) {
        for k in 0..sub {
            samples.push(w[0] + (w[1] - w[0]) * k as f64 / sub as f64);
        }
    }
    samples.push(*traj.t.last().unwrap());
    let raw: Vec<f64> = samples.iter().map(|&t| traj.aux_at(t)[AUX_RAW]).collect();
    let mut switches = Vec::new();
    for bound in [lo, hi] {
        for i in 0..samples.len() - 1 {
            let (fa, fb) = (raw[i] - bound, raw[i + 1] - bound);
            if (fa < 0.0) == (fb < 0.0) {
                continue;
            }
            let (mut a, mut b) = (samples[i], samples[i + 1]);
            for _ in 0..60 {
                let c = 0.5 * (a + b);
                if ((traj.aux_at(c)[AUX_RAW] - bound) < 0.0) == (fa < 0.0) {
                    a = c;
                } else {
                    b = c;
                }
            }
            // entering saturation: raw crosses the bound outwards
            let entering = if bound == hi { fb >= 0.0 } else { fb < 0.0 };
            switches.push(Switch {
                t: 0.5 * (a + b),
                bound,
                entering,
            });
        }
    }
    switches.sort_by(|a, b| a.t.total_cmp(&b.t));
    traj.switches = switches;
}

/// J = ∫u*² dt and max|u*| on the interpolant (Gauss–Legendre per interval,
/// split at the switches; max over the GL points, the nodes and the switches).
fn integrate_cost(traj: &mut OptimalTrajectory) {
    let mut cost = 0.0;
    let mut umax = traj.input.iter().fold(0.0f64, |m, u| m.max(u.abs()));
    let sw: Vec<f64> = traj.switches.iter().map(|s| s.t).collect();
    let t = traj.t.clone();
    for w in t.windows(2) {
        let mut cuts = vec![w[0]];
        cuts.extend(sw.iter().copied().filter(|&s| s > w[0] && s < w[1]));
        cuts.push(w[1]);
        for c in cuts.windows(2) {
            cost += gauss5(c[0], c[1], &mut |tt| {
                let u = traj.aux_at(tt)[AUX_U];
                umax = umax.max(u.abs());
                u * u
            });
        }
    }
    traj.cost = cost;
    traj.max_abs_input = umax;
}
