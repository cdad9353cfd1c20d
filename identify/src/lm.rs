//! Bounded Levenberg–Marquardt least squares: minimise ½‖r(θ)‖² over a box
//! lower ≤ θ ≤ upper.
//!
//! - **Scaling.** The solver works on variables y of order one: y = ln θ for
//!   a positive parameter whose bounds span a decade or more (a relative
//!   step is then the same everywhere in its range), y = θ/s otherwise, with
//!   s the start's magnitude (or the bounds' width when the start is 0).
//! - **Step.** Levenberg–Marquardt with Moré's diagonal scaling D (the
//!   largest column norms of the Jacobian seen so far): h solves
//!   (JᵀJ + μ·DᵀD)·h = −Jᵀr on the free variables, through the SVD of J·D⁻¹,
//!   so one factorisation serves every trial μ of an iteration.
//! - **Bounds.** A variable on a bound whose gradient points out of the box
//!   is held there (the active set); the others' step is projected onto the
//!   box. The gain ratio uses the model's prediction of the projected step.
//! - **Damping.** Nielsen's update: μ·max(1/3, 1 − (2ρ − 1)³) after a
//!   success, μ·ν (ν doubling) after a failure. A failed evaluation (`None`,
//!   e.g. a simulation that did not finish) counts as a failure.
//! - **Stopping.** Relative cost decrease (actual and predicted ≤ ftol·cost),
//!   step size (‖h‖∞ ≤ xtol in scaled units), gradient (largest cosine
//!   between r and a free column of J ≤ gtol, MINPACK's test), the
//!   iteration cap, or too many failures in a row.
//! - **Jacobian.** Given by the caller, or forward differences in y, the
//!   columns evaluated in parallel (rayon) when the residual is `Fn + Sync`
//!   ([`minimize`]) and in turn when it is only `FnMut` ([`minimize_mut`]).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// Solver settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    pub max_iterations: usize,
    /// Relative cost decrease below which the solver stops.
    pub ftol: f64,
    /// Step (∞-norm, scaled variables) below which the solver stops.
    pub xtol: f64,
    /// Cosine between r and the columns of J below which the solver stops.
    pub gtol: f64,
    /// Forward-difference step in scaled variables.
    pub fd_step: f64,
    /// μ at the start, relative to the scaled JᵀJ (whose diagonal is ≤ 1).
    pub initial_damping: f64,
    /// Consecutive rejected steps before giving up.
    pub max_rejections: usize,
    /// Stops the solver before its next trial step once raised (from
    /// another thread: a start whose result is no longer needed).
    pub stop: Option<Stop>,
    /// Gives up a start that is still far above a cost known to be
    /// reachable ([`Status::GaveUp`]).
    pub give_up: Option<GiveUp>,
    /// What a trial whose residual could not be evaluated does to μ.
    pub on_failed_evaluation: OnFailedEvaluation,
}

/// The damping after a trial step whose residual could not be evaluated
/// (`None`, e.g. a replay over its step budget).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OnFailedEvaluation {
    /// As after a cost increase: μ·ν, ν doubling (after n failures in a row
    /// μ has grown 2^(n(n+1)/2)-fold, and a step ∝ 1/μ as much shorter).
    #[default]
    Nielsen,
    /// The least μ·2^k that halves the step's largest component: n failures
    /// in a row shorten the step 2^n-fold, and the damping stays near the
    /// longest step that can be evaluated.
    HalveStep,
}

/// After `after` accepted iterations, a cost (½‖r‖²) above `above` ends
/// the minimisation ([`Status::GaveUp`]): a start that cannot come near a
/// fit found elsewhere is not worth its remaining iterations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GiveUp {
    pub after: usize,
    pub above: f64,
}

impl GiveUp {
    /// Whether a cost of `cost` after `iterations` accepted iterations gives up
    /// (a NaN cost does).
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // deliberate: NaN gives up
    pub fn gives_up(&self, iterations: usize, cost: f64) -> bool {
        iterations == self.after && !(cost <= self.above)
    }
}

/// A flag that stops a running minimisation ([`Status::Stopped`]).
#[derive(Debug, Clone, Default)]
pub struct Stop(Arc<AtomicBool>);

