//! The fit of [JA 80] with the instants of the record's voltage edges among
//! its parameters.
//!
//! An edge's instant τ is placed with a model ([`crate::edges::located`]) and the
//! model's values are fitted on the placed edges: the two depend on each
//! other. Alternating them converges slowly where they are coupled (on the
//! hidden-fringing benchmark record the winding length still moves by 33
//! white-noise standard errors in the third round, by a third a round;
//! on the hidden-hysteresis record the core's length by 5 % between the
//! second and third). Here the Levenberg–Marquardt solver moves both at
//! once: each placed edge's instant is one more parameter, its column of
//! the Jacobian the sensitivity to the instant of a step of the input
//! ([`crate::sensitivity::forward_with_steps`]: x jumps by (f⁻ − f⁺)·δτ there).
//!
//! An edge is parametrised by where it falls in its sample interval,
//! y = 1 + (τ − t_k)/Δt (of order one, for the solver's scaling), kept
//! [`INSIDE`] of a sample from either end: at t_k itself the replay would
//! step the input at the sample, a cost with a step at the bound.
//! Edges placed at the midpoint (`located == false`: the current could not
//! place them) stay there.
//!
//! The flux term's integrated reference ([JA 80] with `use_flux`) is the
//! samples' trapezoid, which knows nothing of the edges: it pulls the
//! instants towards the midpoints. The diagnosis fits the current alone.

use nalgebra::DMatrix;

use crate::description::Description;
use crate::edges::{Edge, INSIDE};
use crate::em_fit::{self, FitError, FitOptions, FitParam, FitReport, Sensitivities};
use crate::identifiability::Sensitivity;
use crate::lm;
use crate::sensitivity::InputStep;
use crate::Measured;

/// The most edges whose instants are fitted: one column of the Jacobian
/// each (a record of thousands of steps, e.g. a slow PWM, would make it
/// hundreds of MB). Beyond, every edge stays where it was placed and only
/// the values are fitted. (The diagnose benchmark's 44 309-sample records
/// hold 17 in their fitted part.)
pub const MAX_FITTED_EDGES: usize = 64;

/// Indices of `data`'s located edges whose interval lies inside the record.
fn located_inside(data: &Measured) -> Vec<usize> {
    let edges = data.edges.as_deref().unwrap_or_default();
    (0..edges.len())
        .filter(|&n| edges[n].located && edges[n].k + 1 < data.len())
        .collect()
}

/// Whether [`fit_with_edges`] holds every edge of `data` where it was
/// placed: more located edges than [`MAX_FITTED_EDGES`].
pub fn holds_edges(data: &Measured) -> bool {
    located_inside(data).len() > MAX_FITTED_EDGES
}

/// The placed edges of a record, and which of them are fitted.
struct Instants<'a> {
    data: &'a Measured,
    placed: Vec<Edge>,
    /// Indices into `placed` of the fitted edges (the located ones whose
    /// interval lies inside the record).
    free: Vec<usize>,
}

