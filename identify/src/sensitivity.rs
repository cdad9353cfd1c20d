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
//! - **Integration.** The simulator is reused as is: its samples give x.
//!   A sample interval with no event and no input breakpoint inside (most
//!   of them) takes one step of Radau IIA (2 stages, order 3, L-stable) of
//!   the linear Ṡ = f_x·S + f_θ, the stages' x interpolated from the
//!   samples (cubic Hermite): three tape evaluations, and stable however
//!   stiff the field. Where the interpolant does not follow the field (a
//!   transient within the interval), and across events and breakpoints (a
//!   voltage edge between samples), RK4 integrates x and S together, x
//!   re-anchored at every sample, the interval cut at the events and
//!   breakpoints, each piece with the replayed input's own affine u, in 4
//!   substeps or more where f_x is stiff. Beyond [`MAX_SUBSTEPS`] the pass
//!   gives up ([`Unsupported::Stiff`]) and the fit differences replays for
//!   that Jacobian. A second Dopri pass on the augmented system would not
//!   fit `MAX_DIM` (d·(1 + p) states).
//! - **Restitution.** γ enters only the bounce's reset v⁺ = −γ·v⁻, so its
//!   column has f_θ = 0 and gains R_θ = ∂x⁺/∂γ = (0, −v⁻, 0, …) at each
//!   bounce (not at an impact that sticks: v⁺ = 0 whatever γ).
//! - **Input steps.** The instant t_s of a step of u from u⁻ to u⁺ (a
//!   voltage edge between samples, fitted by `edge_fit`) has f_θ = 0;
//!   moving it later by δ holds u⁻ over [t_s, t_s + δ], so S jumps there
//!   by f(x, u⁻) − f(x, u⁺) ([`forward_with_steps`]).
//! - **Perturbations of the input** ([`input_response`]): a column per
//!   perturbation δu(t) of the input (e.g. noise on the voltage's samples,
//!   linear between the input's knots like u itself), f_θ = f_u·δu(t) and
//!   i_θ = i_u·δu(t): the outputs' linear response, for the diagnosis's
//!   propagation of the voltage noise.
//! - **Jiles–Atherton core.** Its field switches with δ = sign φ̇ [JA 26],
//!   but it is continuous there: Ḣ_c = dH_c/dB_c(δ)·φ̇/A_c [JA 33] is 0 on
//!   both sides of φ̇ = 0, so the saltation term (f⁺ − f⁻)·τ vanishes and S
//!   is continuous across a switch, as at a lift-off (only f_x jumps; the
//!   symbolic ∂ sign/∂x is 0).
//!
//! Not supported (the fit falls back to finite differences): parameters
//! that change the model's structure (the resistance drift when the model
//! has none) and those entering only the mode logic
//! (`mechanics.bounce_threshold`).

// `!(a <= b)` comparisons are deliberate: they also catch NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::cell::RefCell;

use nalgebra::DMatrix;

use crate::description::{schema, Description};
use crate::model::Model;
use crate::sim::{Affine, EventKind, Input, Limit, Mode, Trajectory, MAX_DIM};
use crate::sym::{Id, Tape};

mod split;

/// RK4 substeps per sample interval (and per piece of one cut at events):
/// on the saturating valve at 20 µs samples, 4 keep the Jacobian within
/// 3e-6 of central differences (as 32 do); 2 lose accuracy at voltage edges.
/// More where the field is stiff there (see [`STABLE_REACH`]).
pub const SUBSTEPS: usize = 4;

/// The largest defect of the replay's cubic interpolant at a Radau stage,
/// relative to the field's magnitudes there (see [`Field::radau`]).
pub const HERMITE_DEFECT: f64 = 1e-4;

/// The largest h·|λ| of an RK4 substep, |λ| bounded at its start
/// ([`spectral_bound`] of f_x): explicit RK4 is stable to 2.78 on the
/// negative real axis, and the field can stiffen within the substep.
pub const STABLE_REACH: f64 = 1.0;

/// The most substeps one piece may take: beyond, the field is too stiff for
/// an explicit method (a Jiles–Atherton core far in saturation, where
/// ∂Ḣ_c/∂H_c reaches −1e10/s) and [`forward`] gives up ([`Unsupported::Stiff`]);
/// the fit then differences whole replays, which the adaptive simulator makes.
pub const MAX_SUBSTEPS: usize = 256;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Unsupported {
    #[error("parameter `{path}` has no analytic sensitivity: {reason}")]
    Parameter { path: String, reason: &'static str },
    #[error("the field is too stiff at t = {t:e} s (|λ| up to {rate:.1e}/s) for the sensitivities' explicit RK4")]
    Stiff { t: f64, rate: f64 },
}

/// How a fitted parameter enters the replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Theta {
    /// A symbol of the model's field.
    Field(Id),
    /// The restitution γ: only the bounce's reset v⁺ = −γ·v⁻.
    Restitution,
    /// The instant of a step of the input ([`InputStep`]): f_θ = 0, and S
    /// jumps at the step.
    StepInstant,
    /// A perturbation δu(t) of the input ([`InputPerturbations`]):
    /// f_θ = f_u·δu(t), i_θ = i_u·δu(t).
    Input,
}

