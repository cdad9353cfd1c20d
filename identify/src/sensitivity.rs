//! Forward parameter sensitivities S = ∂x/∂θ of a replayed trajectory, and
//! from them ∂i/∂θ, ∂z/∂θ, ∂φ/∂θ at the output times: the analytic Jacobian
//! of the fit (issue 5 §1) in place of finite differences of whole replays.
//!
//! - **Symbolic part.** ∂f/∂x, ∂f/∂θ, ∂i/∂x, ∂i/∂θ are derived from the
//!   model's expressions with the fitted parameters' symbols, then every
//!   parameter is bound to its value and all of it compiled to one tape of
//!   (x, u, t).
//! - **Flow.** Ṡ = f_x·S + f_θ in free motion; stuck at a stop the rows of z
//!   and v are zero (ż = v̇ = 0) and only the magnetic rows evolve.
//! - **Events.** The saltation update with the impact guard g = z − z_lim,
//!   S⁺ = R_x·S + (f⁺ − R_x·f⁻)·(g_x·S)/(g_x·f⁻), R_x = diag(1, −γ, 1, …) for
//!   a bounce and diag(0, 0, 1, …) for sticking (z⁺ = z_lim, v⁺ = 0). (With
//!   τ = ∂t_e/∂θ = −(g_x·S)/(g_x·f⁻) this is S⁺ = R_x·S − (f⁺ − R_x·f⁻)·τ.)
//!   A lift-off leaves S unchanged: at the crossing v = 0 and the free
//!   acceleration (the guard) is 0, so f⁺ = f⁻ and the saltation term is
//!   zero.
//! - **Integration.** The simulator is reused as is: the sensitivity ODE is
//!   integrated by fixed-step RK4 together with x over each sample interval,
//!   x re-anchored at every sample on the simulator's (tight-tolerance)
//!   state, the interval cut at the simulator's event times and at the
//!   input's breakpoints (a voltage edge between samples), each piece with
//!   the replayed input's own affine u. A second Dopri pass on
//!   the augmented system would not fit `MAX_DIM` (d·(1 + p) states).
//!
//! Not supported (the fit falls back to finite differences): parameters
//! that change the model's structure (the resistance drift when the model
//! has none), those entering only the resets or the mode logic
//! (`mechanics.restitution`, `mechanics.bounce_threshold`), and the
//! Jiles–Atherton core, whose switching functions (sign φ̇) would need a
//! saltation update at every switch.

use std::cell::RefCell;

use nalgebra::DMatrix;

use crate::description::{Core, Description};
use crate::model::Model;
use crate::sim::{EventKind, Input, Limit, Mode, Trajectory, MAX_DIM};
use crate::sym::{Id, Tape};

