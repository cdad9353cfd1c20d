//! Energy-optimal soft-landing trajectory (perfect-tracking-soft-landing [PT §4],
//! [PT 58–66]), by Pontryagin's principle and collocation.
//!
//! Minimise J = ∫ u² dt subject to ẋ = f(x, u), u_min ≤ u ≤ u_max,
//! x(t₀) = T⁻¹([z₀, 0, 0]), x(t_f) = T⁻¹([z_f, 0, 0]) (rest at both ends).
//! With H = u² + pᵀf(x, u) and f = f₀(x) + g(x)·u input-affine:
//!
//! - u* = clamp(−pᵀg/2, u_min, u_max) (H is convex in u; [PT 65]);
//! - ẋ = ∂H/∂p = f(x, u*), ṗ = −∂H/∂x = −(∂f/∂x)ᵀp at u = u* ([PT 66]): the
//!   term ∂H/∂u·∂u*/∂x vanishes (∂H/∂u = 0 where u* is interior, ∂u*/∂x = 0
//!   where it is clamped).
//!
//! Everything is derived by the symbolic core from the model's own f: the
//! costate symbols `p1`, `p2`, `p3`, u* as min(max(·)), the 6-state
//! Hamiltonian system and its 6×6 Jacobian (min/max differentiate to
//! selects). The two-point BVP is solved by [`solve_bvp`] with per-component
//! scaling (metres, m/s, webers and the costates differ by ~10 orders).
//!
//! **Limits of the stroke** [PT 57]: a slow motion's free extremal arrives early
//! and hovers at the stop; the optimum is then a shorter free arc with rest at
//! the cheaper end (`optimal/search.rs`). **Initial guess**: the polynomial
//! reference through T⁻¹ (`optimal/guess.rs`).
//!
//! **Tabulated gaps** interpolated C¹ (Hermite through `r_prime`, PCHIP) have
//! a discontinuous R_gap″, which enters the costate equations: the arc is
//! solved on the C² quintic Hermite through the same (z, r, r′) instead
//! (`model/table.rs`), and the trajectory says so ([`OptimalTrajectory::smoothed_gap`]).
//!
//! **Cost.** J is integrated on the collocation interpolant: u*(S(t)) with 5-
//! point Gauss–Legendre on every mesh interval, split at the switching times
//! (so the kinks of the clamp do not degrade the quadrature), plus the rest
//! input's cost where the motion rests.
//!
//! **Reference for the controller.** z_r = z, ż_r = v, z̈_r = T₃(x) and the
//! jerk exactly from state and input: L_f³z(x) + L_g L_f²z(x)·u* ([PT 30]).

// `!(x > 0)` is deliberate: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub(in crate::design) mod guess;
pub(in crate::design) mod problem;
pub(in crate::design) mod robust;
pub(in crate::design) mod search;

use crate::design::derive::linearization::Linearization;
use crate::model::Model;
use crate::sym::Tape;