/// Perturbations of a piecewise-linear input, one per column of
/// [`input_response`]: the input runs linearly between its `knots` (a
/// step is two knots at one instant), and column j moves its value at
/// knot m by `columns[j][sample[m]]` (e.g. noise on the samples of a
/// measured voltage, `sample[m]` the sample each knot's value comes from).
#[derive(Debug, Clone, Copy)]
pub struct InputPerturbations<'a> {
    pub knots: &'a [f64],
    pub sample: &'a [usize],
    pub columns: &'a [Vec<f64>],
}

impl InputPerturbations<'_> {
    /// δu of every column at `t` into `du`, on the input's piece that
    /// starts at or before `from` (right-continuous there: across a step,
    /// the piece after it; up to the end of a piece, its own value).
    fn at(&self, from: f64, t: f64, du: &mut [f64]) {
        let n = self.knots.len();
        if n == 0 {
            du.fill(0.0);
            return;
        }
        let m = self.knots.partition_point(|&k| k <= from).clamp(1, n) - 1;
        let next = (m + 1).min(n - 1);
        let span = self.knots[next] - self.knots[m];
        let a = match span > 0.0 {
            true => ((t - self.knots[m]) / span).clamp(0.0, 1.0),
            false => 0.0,
        };
        let (k0, k1) = (self.sample[m], self.sample[next]);
        for (du, c) in du.iter_mut().zip(self.columns) {
            *du = (1.0 - a) * c[k0] + a * c[k1];
        }
    }
}

/// A step of the input from `before` to `after` at `t`, whose instant is a
/// fitted parameter (a voltage edge between two samples, `edges`). Moving
/// it later by δ holds `before` over [t, t + δ], so x after it moves by
/// (f(x, before) − f(x, after))·δ: ∂x/∂t jumps by f⁻ − f⁺ at t and then
/// follows Ṡ = f_x·S.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputStep {
    pub t: f64,
    pub before: f64,
    pub after: f64,
}

/// The model symbol behind a fit path (the schema's), or why there is none.
fn symbol_name(path: &str) -> Result<&'static str, &'static str> {
    match path {
        "mechanics.bounce_threshold" => Err("it only decides between a bounce and sticking"),
        _ => schema::lookup(path)
            .and_then(|key| key.symbol.filter(|_| key.fittable))
            .ok_or("it is not a parameter of the model's field"),
    }
}