impl Stop {
    pub fn raise(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    pub fn raised(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// Two flags are equal when they are the same flag.
impl PartialEq for Stop {
    fn eq(&self, other: &Stop) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl Default for Options {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            ftol: 1e-10,
            xtol: 1e-10,
            gtol: 1e-10,
            fd_step: 1e-6,
            initial_damping: 1e-3,
            max_rejections: 30,
            stop: None,
            give_up: None,
            on_failed_evaluation: OnFailedEvaluation::Nielsen,
        }
    }
}

/// Why the solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// The cost decreased by less than `ftol` relative, as predicted.
    CostConverged,
    /// The step fell below `xtol`.
    StepConverged,
    /// The (projected) gradient vanished (`gtol`).
    GradientConverged,
    /// `max_iterations` reached.
    MaxIterations,
    /// `max_rejections` steps in a row failed to decrease the cost.
    NoProgress,
    /// The Jacobian could not be evaluated at the last point.
    JacobianFailed,
    /// [`Options::stop`] was raised.
    Stopped,
    /// [`Options::give_up`]: still too far from a fit found elsewhere.
    GaveUp,
}

impl Status {
    /// Whether the solver stopped at a (local) minimum.
    pub fn converged(self) -> bool {
        matches!(
            self,
            Status::CostConverged | Status::StepConverged | Status::GradientConverged
        )
    }
}

/// The result of a minimisation.
#[derive(Debug, Clone)]
pub struct Report {
    pub theta: Vec<f64>,
    /// ½‖r‖² at `theta`.
    pub cost: f64,
    pub residuals: Vec<f64>,
    /// ∂r/∂θ at `theta` (original units; one column per parameter).
    pub jacobian: DMatrix<f64>,
    pub iterations: usize,
    /// Residual evaluations, finite differences included.
    pub evaluations: usize,
    /// Of [`minimize_with_jacobian`]'s Jacobians, those the caller could not
    /// give and the solver differenced instead.
    pub differenced_jacobians: usize,
    pub status: Status,
}

/// What the monitor sees after each iteration.
#[derive(Debug, Clone)]
pub struct Iteration<'a> {
    pub iteration: usize,
    pub cost: f64,
    pub theta: &'a [f64],
    pub damping: f64,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LmError {
    #[error("parameter {index}: bounds [{lower:e}, {upper:e}] are not an interval (need lower < upper, no NaN)")]
    Bounds {
        index: usize,
        lower: f64,
        upper: f64,
    },
    #[error("{bounds} bounds for {parameters} parameters")]
    Dimension { parameters: usize, bounds: usize },
    #[error("the residuals could not be evaluated at the start point")]
    Start,
    #[error("the Jacobian could not be evaluated at the start point")]
    StartJacobian,
}

/// Minimises with a forward-difference Jacobian whose columns are
/// evaluated in parallel.
pub fn minimize<F>(
    residual: F,
    x0: &[f64],
    bounds: &[(f64, f64)],
    options: &Options,
    monitor: &mut dyn FnMut(&Iteration),
) -> Result<Report, LmError>
where
    F: Fn(&[f64]) -> Option<Vec<f64>> + Sync,
{
    let count = AtomicUsize::new(0);
    let f = |x: &[f64]| {
        count.fetch_add(1, Ordering::Relaxed);
        residual(x)
    };
    let map = Map::new(x0, bounds)?;
    let mut problem = Problem {
        map: &map,
        residual: |y: &[f64]| f(&map.theta(y)),
        jacobian: |y: &[f64], r: &[f64]| {
            let columns: Vec<Option<Vec<f64>>> = (0..y.len())
                .into_par_iter()
                .map(|j| fd_column(&map, &f, y, r, j, options.fd_step))
                .collect();
            assemble(columns, r.len())
        },
    };
    let mut report = solve(&mut problem, options, monitor)?;
    report.evaluations = count.load(Ordering::Relaxed);
    Ok(report)
}

/// [`minimize`] for a residual that is only `FnMut` (columns in turn).
pub fn minimize_mut<F>(
    residual: F,
    x0: &[f64],
    bounds: &[(f64, f64)],
    options: &Options,
    monitor: &mut dyn FnMut(&Iteration),
) -> Result<Report, LmError>
where
    F: FnMut(&[f64]) -> Option<Vec<f64>>,
{
    let count = std::cell::Cell::new(0);
    let f = std::cell::RefCell::new(residual);
    let call = |x: &[f64]| {
        count.set(count.get() + 1);
        (f.borrow_mut())(x)
    };
    let map = Map::new(x0, bounds)?;
    let mut problem = Problem {
        map: &map,
        residual: |y: &[f64]| call(&map.theta(y)),
        jacobian: |y: &[f64], r: &[f64]| fd_jacobian(&map, &call, y, r, options.fd_step),
    };
    let mut report = solve(&mut problem, options, monitor)?;
    report.evaluations = count.get();
    Ok(report)
}

/// Minimises with the caller's Jacobian ∂r/∂θ (original units); where it
/// has none (`None`, or not finite) with forward differences of `residual`.
pub fn minimize_with_jacobian<F, J>(
    residual: F,
    mut jacobian: J,
    x0: &[f64],
    bounds: &[(f64, f64)],
    options: &Options,
    monitor: &mut dyn FnMut(&Iteration),
) -> Result<Report, LmError>
where
    F: FnMut(&[f64]) -> Option<Vec<f64>>,
    J: FnMut(&[f64]) -> Option<DMatrix<f64>>,
{
    let (count, differenced) = (std::cell::Cell::new(0), std::cell::Cell::new(0));
    let f = std::cell::RefCell::new(residual);
    let call = |x: &[f64]| {
        count.set(count.get() + 1);
        (f.borrow_mut())(x)
    };
    let map = Map::new(x0, bounds)?;
    let mut problem = Problem {
        map: &map,
        residual: |y: &[f64]| call(&map.theta(y)),
        jacobian: |y: &[f64], r: &[f64]| match jacobian(&map.theta(y)) {
            Some(mut jac) if finite(jac.as_slice()) => {
                for j in 0..y.len() {
                    let d = map.dtheta_dy(y, j);
                    jac.column_mut(j).scale_mut(d);
                }
                Some(jac)
            }
            _ => {
                differenced.set(differenced.get() + 1);
                fd_jacobian(&map, &call, y, r, options.fd_step)
            }
        },
    };
    let mut report = solve(&mut problem, options, monitor)?;
    report.evaluations = count.get();
    report.differenced_jacobians = differenced.get();
    Ok(report)
}

// ---------------------------------------------------------------- scaling

/// How θ_j depends on the solver's y_j.
#[derive(Debug, Clone, Copy)]
enum Scale {
    /// θ = exp(y)
    Log,
    /// θ = s·y
    Linear(f64),
}

/// Bounds at which a positive parameter is solved for in ln θ.
const LOG_RATIO: f64 = 10.0;

struct Map {
    scales: Vec<Scale>,
    /// Bounds and start in y.
    lower: Vec<f64>,
    upper: Vec<f64>,
    y0: Vec<f64>,
}

impl Map {
    fn new(x0: &[f64], bounds: &[(f64, f64)]) -> Result<Map, LmError> {
        if x0.len() != bounds.len() {
            return Err(LmError::Dimension {
                parameters: x0.len(),
                bounds: bounds.len(),
            });
        }
        let mut map = Map {
            scales: vec![],
            lower: vec![],
            upper: vec![],
            y0: vec![],
        };
        for (index, (&x, &(lower, upper))) in x0.iter().zip(bounds).enumerate() {
            if !(lower < upper) {
                return Err(LmError::Bounds {
                    index,
                    lower,
                    upper,
                });
            }
            let x = x.clamp(lower, upper);
            let scale = if lower > 0.0 && upper >= LOG_RATIO * lower {
                Scale::Log
            } else if x != 0.0 && x.is_finite() {
                Scale::Linear(x.abs())
            } else if (upper - lower).is_finite() {
                Scale::Linear(upper - lower)
            } else {
                Scale::Linear(1.0)
            };
            let to_y = |t: f64| match scale {
                Scale::Log => t.ln(),
                Scale::Linear(s) => t / s,
            };
            map.scales.push(scale);
            map.lower.push(to_y(lower));
            map.upper.push(to_y(upper));
            map.y0.push(to_y(x));
        }
        Ok(map)
    }