use super::bvp::BvpSolution;
use super::reference::{Flat, Polynomial, Reference};
use guess::{Guess, GuessTapes};
use problem::{
    HamiltonianSystem, OptimalError, OptimalSpec, AUX_A, AUX_H, AUX_JERK, AUX_RAW, AUX_U,
};
use search::{ArcSolver, Plan, Rest, PROBE_MAX_NODES, SEARCH_TOL};

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
    /// The free arc [t_a, t_b] ⊆ [t₀, t_f]: the armature rests at z₀ before
    /// t_a and at z_f after t_b (the limits of the stroke, `optimal/search.rs`).
    pub arc: (f64, f64),
    /// The inputs that hold the rest at z₀ and at z_f.
    pub rest_inputs: [f64; 2],
    /// ∫u² dt over the rest before and after the arc (included in `cost`).
    pub rest_cost: f64,
    /// H − u_rest² at the arc's moving end: ≤ 0 (more time would not lower J)
    /// when the arc spans [t₀, t_f], ≈ 0 when it is shorter.
    pub duration_slope: f64,
    /// Set when the arc was solved on a C² twin of a C¹ tabulated gap: what was done.
    pub smoothed_gap: Option<String>,
    /// With `contact_uncertainty` > 0: the probability-based design, its
    /// cost and contact figures beside the deterministic reference's
    /// (`optimal/robust.rs`).
    pub contact: Option<robust::ContactDesign>,
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

    /// u*(t) on the interpolant inside the arc; outside it, the input that
    /// holds the rest state.
    pub fn input_at(&self, t: f64) -> f64 {
        if t < self.arc.0 {
            self.rest_inputs[0]
        } else if t > self.arc.1 {
            self.rest_inputs[1]
        } else {
            self.aux_at(t)[AUX_U]
        }
    }

    /// Instants where the reference is not smooth inside (t₀, t_f): the
    /// switches of u* and the arc's ends where the motion rests.
    pub fn breaks(&self) -> Vec<f64> {
        let (t0, tf) = (self.spec.t0, self.spec.tf);
        let mut b: Vec<f64> = self.switches.iter().map(|s| s.t).collect();
        b.extend(
            [self.arc.0, self.arc.1]
                .into_iter()
                .filter(|&t| t > t0 && t < tf),
        );
        b.sort_by(f64::total_cmp);
        b
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
        let mut v = self.summary_json_without_contact();
        if let (Some(c), Some(map)) = (&self.contact, v.as_object_mut()) {
            map.insert(
                "contact".into(),
                serde_json::json!({
                    "sigma": c.sigma,
                    "weight": c.weight,
                    "cost": c.cost,
                    "deterministic_cost": c.deterministic_cost,
                    "deterministic_energy": c.deterministic_energy,
                    "robust": figures_json(&c.robust),
                    "deterministic": figures_json(&c.deterministic),
                    "steps": c.steps,
                }),
            );
        }
        v
    }

    fn summary_json_without_contact(&self) -> serde_json::Value {
        serde_json::json!({
            "cost": self.cost,
            "guess_cost": self.guess_cost,
            "guess_max_abs_input": self.guess_max_abs_input,
            "max_abs_input": self.max_abs_input,
            "switches": self.switches.iter().map(|s| serde_json::json!({
                "t": s.t, "bound": s.bound, "entering": s.entering,
            })).collect::<Vec<_>>(),
            "nodes": self.nodes(),
            "arc": [self.arc.0, self.arc.1],
            "rest_cost": self.rest_cost,
            "duration_slope": self.duration_slope,
            "smoothed_gap": self.smoothed_gap,
            "max_residual": self.max_residual,
            "bc_residual": self.bc_residual,
            "newton_iterations": self.newton_iterations,
            "x0": self.x0,
            "xf": self.xf,
        })
    }
}