/// How each of `paths` enters `model`, when all have analytic sensitivities.
pub fn symbols(model: &Model, paths: &[&str]) -> Result<Vec<Theta>, Unsupported> {
    paths
        .iter()
        .map(|&path| {
            let unsupported = |reason| Unsupported::Parameter {
                path: path.to_owned(),
                reason,
            };
            if path == "mechanics.restitution" {
                return Ok(Theta::Restitution);
            }
            let name = symbol_name(path).map_err(unsupported)?;
            model
                .params
                .symbol(name)
                .map(Theta::Field)
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
    /// Sample intervals taken by one Radau step, and by RK4 (events, input
    /// breakpoints, or an interpolant that did not follow the field).
    pub radau_intervals: usize,
    pub rk4_intervals: usize,
}

/// f, f_x, f_θ, i, i_x, i_θ of (x, u, t) on one tape, outputs in that
/// order (row-major blocks: f_x[i·d + k], f_θ[i·p + j]), then f_u and i_u
/// where columns perturb the input.
struct Field<'a> {
    tape: Tape,
    /// The tape's scratch for the replay's samples, and one for the points
    /// between them (Radau's stage, RK4's, events, steps): consecutive
    /// evaluations at one sample (the end of an interval, its current's
    /// row, the start of the next) then run the tape once
    /// ([`Tape::eval`] skips what did not change).
    at_samples: RefCell<Vec<f64>>,
    between: RefCell<Vec<f64>>,
    out: RefCell<Vec<f64>>,
    d: usize,
    p: usize,
    /// The columns of S that can be nonzero: the parameters', and those of
    /// the steps whose jump is applied (a step's column is zero before its
    /// instant, and its f_θ is zero: the flow leaves it zero).
    live: std::cell::Cell<usize>,
    /// The column of the restitution γ, if fitted.
    restitution: Option<usize>,
    z_min: f64,
    z_max: f64,
    /// The input's perturbations: its columns are the last ones.
    perturbed: Option<InputPerturbations<'a>>,
    /// δu of each perturbed column (scratch of [`Field::input_forcing`] and
    /// [`Field::current`]).
    du: RefCell<Vec<f64>>,
    /// Where the input's piece being integrated starts (δu follows that
    /// piece up to its end, as u does).
    piece_from: std::cell::Cell<f64>,
}

/// f_x and f_θ at the two stages of [`Field::radau`], and the right-hand
/// sides of its stage system, one column per parameter (allocated once a
/// pass).
struct Work {
    a: [Vec<f64>; 2],
    b: [Vec<f64>; 2],
    rhs: nalgebra::OMatrix<f64, nalgebra::Const<{ 2 * MAX_DIM }>, nalgebra::Dyn>,
    /// The same for three states.
    rhs3: nalgebra::OMatrix<f64, nalgebra::Const<6>, nalgebra::Dyn>,
}

impl Work {
    fn new(d: usize, p: usize) -> Work {
        Work {
            a: [vec![0.0; d * d], vec![0.0; d * d]],
            b: [vec![0.0; d * p], vec![0.0; d * p]],
            rhs: nalgebra::OMatrix::zeros_generic(nalgebra::Const, nalgebra::Dyn(p)),
            rhs3: nalgebra::OMatrix::zeros_generic(nalgebra::Const, nalgebra::Dyn(p)),
        }
    }
}

impl<'a> Field<'a> {
    fn new(
        model: &mut Model,
        theta: &[Theta],
        perturbed: Option<InputPerturbations<'a>>,
    ) -> Field<'a> {
        let (d, p) = (model.dim(), theta.len());
        let f = model.f.clone();
        let mut exprs = f.clone();
        exprs.extend(model.jacobian().into_iter().flatten());
        let zero = model.graph.constant(0.0);
        let diff = |model: &mut Model, e: Id, th: &Theta| match *th {
            Theta::Field(th) => model.graph.diff(e, th),
            Theta::Restitution | Theta::StepInstant | Theta::Input => zero,
        };
        for &fi in &f {
            for th in theta {
                exprs.push(diff(model, fi, th));
            }
        }
        let i = model.current;
        exprs.push(i);
        for k in 0..d {
            let xk = model.states[k];
            exprs.push(model.graph.diff(i, xk));
        }
        for th in theta {
            exprs.push(diff(model, i, th));
        }
        if perturbed.is_some() {
            let u = model.input;
            for &fi in f.iter().chain([&i]) {
                exprs.push(model.graph.diff(fi, u));
            }
        }
        let tape = model.compile(&exprs);
        let m = &model.description.mechanics;
        Field {
            at_samples: RefCell::new(tape.scratch()),
            between: RefCell::new(tape.scratch()),
            out: RefCell::new(vec![0.0; exprs.len()]),
            tape,
            d,
            p,
            live: std::cell::Cell::new(p),
            restitution: theta.iter().position(|th| *th == Theta::Restitution),
            z_min: m.z_min,
            z_max: m.z_max,
            du: RefCell::new(vec![0.0; perturbed.map_or(0, |q| q.columns.len())]),
            piece_from: std::cell::Cell::new(f64::NEG_INFINITY),
            perturbed,
        }
    }

    /// The first column that perturbs the input, and their number.
    fn perturbed_columns(&self) -> (usize, usize) {
        let k = self.perturbed.map_or(0, |q| q.columns.len());
        (self.p - k, k)
    }

    /// f_u·δu(t) of the perturbed columns into their entries of the d×p
    /// block `b` (rows of z and v left alone when `stuck`), f_u from the
    /// last evaluation, which must be at `t`.
    fn input_forcing(&self, t: f64, stuck: bool, b: &mut [f64]) {
        let Some(q) = self.perturbed else {
            return;
        };
        let (d, p) = (self.d, self.p);
        let (first, k) = self.perturbed_columns();
        let mut du = self.du.borrow_mut();
        q.at(self.piece_from.get(), t, &mut du);
        let out = self.out.borrow();
        let fu = &out[out.len() - d - 1..out.len() - 1];
        for i in (0..d).filter(|&i| !(stuck && i < 2)) {
            for j in 0..k {
                b[i * p + first + j] += fu[i] * du[j];
            }
        }
    }

    /// Evaluates the tape at a sample (t, x, u), z held inside the stops.
    fn eval(&self, t: f64, x: &[f64], u: f64) {
        self.eval_on(&self.at_samples, t, x, u);
    }

    /// [`eval`](Self::eval) at a point between the samples.
    fn eval_between(&self, t: f64, x: &[f64], u: f64) {
        self.eval_on(&self.between, t, x, u);
    }

    fn eval_on(&self, scratch: &RefCell<Vec<f64>>, t: f64, x: &[f64], u: f64) {
        let mut inputs = [0.0; MAX_DIM + 2];
        inputs[..self.d].copy_from_slice(&x[..self.d]);
        inputs[0] = x[0].clamp(self.z_min, self.z_max);
        inputs[self.d] = u;
        inputs[self.d + 1] = t;
        let n = self.d + 2;
        self.tape.eval(
            &inputs[..n],
            &mut scratch.borrow_mut(),
            &mut self.out.borrow_mut(),
        );
    }

    /// The field at (t, x, u), mechanical rows zero when `stuck`.
    fn f(&self, t: f64, x: &[f64], u: f64, stuck: bool) -> [f64; MAX_DIM] {
        self.eval_between(t, x, u);
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
        self.eval_between(t, x, u);
        let out = self.out.borrow();
        let (f, rest) = out.split_at(d);
        let (fx, rest) = rest.split_at(d * d);
        let fth = &rest[..d * p];
        for i in 0..d {
            let frozen = stuck && i < 2;
            dx[i] = if frozen { 0.0 } else { f[i] };
            // (the other columns' rates stay zero)
            for j in 0..self.live.get() {
                ds[i * p + j] = match frozen {
                    true => 0.0,
                    false => {
                        fth[i * p + j] + (0..d).map(|k| fx[i * d + k] * s[k * p + j]).sum::<f64>()
                    }
                };
            }
        }
        drop(out);
        self.input_forcing(t, stuck, ds);
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
        if let Some(q) = self.perturbed {
            let (first, k) = self.perturbed_columns();
            let mut du = self.du.borrow_mut();
            q.at(t, t, &mut du);
            let iu = out[out.len() - 1];
            for j in 0..k {
                row[first + j] += iu * du[j];
            }
        }
    }

    /// A bound on |λ|max of f_x at the last evaluation, rows of z and v
    /// zero when `stuck` (∞ when f_x is not finite).
    fn rate_bound(&self, stuck: bool) -> f64 {
        let d = self.d;
        let mut fx = [0.0; MAX_DIM * MAX_DIM];
        self.frozen_rows(stuck, d, d, &mut fx[..d * d]);
        spectral_bound(&fx[..d * d], d)
    }

    /// The `cols`-wide block of the last evaluation's outputs from `from`
    /// on (f_x: from d, d wide; f_θ: from d + d², p wide) into `block`,
    /// rows of z and v zero when `stuck`.
    fn frozen_rows(&self, stuck: bool, from: usize, cols: usize, block: &mut [f64]) {
        let out = self.out.borrow();
        let rows = out[from..from + self.d * cols].chunks(cols);
        for (i, (row, into)) in rows.zip(block.chunks_mut(cols)).enumerate() {
            match stuck && i < 2 {
                true => into.fill(0.0),
                false => into.copy_from_slice(row),
            }
        }
    }

    /// Classical RK4 of (x, S) over [a, b] in `SUBSTEPS` steps, finer from
    /// any substep on whose f_x asks for it ([`STABLE_REACH`]); u linear.
    fn integrate(
        &self,
        a: f64,
        b: f64,
        x: &mut [f64],
        s: &mut [f64],
        u: &dyn Fn(f64) -> f64,
        stuck: bool,
    ) -> Result<(), Unsupported> {
        let (d, n) = (self.d, self.d * self.p);
        self.piece_from.set(a);
        let mut k = [[0.0; MAX_DIM]; 4];
        let mut ks = vec![vec![0.0; n]; 4];
        let (mut xt, mut st) = ([0.0; MAX_DIM], vec![0.0; n]);
        // Substeps of length h from `start`: `step` done of `steps`; `taken`
        // before `start`.
        let (mut start, mut steps, mut step, mut taken) = (a, SUBSTEPS, 0, 0);
        let mut h = (b - a) / SUBSTEPS as f64;
        while step < steps {
            let t = start + step as f64 * h;
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
                if stage == 0 {
                    let rate = self.rate_bound(stuck);
                    let needed = ((b - t) * rate / STABLE_REACH).ceil();
                    if needed > (steps - step) as f64 {
                        // Stiffer than the substeps left can follow: from t on, finer.
                        taken += step;
                        if !(needed <= (MAX_SUBSTEPS - taken) as f64) {
                            return Err(Unsupported::Stiff { t, rate });
                        }
                        steps = needed as usize;
                        (start, step, h) = (t, 0, (b - t) / steps as f64);
                    }
                }
            }
            // (RK4) y += h/6·(k1 + 2k2 + 2k3 + k4)
            for i in 0..d {
                x[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
            }
            for i in 0..n {
                s[i] += h / 6.0 * (ks[0][i] + 2.0 * ks[1][i] + 2.0 * ks[2][i] + ks[3][i]);
            }
            step += 1;
        }
        Ok(())
    }

    /// f_x and f_θ at the last evaluation into `a` (d×d) and `b` (d×p),
    /// rows of z and v zero when `stuck`; f itself is returned.
    fn linearisation(&self, stuck: bool, a: &mut [f64], b: &mut [f64]) -> [f64; MAX_DIM] {
        let (d, p) = (self.d, self.p);
        self.frozen_rows(stuck, d, d, a);
        self.frozen_rows(stuck, d + d * d, p, b);
        let out = self.out.borrow();
        std::array::from_fn(|i| match i < d && !(stuck && i < 2) {
            true => out[i],
            false => 0.0,
        })
    }

    /// One step of Radau IIA (2 stages, order 3, L-stable) of the linear
    /// Ṡ = f_x·S + f_θ over a sample interval [t0, t1] with neither an event
    /// nor an input breakpoint inside. x is not integrated: at t1 it is the
    /// replay's sample, at the stage t0 + h/3 the cubic Hermite interpolant
    /// of the samples and their derivatives. Three tape evaluations instead
    /// of RK4's sixteen, and stable however stiff the field (a saturated
    /// Jiles–Atherton core). `false` (S untouched) if the stage system is
    /// singular.
    #[allow(clippy::too_many_arguments)]
    fn radau(
        &self,
        (t0, t1): (f64, f64),
        x0: &[f64],
        x1: &[f64],
        s: &mut [f64],
        piece: Affine,
        stuck: bool,
        work: &mut Work,
    ) -> bool {
        let (d, p, h, live) = (self.d, self.p, t1 - t0, self.live.get());
        // (Radau IIA) c = (1/3, 1), A = [`RADAU`]
        const C1: f64 = 1.0 / 3.0;
        self.piece_from.set(t0);
        self.eval(t0, x0, piece.value(t0));
        let f0 = self.linearisation(stuck, &mut work.a[0], &mut work.b[0]);
        self.eval(t1, x1, piece.value(t1));
        let f1 = self.linearisation(stuck, &mut work.a[1], &mut work.b[1]);
        self.input_forcing(t1, stuck, &mut work.b[1]);
        // cubic Hermite at σ = 1/3: h00 = 20/27, h10 = 4/27, h01 = 7/27, h11 = −2/27
        let xm: [f64; MAX_DIM] = std::array::from_fn(|i| match i < d {
            true => (20.0 * x0[i] + 7.0 * x1[i] + h * (4.0 * f0[i] - 2.0 * f1[i])) / 27.0,
            false => 0.0,
        });
        let tm = t0 + C1 * h;
        self.eval_between(tm, &xm, piece.value(tm));
        let [a1, a2] = &mut work.a;
        let [b1, b2] = &mut work.b;
        let fm = self.linearisation(stuck, a1, b1);
        self.input_forcing(tm, stuck, b1);
        // The interpolant's slope at σ = 1/3, (4/3)(x1 − x0)/h − f1/3, must
        // be the field's there: else x moves faster than a cubic follows (a
        // transient within the interval) and RK4 integrates x instead.
        let follows = (0..d).all(|i| {
            let slope = 4.0 / 3.0 * (x1[i] - x0[i]) / h - f1[i] / 3.0;
            (fm[i] - slope).abs() <= HERMITE_DEFECT * (f0[i].abs() + fm[i].abs() + f1[i].abs())
        });
        if !follows {
            return false;
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if !(finite(a1) && finite(a2) && finite(b1) && finite(b2)) {
            return false;
        }
        let (stage, forcing): ([&[f64]; 2], [&[f64]; 2]) = ([a1, a2], [b1, b2]);
        // the three-state models (a saturating core) in 6×6, not padded to 8×8
        match d {
            3 => radau_stages::<3, 6>(h, (d, p, live), stage, forcing, s, &mut work.rhs3),
            _ => radau_stages::<MAX_DIM, { 2 * MAX_DIM }>(
                h,
                (d, p, live),
                stage,
                forcing,
                s,
                &mut work.rhs,
            ),
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
                // R_θ of a bounce v⁺ = −γ·v⁻: ∂v⁺/∂γ = −v⁻.
                if let (Some(j), false) = (self.restitution, stuck) {
                    s[p + j] -= v_before;
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

/// (Radau IIA) A = [[5/12, −1/12], [3/4, 1/4]]
const RADAU: [[f64; 2]; 2] = [[5.0 / 12.0, -1.0 / 12.0], [0.75, 0.25]];

/// The stage system of [`Field::radau`], [Z1; Z2] = S + h·RADAU·[A1·Z1 +
/// B1; A2·Z2 + B2] (A_k = f_x, B_k = f_θ at the stages, row-major, d×d and
/// d×p), solved in blocks of `B` ≥ d rows (`N` = 2·`B`; a block's rows from
/// d on are identity), and S ← Z2. False (S untouched) where the system is
/// singular.
fn radau_stages<const B: usize, const N: usize>(
    h: f64,
    (d, p, live): (usize, usize, usize),
    stage: [&[f64]; 2],
    forcing: [&[f64]; 2],
    s: &mut [f64],
    rhs: &mut nalgebra::OMatrix<f64, nalgebra::Const<N>, nalgebra::Dyn>,
) -> bool
where
    nalgebra::Const<N>: nalgebra::DimMin<nalgebra::Const<N>, Output = nalgebra::Const<N>>,
{
    debug_assert!(N == 2 * B && d <= B);
    let m = nalgebra::SMatrix::<f64, N, N>::from_fn(|r, c| {
        let (bi, i, bk, k) = (r / B, r % B, c / B, c % B);
        let identity = if r == c { 1.0 } else { 0.0 };
        match i < d && k < d {
            true => identity - h * RADAU[bi][bk] * stage[bk][i * d + k],
            false => identity,
        }
    });
    let Some(lu) = Some(m.lu()).filter(|lu| lu.is_invertible()) else {
        return false;
    };
    for j in 0..live {
        for r in 0..N {
            let (bi, i) = (r / B, r % B);
            rhs[(r, j)] = match i < d {
                true => {
                    s[i * p + j]
                        + h * (RADAU[bi][0] * forcing[0][i * p + j]
                            + RADAU[bi][1] * forcing[1][i * p + j])
                }
                false => 0.0,
            };
        }
    }
    if !lu.solve_mut(&mut rhs.columns_mut(0, live)) {
        return false;
    }
    for j in 0..live {
        for i in 0..d {
            s[i * p + j] = rhs[(B + i, j)];
        }
    }
    true
}

/// An upper bound on the spectral radius of the d×d matrix `a` (row-major,
/// d ≤ [`MAX_DIM`]): Fujiwara's bound on the roots of its characteristic
/// polynomial zᵈ + c₁zᵈ⁻¹ + … + c_d (coefficients by Faddeev–LeVerrier),
/// 2·max(|c₁|, |c₂|^½, …, |c_d/2|^(1/d)). Unlike a matrix norm it does not
/// depend on the states' units; ∞ when `a` is not finite.
fn spectral_bound(a: &[f64], d: usize) -> f64 {
    if !a.iter().all(|v| v.is_finite()) {
        return f64::INFINITY;
    }
    // M_k = A·M_{k−1} + c_{k−1}·I, c_k = −tr(A·M_k)/k (M_0 = 0, c_0 = 1).
    let mut m = [0.0; MAX_DIM * MAX_DIM];
    let (mut c_prev, mut bound) = (1.0, 0.0f64);
    for k in 1..=d {
        let mut next = [0.0; MAX_DIM * MAX_DIM];
        for i in 0..d {
            for j in 0..d {
                next[i * d + j] = (0..d).map(|l| a[i * d + l] * m[l * d + j]).sum::<f64>()
                    + if i == j { c_prev } else { 0.0 };
            }
        }
        let trace: f64 = (0..d)
            .map(|i| (0..d).map(|l| a[i * d + l] * next[l * d + i]).sum::<f64>())
            .sum();
        let c = -trace / k as f64;
        if !c.is_finite() {
            return f64::INFINITY;
        }
        let term = if k == d { c.abs() / 2.0 } else { c.abs() };
        bound = bound.max(term.powf(1.0 / k as f64));
        (m, c_prev) = (next, c);
    }
    2.0 * bound
}

/// The sensitivities of `paths` along `trajectory`, a replay of `model`
/// (with its values) driven by `input` (the intervals are cut at its
/// breakpoints, e.g. a voltage edge between samples).
pub fn forward<I: Input + Sync + ?Sized>(
    model: &mut Model,
    paths: &[&str],
    trajectory: &Trajectory,
    input: &I,
) -> Result<OutputSensitivities, Unsupported> {
    forward_with_steps(model, paths, &[], trajectory, input)
}

/// [`forward`] with one more column per step of `steps`: the sensitivities
/// to its instant. The steps must be in order of time and each a
/// breakpoint of `input` where it steps from `before` to `after` (else the
/// jumps are applied late, or where the trajectory has none).
pub fn forward_with_steps<I: Input + Sync + ?Sized>(
    model: &mut Model,
    paths: &[&str],
    steps: &[InputStep],
    trajectory: &Trajectory,
    input: &I,
) -> Result<OutputSensitivities, Unsupported> {
    debug_assert!(
        steps.windows(2).all(|w| w[0].t <= w[1].t),
        "steps out of order"
    );
    let mut theta = symbols(model, paths)?;
    theta.extend(steps.iter().map(|_| Theta::StepInstant));
    if split::worth_it(trajectory.len(), model.dim(), theta.len()) {
        return split::along_in_halves(model, &theta, paths.len(), steps, trajectory, input);
    }
    let field = Field::new(model, &theta, None);
    along(&field, paths.len(), steps, trajectory, input)
}

/// The outputs' response to `perturbations` of the input along
/// `trajectory`, a replay of `model` driven by `input`, linearised: column
/// j of each output is its change per unit of the j-th perturbation (e.g.
/// the current's answer to noise on the voltage's samples; checked against
/// replays of the perturbed input in `identify/tests/sensitivity.rs`).
pub fn input_response<I: Input + ?Sized>(
    model: &mut Model,
    perturbations: InputPerturbations,
    trajectory: &Trajectory,
    input: &I,
) -> Result<OutputSensitivities, Unsupported> {
    let theta = vec![Theta::Input; perturbations.columns.len()];
    let field = Field::new(model, &theta, Some(perturbations));
    along(&field, theta.len(), &[], trajectory, input)
}

/// The sensitivities of `field`'s columns along `trajectory` (driven by
/// `input`), the columns of `steps` from `first_step` on.
fn along<I: Input + ?Sized>(
    field: &Field,
    first_step: usize,
    steps: &[InputStep],
    trajectory: &Trajectory,
    input: &I,
) -> Result<OutputSensitivities, Unsupported> {
    along_from(field, first_step, steps, trajectory, input, None).map(|(out, _)| out)
}

/// [`along`] from S = `s0` (row-major d×p; None: zero) at the trajectory's
/// first sample, and S at its last.
fn along_from<I: Input + ?Sized>(
    field: &Field,
    first_step: usize,
    steps: &[InputStep],
    trajectory: &Trajectory,
    input: &I,
    s0: Option<Vec<f64>>,
) -> Result<(OutputSensitivities, Vec<f64>), Unsupported> {
    let tr = trajectory;
    let (n, d, p) = (tr.t.len(), field.d, field.p);
    let mut out = OutputSensitivities {
        current: DMatrix::zeros(n, p),
        z: DMatrix::zeros(n, p),
        phi: DMatrix::zeros(n, p),
        radau_intervals: 0,
        rk4_intervals: 0,
    };
    let mut s = s0.unwrap_or_else(|| vec![0.0; d * p]);
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
        return Ok((out, s));
    }
    record(0, &s, &mut out);
    let events = &tr.events;
    let mut next = events.iter().take_while(|e| e.t <= tr.t[0]).count();
    let mut work = Work::new(d, p);
    // the next step whose jump is still to be applied
    let mut step = steps.iter().take_while(|e| e.t < tr.t[0]).count();
    field.live.set(first_step + step);
    for k in 0..n - 1 {
        let t1 = tr.t[k + 1];
        let mut x = tr.x[k];
        let mut mode = tr.mode[k];
        let mut a = tr.t[k];
        let smooth = events.get(next).is_none_or(|e| e.t > t1)
            && input.next_breakpoint(a) >= t1
            && steps.get(step).is_none_or(|e| e.t >= t1);
        let stuck = mode != Mode::Free;
        if smooth
            && field.radau(
                (a, t1),
                &x,
                &tr.x[k + 1],
                &mut s,
                input.piece(a),
                stuck,
                &mut work,
            )
        {
            out.radau_intervals += 1;
            record(k + 1, &s, &mut out);
            continue;
        }
        out.rk4_intervals += 1;
        // Pieces of the interval between the input's breakpoints and the
        // events, each integrated with its own affine piece of u.
        loop {
            while let Some(e) = steps.get(step).filter(|e| e.t <= a) {
                let stuck = mode != Mode::Free;
                let (before, after) = (
                    field.f(a, &x, e.before, stuck),
                    field.f(a, &x, e.after, stuck),
                );
                for i in 0..d {
                    s[i * p + first_step + step] += before[i] - after[i];
                }
                step += 1;
                field.live.set(first_step + step);
            }
            let event = events.get(next).filter(|e| e.t <= t1);
            let b = input
                .next_breakpoint(a)
                .min(event.map_or(t1, |e| e.t))
                .min(steps.get(step).map_or(t1, |e| e.t.max(a)))
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
                )?;
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
    Ok((out, s))
}

#[cfg(test)]
mod tests {
    use super::{radau_stages, spectral_bound, MAX_DIM};

    /// The stage system of a three-state model solved as 6×6 gives the bits
    /// the 8×8 padded one gave (finite, normal pivots: the padding's rows
    /// never pivot, and their zeros add nothing), on pseudo-random stiff
    /// and mild systems with zeros and ties among the entries.
    #[test]
    fn the_three_state_stage_system_is_the_padded_one() {
        let mut rng = designer::random::SplitMix64::new(29);
        let mut uniform = || rng.uniform();
        let (d, p) = (3, 5);
        for case in 0..2_000 {
            let mut entry = |scale: f64| match (uniform() * 6.0) as usize {
                0 => 0.0,
                1 => 1.0,
                _ => scale * (2.0 * uniform() - 1.0),
            };
            let scale = [1.0, 1e3, 1e8][case % 3];
            let a: [Vec<f64>; 2] =
                std::array::from_fn(|_| (0..d * d).map(|_| entry(scale)).collect());
            let b: [Vec<f64>; 2] =
                std::array::from_fn(|_| (0..d * p).map(|_| entry(1.0)).collect());
            let s0: Vec<f64> = (0..d * p).map(|_| entry(1.0)).collect();
            let h = 40e-6;
            let stage = [a[0].as_slice(), a[1].as_slice()];
            let forcing = [b[0].as_slice(), b[1].as_slice()];
            let (mut s6, mut s8) = (s0.clone(), s0.clone());
            let mut rhs6 = nalgebra::OMatrix::<f64, nalgebra::Const<6>, nalgebra::Dyn>::zeros(p);
            let mut rhs8 =
                nalgebra::OMatrix::<f64, nalgebra::Const<{ 2 * MAX_DIM }>, nalgebra::Dyn>::zeros(p);
            let ok6 = radau_stages::<3, 6>(h, (d, p, p), stage, forcing, &mut s6, &mut rhs6);
            let ok8 = radau_stages::<MAX_DIM, { 2 * MAX_DIM }>(
                h,
                (d, p, p),
                stage,
                forcing,
                &mut s8,
                &mut rhs8,
            );
            assert_eq!(ok6, ok8, "case {case}");
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&s6), bits(&s8), "case {case}");
        }
    }

    /// At least the spectral radius (within 2× of it for these), the same
    /// for the matrix in other units (D·A·D⁻¹), ∞ when not finite.
    #[test]
    fn the_spectral_bound_holds_and_ignores_units() {
        // eigenvalues −1, −1e4 (a stiff pair), with a coupling
        let a = [-1.0, 3.0, 0.0, -1e4];
        let b = spectral_bound(&a, 2);
        assert!((1e4..=2.0 * 1e4 * 1.01).contains(&b), "{b}");
        // the same matrix in other units: D·A·D⁻¹, D = diag(1, 1e-9)
        let scaled = [-1.0, 3.0e9, 0.0, -1e4];
        assert_eq!(spectral_bound(&scaled, 2), b);
        // a rotation: eigenvalues ±5i
        let rot = [0.0, 5.0, -5.0, 0.0];
        let r = spectral_bound(&rot, 2);
        assert!((5.0..=10.0).contains(&r), "{r}");
        // 4×4 triangular: eigenvalues on the diagonal, the largest 7
        let t = [
            -2.0, 1.0, 0.0, 5.0, 0.0, -7.0, 2.0, 0.0, 0.0, 0.0, 3.0, 1.0, 0.0, 0.0, 0.0, -1.0,
        ];
        let tb = spectral_bound(&t, 4);
        assert!((7.0..=14.0 * 1.5).contains(&tb), "{tb}");
        assert_eq!(spectral_bound(&[f64::NAN, 0.0, 0.0, 0.0], 2), f64::INFINITY);
        assert_eq!(
            spectral_bound(&[1e300, 1e300, 1e300, 1e300], 2),
            f64::INFINITY
        );
    }
}