    fn theta(&self, y: &[f64]) -> Vec<f64> {
        (0..y.len()).map(|j| self.theta_j(y[j], j)).collect()
    }

    fn theta_j(&self, y: f64, j: usize) -> f64 {
        match self.scales[j] {
            Scale::Log => y.exp(),
            Scale::Linear(s) => s * y,
        }
    }

    fn dtheta_dy(&self, y: &[f64], j: usize) -> f64 {
        match self.scales[j] {
            Scale::Log => y[j].exp(),
            Scale::Linear(s) => s,
        }
    }

    /// The forward-difference step of y_j (a relative step for ln θ).
    fn fd_step(&self, y: &[f64], j: usize, step: f64) -> f64 {
        match self.scales[j] {
            Scale::Log => step,
            Scale::Linear(_) => step * y[j].abs().max(1.0),
        }
    }
}

/// Column j of ∂r/∂y by a forward difference (backward at the upper bound
/// or when the forward point fails).
fn fd_column<F>(map: &Map, f: &F, y: &[f64], r: &[f64], j: usize, step: f64) -> Option<Vec<f64>>
where
    F: Fn(&[f64]) -> Option<Vec<f64>>,
{
    let h = map.fd_step(y, j, step);
    let forward = y[j] + h <= map.upper[j];
    let signs: [f64; 2] = if forward { [1.0, -1.0] } else { [-1.0, 1.0] };
    for sign in signs {
        let mut yj = y.to_vec();
        yj[j] = (y[j] + sign * h).clamp(map.lower[j], map.upper[j]);
        let dh = yj[j] - y[j];
        if dh == 0.0 {
            continue;
        }
        if let Some(rj) = f(&map.theta(&yj)).filter(|rj| rj.len() == r.len() && finite(rj)) {
            return Some(rj.iter().zip(r).map(|(a, b)| (a - b) / dh).collect());
        }
    }
    None
}

/// The forward-difference Jacobian at `y`, one column after the other.
fn fd_jacobian<F>(map: &Map, f: &F, y: &[f64], r: &[f64], step: f64) -> Option<DMatrix<f64>>
where
    F: Fn(&[f64]) -> Option<Vec<f64>>,
{
    let columns = (0..y.len())
        .map(|j| fd_column(map, f, y, r, j, step))
        .collect();
    assemble(columns, r.len())
}

fn assemble(columns: Vec<Option<Vec<f64>>>, rows: usize) -> Option<DMatrix<f64>> {
    let columns: Vec<Vec<f64>> = columns.into_iter().collect::<Option<_>>()?;
    let flat: Vec<f64> = columns.concat();
    Some(DMatrix::from_vec(rows, columns.len(), flat))
}

// ------------------------------------------------------------------ solver

struct Problem<'m, R, J> {
    map: &'m Map,
    /// r(y)
    residual: R,
    /// ∂r/∂y at (y, r(y))
    jacobian: J,
}