impl<'a> Instants<'a> {
    fn of(data: &'a Measured) -> Instants<'a> {
        let placed = data.edges.clone().unwrap_or_default();
        let mut free = located_inside(data);
        if free.len() > MAX_FITTED_EDGES {
            free.clear();
        }
        Instants { data, placed, free }
    }

    /// Sample interval of the `n`-th fitted edge.
    fn interval(&self, n: usize) -> (f64, f64) {
        let k = self.placed[self.free[n]].k;
        (self.data.t[k], self.data.t[k + 1] - self.data.t[k])
    }

    /// y of each fitted edge.
    fn start(&self) -> Vec<f64> {
        (0..self.free.len())
            .map(|n| {
                let (t0, dt) = self.interval(n);
                1.0 + ((self.placed[self.free[n]].tau - t0) / dt).clamp(INSIDE, 1.0 - INSIDE)
            })
            .collect()
    }

    /// The edges with the fitted ones at `y`.
    fn edges(&self, y: &[f64]) -> Vec<Edge> {
        let mut edges = self.placed.clone();
        for (n, &yn) in y.iter().enumerate() {
            let (t0, dt) = self.interval(n);
            edges[self.free[n]].tau = t0 + (yn - 1.0).clamp(0.0, 1.0) * dt;
        }
        edges
    }

    /// The record driven by the edges at `y`.
    fn driven(&self, y: &[f64]) -> Measured {
        Measured {
            edges: Some(self.edges(y)),
            ..self.data.clone()
        }
    }

    /// The fitted edges as steps of the input (for their sensitivities).
    fn steps(&self, edges: &[Edge]) -> Vec<InputStep> {
        self.free
            .iter()
            .map(|&n| {
                let e = edges[n];
                InputStep {
                    t: e.tau,
                    before: self.data.v[e.k],
                    after: self.data.v[e.k + 1],
                }
            })
            .collect()
    }
}

/// The fit of the values and the edges' instants.
#[derive(Debug, Clone)]
pub struct EdgeFit {
    /// The values' fit at the fitted instants. Its standard errors
    /// (`sensitivity.relative_std_errors`) are marginal over the instants,
    /// which the same noise moves; its singular values and weak directions
    /// are the values' alone.
    pub report: FitReport,
    /// The record's edges, the located ones at their fitted instants.
    pub edges: Vec<Edge>,
    /// ∂r/∂(θ, y) at the optimum: the values' columns (original units),
    /// then one per fitted edge (y = 1 + its place in its interval).
    pub jacobian: DMatrix<f64>,
}

/// Fits `params` of `description` and the instants of `data`'s located
/// edges together (at most [`MAX_FITTED_EDGES`]). One start, whatever
/// `options.starts`: the description's values and the placed instants.
pub fn fit_with_edges(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> Result<EdgeFit, FitError> {
    let instants = Instants::of(data);
    let setup = em_fit::Setup::new(description, data, params, options)?;
    let p = params.len();
    let x0: Vec<f64> = setup.x0.iter().copied().chain(instants.start()).collect();
    let bounds: Vec<(f64, f64)> = (setup.bounds.iter().copied())
        .chain(instants.free.iter().map(|_| (1.0 + INSIDE, 2.0 - INSIDE)))
        .collect();
    let paths: Vec<&str> = params.iter().map(|q| q.path.as_str()).collect();
    let analytic = em_fit::analytic_jacobian(description, &paths, options);
    let budget = setup.objective.budget;
    let split = |y: &[f64]| -> Option<(Description, Measured)> {
        let d = em_fit::with_values(description, params, &y[..p]).ok()?;
        Some((d, instants.driven(&y[p..])))
    };
    let replayed = |y: &[f64]| -> Option<(Description, Measured, crate::replay::Replay)> {
        let (d, driven) = split(y)?;
        let replay = em_fit::replay(&d, &driven, &budget).ok()?;
        Some((d, driven, replay))
    };
    let residual = |y: &[f64]| {
        let (d, _, replay) = replayed(y)?;
        Some(
            setup
                .objective
                .residuals_of(&d, &em_fit::outputs(&d, &replay)),
        )
    };
    let kept = em_fit::KeptReplay::default();
    let keeping = |y: &[f64]| {
        let (d, _, replay) = replayed(y)?;
        let r = setup
            .objective
            .residuals_of(&d, &em_fit::outputs(&d, &replay));
        kept.keep(y, replay.trajectory);
        Some(r)
    };
    let jacobian = |y: &[f64]| {
        let (d, driven) = split(y)?;
        let trajectory = kept.at(y, || {
            em_fit::replay(&d, &driven, &budget)
                .ok()
                .map(|r| r.trajectory)
        })?;
        let steps = instants.steps(driven.edges.as_deref()?);
        let mut j =
            (setup.objective).jacobian_with_steps(&d, &paths, &steps, &driven, &trajectory)?;
        // ∂τ/∂y = Δt
        for n in 0..steps.len() {
            let dt = instants.interval(n).1;
            j.column_mut(p + n).scale_mut(dt);
        }
        Some(j)
    };
    let lm_options = em_fit::lm_options(options);
    let result = match analytic {
        true => {
            lm::minimize_with_jacobian(keeping, jacobian, &x0, &bounds, &lm_options, &mut |_| {})
        }
        false => lm::minimize(residual, &x0, &bounds, &lm_options, &mut |_| {}),
    };
    let report = result.map_err(|e| FitError::Solver {
        file: data.file_name.clone(),
        message: e.to_string(),
    })?;
    let (fitted, driven) = split(&report.theta).ok_or_else(|| FitError::Solver {
        file: data.file_name.clone(),
        message: "the fitted values are not a description".into(),
    })?;
    let errors = setup.objective.errors(&fitted, &driven)?;
    let names: Vec<String> = paths.iter().map(|s| s.to_string()).collect();
    let fit = FitReport {
        sensitivity: sensitivity_of(&names, &report),
        values: names
            .into_iter()
            .zip(report.theta[..p].iter().copied())
            .collect(),
        description: fitted,
        wnrmse_current: errors.current,
        wnrmse_flux: errors.flux,
        nrmse_position: errors.position,
        cost: 2.0 * report.cost,
        iterations: report.iterations,
        simulations: report.evaluations + 1 + kept.replays(),
        sensitivities: match analytic {
            true => Sensitivities::Analytic,
            false => Sensitivities::FiniteDifference,
        },
        status: report.status,
        best_start: 0,
        differenced_jacobians: report.differenced_jacobians,
        scanned_threshold: None,
    };
    Ok(EdgeFit {
        report: fit,
        edges: driven.edges.unwrap_or_default(),
        jacobian: report.jacobian,
    })
}

/// The values' sensitivity (the first `names.len()` columns of the
/// solver's Jacobian), with standard errors marginal over the instants.
fn sensitivity_of(names: &[String], report: &lm::Report) -> Sensitivity {
    let p = names.len();
    let values = report.jacobian.columns(0, p).into_owned();
    let mut s = Sensitivity::from_jacobian(names, &values, &report.theta[..p], &report.residuals);
    let mut all = names.to_vec();
    all.extend((p..report.theta.len()).map(|n| format!("edge {}", n - p)));
    let joint =
        Sensitivity::from_jacobian(&all, &report.jacobian, &report.theta, &report.residuals);
    s.relative_std_errors = joint.relative_std_errors[..p].to_vec();
    s
}