/// RK4 substeps per sample interval (and per piece of one cut at events):
/// on the saturating valve at 20 µs samples, 4 keep the Jacobian within
/// 3e-6 of central differences (as 32 do); 2 lose accuracy at voltage edges.
pub const SUBSTEPS: usize = 4;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Unsupported {
    #[error("parameter `{path}` has no analytic sensitivity: {reason}")]
    Parameter { path: String, reason: &'static str },
    #[error("the Jiles–Atherton core has no analytic sensitivities (its switching functions need a saltation update per switch)")]
    Hysteresis,
}

/// The model parameter behind a fit path, or why there is none.
fn symbol_name(path: &str) -> Result<&'static str, &'static str> {
    Ok(match path {
        "coil.turns" => "N",
        "coil.resistance" => "R",
        "coil.eddy" => "k_e",
        "coil.resistance_drift" => "R_drift",
        "mechanics.mass" => "m",
        "mechanics.stiffness" => "k_s",
        "mechanics.damping" => "c",
        "mechanics.preload" => "F0",
        "gap.slope" => "k_gap",
        "gap.offset" => "R_gap0",
        "gap.area" => "A_gap",
        "gap.winding_length" => "l_w",
        "gap.r0" => "R_g0",
        "gap.r0_prime" => "R_g0_prime",
        "gap.k1" => "k1",
        "gap.k2" => "k2",
        "core.r0" => "R_core0",
        "core.phi_sat" => "phi_sat",
        "mechanics.restitution" | "mechanics.bounce_threshold" => {
            return Err("it only enters the impact reset")
        }
        _ => return Err("it is not a parameter of the model's field"),
    })
}

/// The symbols of `paths` in `model`, when all have analytic sensitivities.
pub fn symbols(model: &Model, paths: &[&str]) -> Result<Vec<Id>, Unsupported> {
    if matches!(model.description.core, Core::JilesAtherton(_)) {
        return Err(Unsupported::Hysteresis);
    }
    paths
        .iter()
        .map(|&path| {
            let unsupported = |reason| Unsupported::Parameter {
                path: path.to_owned(),
                reason,
            };
            let name = symbol_name(path).map_err(unsupported)?;
            model
                .params
                .symbol(name)
                .ok_or_else(|| unsupported("the model does not contain it at this value"))
        })
        .collect()
}

/// Whether every one of `paths` of `d` has an analytic sensitivity.
pub fn check(d: &Description, paths: &[&str]) -> Result<(), Unsupported> {
    symbols(&Model::build(d), paths).map(|_| ())
}

/// ∂(output)/∂θ at every output time (one row per time, one column per θ).
#[derive(Debug, Clone, PartialEq)]
pub struct OutputSensitivities {
    pub current: DMatrix<f64>,
    pub z: DMatrix<f64>,
    pub phi: DMatrix<f64>,
}

/// f, f_x, f_θ, i, i_x, i_θ of (x, u, t) on one tape, outputs in that
/// order (row-major blocks: f_x[i·d + k], f_θ[i·p + j]).
struct Field {
    tape: Tape,
    scratch: RefCell<Vec<f64>>,
    out: RefCell<Vec<f64>>,
    d: usize,
    p: usize,
    z_min: f64,
    z_max: f64,
}

impl Field {
    fn new(model: &mut Model, theta: &[Id]) -> Field {
        let (d, p) = (model.dim(), theta.len());
        let f = model.f.clone();
        let mut exprs = f.clone();
        exprs.extend(model.jacobian().into_iter().flatten());
        for &fi in &f {
            for &th in theta {
                exprs.push(model.graph.diff(fi, th));
            }
        }
        let i = model.current;
        exprs.push(i);
        for k in 0..d {
            let xk = model.states[k];
            exprs.push(model.graph.diff(i, xk));
        }
        for &th in theta {
            exprs.push(model.graph.diff(i, th));
        }
        let tape = model.compile(&exprs);
        let m = &model.description.mechanics;
        Field {
            scratch: RefCell::new(tape.scratch()),
            out: RefCell::new(vec![0.0; exprs.len()]),
            tape,
            d,
            p,
            z_min: m.z_min,
            z_max: m.z_max,
        }
    }

    /// Evaluates the tape at (t, x, u), z held inside the stops.
    fn eval(&self, t: f64, x: &[f64], u: f64) {
        let mut inputs = [0.0; MAX_DIM + 2];
        inputs[..self.d].copy_from_slice(&x[..self.d]);
        inputs[0] = x[0].clamp(self.z_min, self.z_max);
        inputs[self.d] = u;
        inputs[self.d + 1] = t;
        let n = self.d + 2;
        self.tape.eval(
            &inputs[..n],
            &mut self.scratch.borrow_mut(),
            &mut self.out.borrow_mut(),
        );
    }

    /// The field at (t, x, u), mechanical rows zero when `stuck`.
    fn f(&self, t: f64, x: &[f64], u: f64, stuck: bool) -> [f64; MAX_DIM] {
        self.eval(t, x, u);
        let out = self.out.borrow();
        std::array::from_fn(|i| match i < self.d && !(stuck && i < 2) {
            true => out[i],
            false => 0.0,
        })
    }

    /// ẋ and Ṡ = f_x·S + f_θ (rows of z and v zero when `stuck`).
    fn rhs(
        &self,
        t: f64,
        x: &[f64],
        s: &[f64],
        u: f64,
        stuck: bool,
        dx: &mut [f64],
        ds: &mut [f64],
    ) {
        let (d, p) = (self.d, self.p);
        self.eval(t, x, u);
        let out = self.out.borrow();
        let (f, rest) = out.split_at(d);
        let (fx, rest) = rest.split_at(d * d);
        let fth = &rest[..d * p];
        for i in 0..d {
            let frozen = stuck && i < 2;
            dx[i] = if frozen { 0.0 } else { f[i] };
            for j in 0..p {
                ds[i * p + j] = match frozen {
                    true => 0.0,
                    false => {
                        fth[i * p + j] + (0..d).map(|k| fx[i * d + k] * s[k * p + j]).sum::<f64>()
                    }
                };
            }
        }
    }

    /// ∂i/∂θ = i_x·S + i_θ at (t, x, u).
    fn current(&self, t: f64, x: &[f64], s: &[f64], u: f64, row: &mut [f64]) {
        let (d, p) = (self.d, self.p);
        self.eval(t, x, u);
        let out = self.out.borrow();
        let base = d + d * d + d * p + 1;
        let (ix, ith) = (&out[base..base + d], &out[base + d..base + d + p]);
        for j in 0..p {
            row[j] = ith[j] + (0..d).map(|k| ix[k] * s[k * p + j]).sum::<f64>();
        }
    }

    /// Classical RK4 of (x, S) over [a, b] in `SUBSTEPS` steps; u linear.
    fn integrate(
        &self,
        a: f64,
        b: f64,
        x: &mut [f64],
        s: &mut [f64],
        u: &dyn Fn(f64) -> f64,
        stuck: bool,
    ) {
        let (d, n) = (self.d, self.d * self.p);
        let h = (b - a) / SUBSTEPS as f64;
        let mut k = [[0.0; MAX_DIM]; 4];
        let mut ks = vec![vec![0.0; n]; 4];
        let (mut xt, mut st) = ([0.0; MAX_DIM], vec![0.0; n]);
        for step in 0..SUBSTEPS {
            let t = a + step as f64 * h;
            for stage in 0..4 {
                let c = [0.0, 0.5, 0.5, 1.0][stage];
                for i in 0..d {
                    xt[i] = x[i]
                        + if stage == 0 {
                            0.0
                        } else {
                            c * h * k[stage - 1][i]
                        };
                }
                for i in 0..n {
                    st[i] = s[i]
                        + if stage == 0 {
                            0.0
                        } else {
                            c * h * ks[stage - 1][i]
                        };
                }
                let tc = t + c * h;
                let (kx, kss) = (&mut k[stage], &mut ks[stage]);
                self.rhs(tc, &xt, &st, u(tc), stuck, kx, kss);
            }
            // (RK4) y += h/6·(k1 + 2k2 + 2k3 + k4)
            for i in 0..d {
                x[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
            }
            for i in 0..n {
                s[i] += h / 6.0 * (ks[0][i] + 2.0 * ks[1][i] + 2.0 * ks[2][i] + ks[3][i]);
            }
        }
    }

    /// The saltation update at an impact, a stick or a lift-off.
    fn event(&self, t: f64, kind: EventKind, after: Mode, x: &mut [f64], s: &mut [f64], u: f64) {
        let (d, p) = (self.d, self.p);
        let stop = |limit| match limit {
            Limit::Min => self.z_min,
            Limit::Max => self.z_max,
        };
        match kind {
            EventKind::Impact {
                limit,
                v_before,
                v_after,
                ..
            } => {
                x[0] = stop(limit);
                x[1] = v_before;
                let f_minus = self.f(t, x, u, false);
                x[1] = v_after;
                let stuck = after != Mode::Free;
                let f_plus = self.f(t, x, u, stuck);
                let mut r = [1.0; MAX_DIM];
                (r[0], r[1]) = match stuck {
                    true => (0.0, 0.0),
                    false => (1.0, v_after / v_before),
                };
                for j in 0..p {
                    // (g_x·S)/(g_x·f⁻) with g = z − z_lim
                    let ratio = if v_before != 0.0 {
                        s[j] / v_before
                    } else {
                        0.0
                    };
                    for i in 0..d {
                        let jump = f_plus[i] - r[i] * f_minus[i];
                        s[i * p + j] = r[i] * s[i * p + j] + jump * ratio;
                    }
                }
            }
            EventKind::Stick { limit } => {
                (x[0], x[1]) = (stop(limit), 0.0);
                s[..2 * p].iter_mut().for_each(|v| *v = 0.0);
            }
            // f⁺ = f⁻ at a lift-off (v = 0, guard a = 0): S is continuous.
            EventKind::LiftOff { .. } => {}
        }
    }
}

/// The sensitivities of `paths` along `trajectory`, a replay of `model`
/// (with its values) driven by `input` (the intervals are cut at its
/// breakpoints, e.g. a voltage edge between samples).
pub fn forward<I: Input + ?Sized>(
    model: &mut Model,
    paths: &[&str],
    trajectory: &Trajectory,
    input: &I,
) -> Result<OutputSensitivities, Unsupported> {
    let theta = symbols(model, paths)?;
    let field = Field::new(model, &theta);
    let tr = trajectory;
    let (n, d, p) = (tr.t.len(), field.d, field.p);
    let mut out = OutputSensitivities {
        current: DMatrix::zeros(n, p),
        z: DMatrix::zeros(n, p),
        phi: DMatrix::zeros(n, p),
    };
    let mut s = vec![0.0; d * p];
    let mut row = vec![0.0; p];
    let mut record = |k: usize, s: &[f64], out: &mut OutputSensitivities| {
        field.current(tr.t[k], &tr.x[k], s, tr.u[k], &mut row);
        for j in 0..p {
            out.current[(k, j)] = row[j];
            out.z[(k, j)] = s[j];
            out.phi[(k, j)] = s[2 * p + j];
        }
    };
    if n == 0 {
        return Ok(out);
    }
    record(0, &s, &mut out);
    let events = &tr.events;
    let mut next = events.iter().take_while(|e| e.t <= tr.t[0]).count();
    for k in 0..n - 1 {
        let t1 = tr.t[k + 1];
        let mut x = tr.x[k];
        let mut mode = tr.mode[k];
        let mut a = tr.t[k];
        // Pieces of the interval between the input's breakpoints and the
        // events, each integrated with its own affine piece of u.
        loop {
            let event = events.get(next).filter(|e| e.t <= t1);
            let b = input
                .next_breakpoint(a)
                .min(event.map_or(t1, |e| e.t))
                .min(t1);
            if b > a {
                let piece = input.piece(a);
                field.integrate(
                    a,
                    b,
                    &mut x,
                    &mut s,
                    &|t| piece.value(t),
                    mode != Mode::Free,
                );
                a = b;
            }
            match event {
                Some(e) if e.t <= a => {
                    field.event(e.t, e.kind, e.mode_after, &mut x, &mut s, input.value(e.t));
                    mode = e.mode_after;
                    next += 1;
                }
                _ if a >= t1 => break,
                _ => {}
            }
        }
        record(k + 1, &s, &mut out);
    }
    Ok(out)
}