/// State of the iteration in scaled variables.
struct Point {
    y: Vec<f64>,
    r: DVector<f64>,
    cost: f64,
    jac: DMatrix<f64>,
}

/// The Jacobian at `y` when it is finite (the SVD of a matrix with a NaN
/// never ends).
fn jacobian_at<R, J>(p: &mut Problem<R, J>, y: &[f64], r: &[f64]) -> Option<DMatrix<f64>>
where
    J: FnMut(&[f64], &[f64]) -> Option<DMatrix<f64>>,
{
    (p.jacobian)(y, r).filter(|jac| finite(jac.as_slice()))
}

fn solve<R, J>(
    p: &mut Problem<R, J>,
    options: &Options,
    monitor: &mut dyn FnMut(&Iteration),
) -> Result<Report, LmError>
where
    R: FnMut(&[f64]) -> Option<Vec<f64>>,
    J: FnMut(&[f64], &[f64]) -> Option<DMatrix<f64>>,
{
    let y = p.map.y0.clone();
    let r = (p.residual)(&y)
        .filter(|r| finite(r))
        .ok_or(LmError::Start)?;
    let jac = jacobian_at(p, &y, &r).ok_or(LmError::StartJacobian)?;
    let r = DVector::from_vec(r);
    let mut pt = Point {
        cost: 0.5 * r.norm_squared(),
        y,
        r,
        jac,
    };
    let mut diag = column_norms(&pt.jac);
    let mut mu = options.initial_damping;
    let mut nu = 2.0;
    let mut iterations = 0;
    let status = loop {
        if iterations >= options.max_iterations {
            break Status::MaxIterations;
        }
        if options.stop.as_ref().is_some_and(Stop::raised) {
            break Status::Stopped;
        }
        update_diag(&mut diag, &pt.jac);
        let g = pt.jac.tr_mul(&pt.r);
        let free = free_variables(p.map, &pt.y, &g);
        if gradient_small(&pt, &g, &free, options.gtol) {
            break Status::GradientConverged;
        }
        let step = Step::new(&pt.jac, &pt.r, &free, &diag);
        match try_steps(p, &mut pt, &step, &g, (&mut mu, &mut nu), options) {
            Outcome::Accepted { small_decrease } => {
                iterations += 1;
                let theta = p.map.theta(&pt.y);
                monitor(&Iteration {
                    iteration: iterations,
                    cost: pt.cost,
                    theta: &theta,
                    damping: mu,
                });
                match jacobian_at(p, &pt.y, pt.r.as_slice()) {
                    Some(jac) => pt.jac = jac,
                    None => break Status::JacobianFailed,
                }
                if small_decrease {
                    break Status::CostConverged;
                }
                if options
                    .give_up
                    .is_some_and(|g| g.gives_up(iterations, pt.cost))
                {
                    break Status::GaveUp;
                }
            }
            Outcome::Stop(status) => break status,
        }
    };
    Ok(report(p.map, pt, iterations, status))
}

enum Outcome {
    Accepted { small_decrease: bool },
    Stop(Status),
}