impl Reference for OptimalTrajectory {
    /// Rest at z₀ before the arc and at z_f after it, the optimal motion between.
    fn at(&self, t: f64) -> Flat {
        let (ta, tb) = self.arc;
        if t <= ta || t >= tb {
            let z = if t <= ta { self.spec.z0 } else { self.spec.zf };
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

fn figures_json(f: &robust::ContactFigures) -> serde_json::Value {
    serde_json::json!({
        "expected_speed": f.expected_speed,
        "rms_speed": f.rms_speed,
        "worst_speed": f.worst_speed,
        "speed_at_sigma": f.speed_at,
    })
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

/// Solves the energy-optimal problem ([PT 58–66]) for `model`, within the
/// stroke [PT 57]: a free arc, with rest at one end where that costs less.
/// Where no solution exists, the error says which bound or duration it needs
/// ([`OptimalError::BoundTooLow`], [`OptimalError::TooShort`]).
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
    match design(model, lin, spec) {
        Err(e) if e.may_be_infeasible() => Err(explain(model, lin, spec, e)),
        other => other,
    }
}

/// Relaxations of the bound tried to tell an infeasible problem from a
/// solver failure.
const RELAX: [f64; 3] = [1.5, 2.5, 4.0];
/// Relaxations of the motion time: up to ×16.
const RELAX_TIME: [f64; 5] = [1.5, 2.5, 4.0, 8.0, 16.0];
/// Relative accuracy of the bisection on the needed bound or duration.
const NEED_TOL: f64 = 5e-3;
/// Collocation tolerance of the solves that only decide existence.
const EXISTENCE_TOL: f64 = 1e-4;

/// Why `spec` has no solution: the bound it needs (a larger u_max solves it),
/// else the duration it needs, each found by bisection with the solver.
fn explain(
    model: &mut Model,
    lin: &Linearization,
    spec: &OptimalSpec,
    err: OptimalError,
) -> OptimalError {
    let source = Box::new(err);
    let duration = spec.tf - spec.t0;
    let mut solves = |s: &OptimalSpec| design(model, lin, s).is_ok();
    let coarse = OptimalSpec {
        tol: spec.tol.max(EXISTENCE_TOL),
        ..spec.clone()
    };
    let with_bound = |b: f64| OptimalSpec {
        u_max: b,
        ..coarse.clone()
    };
    if spec.u_max > 0.0 {
        let candidates = RELAX.map(|k| (k * spec.u_max).min(spec.u_max_limit));
        let larger = candidates.into_iter().filter(|&b| b > spec.u_max);
        if let Some(hi) = larger.into_iter().find(|&b| solves(&with_bound(b))) {
            let needed = bisect(spec.u_max, hi, |b| solves(&with_bound(b)));
            return OptimalError::BoundTooLow {
                needed,
                given: spec.u_max,
                duration,
                source,
            };
        }
    }
    let with_duration = |d: f64| OptimalSpec {
        tf: spec.t0 + d,
        ..coarse.clone()
    };
    if let Some(hi) = RELAX_TIME
        .iter()
        .map(|k| k * duration)
        .find(|&d| solves(&with_duration(d)))
    {
        let needed = bisect(duration, hi, |d| solves(&with_duration(d)));
        return OptimalError::TooShort {
            needed,
            given: duration,
            u_min: spec.u_min,
            u_max: spec.u_max,
            source,
        };
    }
    OptimalError::Unsolved { source }
}

/// The smallest x in (lo, hi] with ok(x), given !ok(lo) and ok(hi), to NEED_TOL.
fn bisect(mut lo: f64, mut hi: f64, mut ok: impl FnMut(f64) -> bool) -> f64 {
    while hi - lo > NEED_TOL * hi {
        let mid = 0.5 * (lo + hi);
        if ok(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// The design: on the C² twin of a C¹ tabulated gap, else on the model.
fn design(
    model: &mut Model,
    lin: &Linearization,
    spec: &OptimalSpec,
) -> Result<OptimalTrajectory, OptimalError> {
    let Some((mut twin, what)) = Model::c2_twin(&model.description) else {
        return solve(model, lin, spec);
    };
    let twin_lin = Linearization::derive(&mut twin)
        .map_err(|e| OptimalError::InvalidSpec(format!("the C² gap twin: {e}")))?;
    // The twin's input differs slightly from the table's own model's: tighten
    // the twin's bounds until the table's model keeps the input within them.
    let mut inner = spec.clone();
    for _ in 0..TWIN_BOUND_PASSES {
        let mut traj = solve(&mut twin, &twin_lin, &inner)?;
        // the samples of the build's check, and a margin of its slack
        let f = super::feasibility::check(model, lin, &traj, (spec.u_min, spec.u_max), 4000);
        let margin = 2e-6 * spec.u_max.abs().max(spec.u_min.abs()).max(1.0);
        let (over_hi, over_lo) = (
            f.max_input - (spec.u_max - margin),
            (spec.u_min + margin) - f.min_input,
        );
        if !(over_hi > 0.0) && !(over_lo > 0.0) {
            traj.smoothed_gap = Some(what);
            return Ok(traj);
        }
        if over_hi > 0.0 {
            inner.u_max -= over_hi + margin;
        }
        if over_lo > 0.0 {
            inner.u_min += over_lo + margin;
        }
    }
    let mut traj = solve(&mut twin, &twin_lin, &inner)?;
    traj.smoothed_gap = Some(what);
    Ok(traj)
}

/// Re-solves of the C² twin with tightened bounds.
const TWIN_BOUND_PASSES: usize = 4;

fn solve(
    model: &mut Model,
    lin: &Linearization,
    spec: &OptimalSpec,
) -> Result<OptimalTrajectory, OptimalError> {
    let sys = HamiltonianSystem::derive(model, lin, spec.u_min, spec.u_max)?;
    let tapes = GuessTapes::new(model, lin)?;
    let x0 = tapes.rest_state(spec.z0, "initial")?;
    let xf = tapes.rest_state(spec.zf, "final")?;
    let full = Polynomial {
        z0: spec.z0,
        zf: spec.zf,
        t0: spec.t0,
        tf: spec.tf,
    };
    let guess = tapes.polynomial(&full, spec.nodes, spec.costate_guess)?;
    let precise = ArcSolver {
        sys: &sys,
        tapes: &tapes,
        spec,
        x0,
        xf,
        scale: scales(spec, &guess),
        max_nodes: spec.max_nodes,
    };
    let search_spec = OptimalSpec {
        tol: spec.tol.max(SEARCH_TOL),
        ..spec.clone()
    };
    let search = ArcSolver {
        spec: &search_spec,
        scale: precise.scale.clone(),
        max_nodes: spec.max_nodes.min(PROBE_MAX_NODES),
        ..precise
    };
    let rest_inputs = [tapes.rest_input(x0, spec.t0), tapes.rest_input(xf, spec.tf)];
    let [c0, cf] = rest_inputs.map(|u| u * u);
    let rest = Rest {
        at_end: cf <= c0,
        rate: c0.min(cf),
    };
    let plan = search.plan(rest, &precise)?;
    let robust = if spec.contact_uncertainty > 0.0 {
        Some(plan.arc.clone())
    } else {
        None
    };
    let mut traj = trajectory(&sys, spec, plan, [x0, xf], rest_inputs);
    traj.guess_cost = guess.cost;
    traj.guess_max_abs_input = guess.max_abs_u;
    locate_switches(&mut traj);
    integrate_cost(&mut traj, &tapes);
    let Some(det_arc) = robust else {
        return Ok(traj);
    };
    // the probability-based design, by continuation from this one
    let det = traj;
    let target = robust::contact_cost(spec, det.cost, det_arc.b - det_arc.a);
    let (arc, rsys, steps) = robust::continuation(model, lin, &precise, &det_arc, target)?;
    let slope = ArcSolver::slope(&arc, rest);
    let mut traj = trajectory(&rsys, spec, Plan { arc, slope }, [x0, xf], rest_inputs);
    traj.guess_cost = guess.cost;
    traj.guess_max_abs_input = guess.max_abs_u;
    locate_switches(&mut traj);
    integrate_cost(&mut traj, &tapes);
    let sigma = spec.contact_uncertainty;
    let (fr, _) = robust::contact_figures(&traj, spec.z0, spec.zf, sigma);
    let (fd, _) = robust::contact_figures(&det, spec.z0, spec.zf, sigma);
    let (er, ed) = (
        contact_integral(&traj, sigma),
        contact_integral(&det, sigma),
    );
    traj.contact = Some(robust::ContactDesign {
        sigma,
        weight: target.weight,
        cost: traj.cost + target.weight * er,
        deterministic_cost: det.cost + target.weight * ed,
        deterministic_energy: det.cost,
        robust: fr,
        deterministic: fd,
        steps,
    });
    Ok(traj)
}

/// Per-component scales of [x; p]: stroke, mean speed ×2, the guess's peak
/// flux and chain costates.
pub(crate) fn scales(spec: &OptimalSpec, guess: &Guess) -> Vec<f64> {
    let stroke = (spec.zf - spec.z0).abs();
    let duration = spec.tf - spec.t0;
    let phi_scale = guess.y.iter().map(|y| y[2].abs()).fold(0.0, f64::max);
    let mut scale = vec![stroke, 2.0 * stroke / duration, phi_scale];
    for k in 0..3 {
        let s = guess.chain.iter().map(|p| p[k].abs()).fold(0.0, f64::max);
        scale.push(if s > 0.0 && s.is_finite() { s } else { 1.0 });
    }
    scale
}

fn trajectory(
    sys: &HamiltonianSystem,
    spec: &OptimalSpec,
    plan: Plan,
    [x0, xf]: [[f64; 3]; 2],
    rest_inputs: [f64; 2],
) -> OptimalTrajectory {
    let sol = plan.arc.sol;
    let aux: Vec<[f64; 5]> = sol
        .t
        .iter()
        .zip(&sol.y)
        .map(|(&t, y)| sys.aux_at(t, y))
        .collect();
    OptimalTrajectory {
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
        guess_cost: 0.0,
        guess_max_abs_input: 0.0,
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
        arc: (plan.arc.a, plan.arc.b),
        rest_inputs,
        rest_cost: 0.0,
        duration_slope: plan.slope,
        smoothed_gap: None,
        contact: None,
        aux: sys.aux.clone(),
    }
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

/// E[v_c²] = ∫ρ(d(z))·|v|³ dt on the arc's interpolant (Gauss–Legendre per
/// mesh interval; the rests have v = 0).
fn contact_integral(traj: &OptimalTrajectory, sigma: f64) -> f64 {
    let (z0, zf) = (traj.spec.z0, traj.spec.zf);
    let inward = (z0 - zf).signum();
    let mut e = 0.0;
    for w in traj.t.windows(2) {
        e += gauss5(w[0], w[1], &mut |tt| {
            let y = traj.solution.eval(tt);
            let d = (y[0] - zf) * inward;
            // the Gaussian continued where a Newton dip leaves the stroke
            robust::density(d, sigma) * y[1].abs().powi(3)
        });
    }
    e
}

/// J = ∫u*² dt and max|u*| on the interpolant (Gauss–Legendre per interval,
/// split at the switches; max over the GL points, the nodes and the switches).
fn integrate_cost(traj: &mut OptimalTrajectory, tapes: &GuessTapes) {
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
    let (t0, tf) = (traj.spec.t0, traj.spec.tf);
    let rests = [(t0, traj.arc.0, traj.x0), (traj.arc.1, tf, traj.xf)];
    let mut rest_cost = 0.0;
    for (a, b, x) in rests.into_iter().filter(|r| r.1 > r.0) {
        // the holding input varies in time only with a resistance drift
        for k in 0..8 {
            let (ka, kb) = (
                a + (b - a) * k as f64 / 8.0,
                a + (b - a) * (k + 1) as f64 / 8.0,
            );
            rest_cost += gauss5(ka, kb, &mut |tt| {
                let u = tapes.rest_input(x, tt);
                umax = umax.max(u.abs());
                u * u
            });
        }
    }
    traj.rest_cost = rest_cost;
    traj.cost = cost + rest_cost;
    traj.max_abs_input = umax;
}