/// Trial steps with increasing damping until one decreases the cost.
fn try_steps<R, J>(
    p: &mut Problem<R, J>,
    pt: &mut Point,
    step: &Step,
    g: &DVector<f64>,
    (mu, nu): (&mut f64, &mut f64),
    options: &Options,
) -> Outcome
where
    R: FnMut(&[f64]) -> Option<Vec<f64>>,
{
    for _ in 0..options.max_rejections {
        if options.stop.as_ref().is_some_and(Stop::raised) {
            return Outcome::Stop(Status::Stopped);
        }
        let h = step.projected(p.map, &pt.y, *mu);
        if h.amax() <= options.xtol {
            return Outcome::Stop(Status::StepConverged);
        }
        // Predicted decrease of the linear model: −gᵀh − ½‖J·h‖².
        let jh = &pt.jac * &h;
        let predicted = -g.dot(&h) - 0.5 * jh.norm_squared();
        let y_new: Vec<f64> = pt.y.iter().zip(h.iter()).map(|(y, h)| y + h).collect();
        let trial = (p.residual)(&y_new).filter(|r| r.len() == pt.r.len() && finite(r));
        if let Some(r_new) = trial {
            let r_new = DVector::from_vec(r_new);
            let cost = 0.5 * r_new.norm_squared();
            let actual = pt.cost - cost;
            let rho = if predicted > 0.0 {
                actual / predicted
            } else {
                -1.0
            };
            if actual > 0.0 && rho > 1e-4 {
                let small = actual <= options.ftol * pt.cost && predicted <= options.ftol * pt.cost;
                // Nielsen's update.
                *mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                *nu = 2.0;
                *pt = Point {
                    y: y_new,
                    r: r_new,
                    cost,
                    jac: std::mem::replace(&mut pt.jac, DMatrix::zeros(0, 0)),
                };
                return Outcome::Accepted {
                    small_decrease: small,
                };
            }
            if actual.abs() <= options.ftol * pt.cost && predicted <= options.ftol * pt.cost {
                return Outcome::Stop(Status::CostConverged);
            }
        } else if options.on_failed_evaluation == OnFailedEvaluation::HalveStep {
            *mu = damping_that_halves(step, p.map, &pt.y, *mu, h.amax());
            continue;
        }
        *mu *= *nu;
        *nu *= 2.0;
    }
    Outcome::Stop(Status::NoProgress)
}

/// The least μ·2^k (k ≥ 1) whose step's largest component is at most half
/// of `amax` (μ·2^64 at most).
fn damping_that_halves(step: &Step, map: &Map, y: &[f64], mu: f64, amax: f64) -> f64 {
    let mut mu = mu;
    for _ in 0..64 {
        mu *= 2.0;
        if step.projected(map, y, mu).amax() <= 0.5 * amax {
            break;
        }
    }
    mu
}

/// The SVD of the scaled free columns, J_f·D_f⁻¹ = U·S·Vᵀ, and Uᵀr.
struct Step {
    free: Vec<usize>,
    diag: Vec<f64>,
    s: Vec<f64>,
    v_t: DMatrix<f64>,
    ut_r: DVector<f64>,
    n: usize,
}

impl Step {
    fn new(jac: &DMatrix<f64>, r: &DVector<f64>, free: &[usize], diag: &[f64]) -> Step {
        let rows = jac.nrows();
        let scaled = DMatrix::from_fn(rows, free.len(), |i, k| jac[(i, free[k])] / diag[free[k]]);
        let svd = scaled.svd(true, true);
        let (u, v_t) = match (svd.u, svd.v_t) {
            (Some(u), Some(v_t)) => (u, v_t),
            _ => (DMatrix::zeros(rows, 0), DMatrix::zeros(0, free.len())),
        };
        Step {
            free: free.to_vec(),
            diag: free.iter().map(|&j| diag[j]).collect(),
            s: svd.singular_values.iter().copied().collect(),
            ut_r: u.tr_mul(r),
            v_t,
            n: jac.ncols(),
        }
    }

    /// h = project(y + δ) − y, δ_f = −D_f⁻¹·V·diag(s/(s² + μ))·Uᵀr.
    fn projected(&self, map: &Map, y: &[f64], mu: f64) -> DVector<f64> {
        let coeff = DVector::from_iterator(
            self.s.len(),
            self.s
                .iter()
                .zip(self.ut_r.iter())
                .map(|(s, ur)| -s * ur / (s * s + mu)),
        );
        let delta = self.v_t.tr_mul(&coeff);
        let mut h = DVector::zeros(self.n);
        for (k, &j) in self.free.iter().enumerate() {
            let target = (y[j] + delta[k] / self.diag[k]).clamp(map.lower[j], map.upper[j]);
            h[j] = target - y[j];
        }
        h
    }
}

/// Variables not held on a bound: on a bound, a variable stays free only if
/// the descent direction −g points into the box.
fn free_variables(map: &Map, y: &[f64], g: &DVector<f64>) -> Vec<usize> {
    (0..y.len())
        .filter(|&j| {
            let at_lower = y[j] <= map.lower[j] && g[j] > 0.0;
            let at_upper = y[j] >= map.upper[j] && g[j] < 0.0;
            !(at_lower || at_upper)
        })
        .collect()
}

/// MINPACK's gradient test on the free variables: max |J_jᵀr|/(‖J_j‖·‖r‖).
fn gradient_small(pt: &Point, g: &DVector<f64>, free: &[usize], gtol: f64) -> bool {
    let rn = pt.r.norm();
    if rn == 0.0 {
        return true;
    }
    free.iter().all(|&j| {
        let cn = pt.jac.column(j).norm();
        cn == 0.0 || g[j].abs() / (cn * rn) <= gtol
    })
}

fn column_norms(jac: &DMatrix<f64>) -> Vec<f64> {
    (0..jac.ncols()).map(|j| jac.column(j).norm()).collect()
}

/// Moré's scaling: the largest column norm seen (a column that has always
/// been zero gets 1).
fn update_diag(diag: &mut [f64], jac: &DMatrix<f64>) {
    for (d, n) in diag.iter_mut().zip(column_norms(jac)) {
        *d = d.max(n);
    }
    for d in diag.iter_mut() {
        if *d == 0.0 {
            *d = 1.0;
        }
    }
}

fn finite(r: &[f64]) -> bool {
    r.iter().all(|x| x.is_finite())
}

fn report(map: &Map, pt: Point, iterations: usize, status: Status) -> Report {
    let mut jacobian = pt.jac;
    for j in 0..pt.y.len() {
        let d = map.dtheta_dy(&pt.y, j);
        jacobian.column_mut(j).scale_mut(1.0 / d);
    }
    Report {
        theta: map.theta(&pt.y),
        cost: pt.cost,
        residuals: pt.r.iter().copied().collect(),
        jacobian,
        iterations,
        evaluations: 0,
        differenced_jacobians: 0,
        status,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quiet(_: &Iteration) {}

    fn rosenbrock(x: &[f64]) -> Option<Vec<f64>> {
        Some(vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]])
    }

    /// Rosenbrock from (−1.2, 1) in [−5, 5]² with the Jacobian `jac`.
    fn rosenbrock_with_jacobian(jac: impl FnMut(&[f64]) -> Option<DMatrix<f64>>) -> Report {
        let bounds = [(-5.0, 5.0), (-5.0, 5.0)];
        minimize_with_jacobian(
            rosenbrock,
            jac,
            &[-1.2, 1.0],
            &bounds,
            &Options::default(),
            &mut quiet,
        )
        .unwrap()
    }

    #[test]
    fn rosenbrock_as_least_squares() {
        let bounds = [(-5.0, 5.0), (-5.0, 5.0)];
        let rep = minimize(
            rosenbrock,
            &[-1.2, 1.0],
            &bounds,
            &Options::default(),
            &mut quiet,
        )
        .unwrap();
        assert!(rep.status.converged(), "{:?}", rep.status);
        assert!(
            (rep.theta[0] - 1.0).abs() < 1e-8 && (rep.theta[1] - 1.0).abs() < 1e-8,
            "{:?}",
            rep.theta
        );
        assert!(rep.cost < 1e-20);
        // The same with the exact Jacobian, and sequentially.
        let jac = |x: &[f64]| {
            Some(DMatrix::from_row_slice(
                2,
                2,
                &[-20.0 * x[0], 10.0, -1.0, 0.0],
            ))
        };
        let exact = rosenbrock_with_jacobian(jac);
        assert!((exact.theta[0] - 1.0).abs() < 1e-10, "{:?}", exact.theta);
        let seq = minimize_mut(
            rosenbrock,
            &[-1.2, 1.0],
            &bounds,
            &Options::default(),
            &mut quiet,
        )
        .unwrap();
        assert_eq!(
            seq.theta, rep.theta,
            "parallel and sequential columns agree bit for bit"
        );
    }

    #[test]
    fn a_raised_stop_ends_the_solver_before_its_next_step() {
        let bounds = [(-5.0, 5.0), (-5.0, 5.0)];
        let stop = Stop::default();
        let options = Options {
            stop: Some(stop.clone()),
            ..Options::default()
        };
        // raised by the monitor (another thread in `diagnose`) after 3 iterations
        let mut raise_at_3 = |it: &Iteration| {
            if it.iteration == 3 {
                stop.raise();
            }
        };
        let rep = minimize(rosenbrock, &[-1.2, 1.0], &bounds, &options, &mut raise_at_3).unwrap();
        assert_eq!((rep.status, rep.iterations), (Status::Stopped, 3));
        assert!(!rep.status.converged());
        // the flag stays raised: the next run stops at the start point
        assert!(stop.raised());
        let rep = minimize(rosenbrock, &[-1.2, 1.0], &bounds, &options, &mut quiet).unwrap();
        assert_eq!((rep.status, rep.iterations), (Status::Stopped, 0));
        assert_eq!(rep.theta, vec![-1.2, 1.0]);
        // a flag is equal to its clones only
        assert_eq!(options.stop, Some(stop.clone()));
        assert_ne!(options.stop, Some(Stop::default()));
    }

    #[test]
    fn a_start_above_the_give_up_cost_after_its_iterations_ends_there() {
        let bounds = [(-5.0, 5.0), (-5.0, 5.0)];
        let mut costs = Vec::new();
        let full = minimize(
            rosenbrock,
            &[-1.2, 1.0],
            &bounds,
            &Options::default(),
            &mut |it| costs.push(it.cost),
        )
        .unwrap();
        assert!(full.status.converged() && full.iterations > 3, "{full:?}");
        let with = |above: f64| Options {
            give_up: Some(GiveUp { after: 3, above }),
            ..Options::default()
        };
        // still above after 3 iterations: ends there, at that point
        let rep = minimize(
            rosenbrock,
            &[-1.2, 1.0],
            &bounds,
            &with(0.5 * costs[2]),
            &mut quiet,
        )
        .unwrap();
        assert_eq!((rep.status, rep.iterations), (Status::GaveUp, 3));
        assert_eq!(rep.cost, costs[2]);
        assert!(!rep.status.converged());
        // at or below it: runs on as without the rule, bit for bit
        let rep = minimize(
            rosenbrock,
            &[-1.2, 1.0],
            &bounds,
            &with(costs[2]),
            &mut quiet,
        )
        .unwrap();
        assert_eq!((rep.status, rep.iterations), (full.status, full.iterations));
        assert_eq!(rep.theta, full.theta);
        // a NaN cost gives up; other iterations never do
        let g = GiveUp {
            after: 3,
            above: 1.0,
        };
        assert!(g.gives_up(3, f64::NAN) && g.gives_up(3, 1.5));
        assert!(!g.gives_up(2, 1.5) && !g.gives_up(4, 1.5) && !g.gives_up(3, 1.0));
    }

    #[test]
    fn a_jacobian_the_caller_cannot_give_is_differenced() {
        // None at every other call, NaN at the rest: the solver must neither
        // stop nor hand a NaN to its SVD (which would never return).
        let calls = std::cell::Cell::new(0);
        let jac = |x: &[f64]| {
            calls.set(calls.get() + 1);
            match calls.get() % 2 {
                0 => None,
                _ => Some(DMatrix::from_row_slice(
                    2,
                    2,
                    &[f64::NAN, 10.0, -1.0, 0.0 * x[0]],
                )),
            }
        };
        let rep = rosenbrock_with_jacobian(jac);
        assert!(rep.status.converged(), "{:?}", rep.status);
        assert!((rep.theta[0] - 1.0).abs() < 1e-8, "{:?}", rep.theta);
        assert!(calls.get() > 2 && rep.evaluations > calls.get());
        // every one of them differenced, and counted
        assert_eq!(rep.differenced_jacobians, calls.get());
    }

    #[test]
    fn exponential_fit_recovers_known_parameters() {
        // y = a·exp(−b·t) + c with a = 3, b = 40 (spans decades: log scaling), c = 0.5.
        let t: Vec<f64> = (0..60).map(|k| k as f64 * 2e-3).collect();
        let y: Vec<f64> = t.iter().map(|t| 3.0 * (-40.0 * t).exp() + 0.5).collect();
        let f = |x: &[f64]| {
            Some(
                t.iter()
                    .zip(&y)
                    .map(|(t, y)| x[0] * (-x[1] * t).exp() + x[2] - y)
                    .collect(),
            )
        };
        let bounds = [(0.0, 10.0), (1.0, 1e4), (-2.0, 2.0)];
        let rep = minimize(
            f,
            &[1.0, 300.0, 0.0],
            &bounds,
            &Options::default(),
            &mut quiet,
        )
        .unwrap();
        for (got, want) in rep.theta.iter().zip([3.0, 40.0, 0.5]) {
            assert!((got - want).abs() < 1e-7 * want, "{:?}", rep.theta);
        }
        // ∂r/∂b = −a·t·exp(−b·t) at the solution, in original units.
        for (k, t) in t.iter().enumerate().step_by(7) {
            let exact = -3.0 * t * (-40.0 * t).exp();
            assert!((rep.jacobian[(k, 1)] - exact).abs() < 1e-5 * 3.0 * 2e-3 + 1e-6 * exact.abs());
        }
    }

    #[test]
    fn an_active_bound_stops_the_parameter_on_it() {
        // min (x − 3)² + (y + 1)² over x ≤ 2, y ≥ 0: the solution is (2, 0).
        let f = |x: &[f64]| Some(vec![x[0] - 3.0, x[1] + 1.0]);
        let rep = minimize(
            f,
            &[0.5, 1.0],
            &[(-1.0, 2.0), (0.0, 5.0)],
            &Options::default(),
            &mut quiet,
        )
        .unwrap();
        assert_eq!(rep.theta, vec![2.0, 0.0]);
        assert!(rep.status.converged(), "{:?}", rep.status);
        assert!((rep.cost - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_failed_evaluation_halves_the_step_with_the_least_damping() {
        let map = Map::new(&[0.5, -0.2], &[(-5.0, 5.0), (-5.0, 5.0)]).unwrap();
        let jac = DMatrix::from_row_slice(3, 2, &[1.0, 0.2, 0.0, 3.0, 0.5, 0.1]);
        let r = DVector::from_vec(vec![1.0, -2.0, 0.5]);
        let step = Step::new(&jac, &r, &[0, 1], &[1.1, 3.0]);
        let y = map.y0.clone();
        for mu in [1e-6, 1e-2, 1.0, 1e3] {
            let amax = step.projected(&map, &y, mu).amax();
            let halved = damping_that_halves(&step, &map, &y, mu, amax);
            assert!(step.projected(&map, &y, halved).amax() <= 0.5 * amax);
            assert!(
                step.projected(&map, &y, 0.5 * halved).amax() > 0.5 * amax || halved == 2.0 * mu
            );
        }
    }

    #[test]
    fn halving_the_step_after_failed_evaluations_takes_fewer_evaluations() {
        // r = eˣ − e, undefined from x = 1.2 on: from x = −3 the Gauss–Newton
        // step is 50 long, far into the undefined part, and again from every
        // point short of the minimum. Both rules reach x = 1; halving the
        // step raises μ no more, and takes fewer evaluations (24 against 27).
        let f = |x: &[f64]| (x[0] < 1.2).then(|| vec![x[0].exp() - 1f64.exp()]);
        let run = |rule| {
            let mut top = 0.0f64;
            let mut watch = |it: &Iteration| top = top.max(it.damping);
            let options = Options {
                on_failed_evaluation: rule,
                ..Options::default()
            };
            let rep = minimize(f, &[-3.0], &[(-10.0, 10.0)], &options, &mut watch).unwrap();
            assert!(rep.status.converged(), "{rule:?}: {:?}", rep.status);
            assert!(
                (rep.theta[0] - 1.0).abs() < 1e-6,
                "{rule:?}: {:?}",
                rep.theta
            );
            (top, rep.evaluations)
        };
        let nielsen = run(OnFailedEvaluation::Nielsen);
        let halving = run(OnFailedEvaluation::HalveStep);
        assert!(
            halving.0 <= nielsen.0,
            "largest μ {halving:?} against {nielsen:?}"
        );
        assert!(
            halving.1 < nielsen.1,
            "evaluations {halving:?} against {nielsen:?}"
        );
    }

    #[test]
    fn failed_evaluations_shrink_the_step() {
        // The residual is undefined beyond x = 1.5; the minimum of (x − 1)² is inside.
        let f = |x: &[f64]| (x[0] < 1.5).then(|| vec![10.0 * (x[0] - 1.0)]);
        let rep = minimize(
            f,
            &[-20.0],
            &[(-100.0, 100.0)],
            &Options::default(),
            &mut quiet,
        )
        .unwrap();
        assert!((rep.theta[0] - 1.0).abs() < 1e-9, "{:?}", rep);
        assert_eq!(
            minimize(
                |_: &[f64]| None,
                &[0.0],
                &[(-1.0, 1.0)],
                &Options::default(),
                &mut quiet
            )
            .unwrap_err(),
            LmError::Start
        );
        assert!(matches!(
            minimize(
                rosenbrock,
                &[0.0, 0.0],
                &[(1.0, 0.0), (0.0, 1.0)],
                &Options::default(),
                &mut quiet
            ),
            Err(LmError::Bounds { index: 0, .. })
        ));
    }
}
