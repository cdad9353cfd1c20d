//! The electromagnetic fit of jiles-atherton-actuator-model [JA §5.2]: parameters
//! of a description chosen to minimise [JA 80],
//!
//! ```text
//! wNRMSE²(i) + wNRMSE²(φ) [+ NRMSE²(z)]
//! ```
//!
//! where each simulated signal comes from replaying the measured voltage
//! (linear between samples, as `reldesign simulate --input` does) through the
//! hybrid model from rest. The weights are |φ̇| estimated from the data
//! ([`weighted`](super::weighted)) with the starting description's R and N,
//! fixed for the whole fit (weights that moved with θ would let the fit lower
//! its error by reweighting). The flux term is used when asked: against the
//! data's flux column, or else the flux integrated from v − R·i with each
//! candidate's own R and N; the position term, normalised by the stroke,
//! whenever the data has `z`.
//! Residuals are √w·(sim − exp)/‖exp‖_w so that ‖r‖² is the objective.
//!
//! Sensitivities are analytic where the symbolic core gives them
//! ([`sensitivity`](super::sensitivity): forward sensitivity equations along
//! the replay, [`Sensitivities::Analytic`]); otherwise (the bounce
//! threshold, a term the model lacks, or when asked), and for any one
//! Jacobian the sensitivities cannot give (a field too stiff for them),
//! forward differences of whole replays: the replays run at a tight
//! tolerance ([`FitOptions::rtol`]) so that a relative step of
//! [`FitOptions::fd_step`] sees a smooth function.
//! Several starts ([`FitOptions::starts`]) are drawn deterministically from
//! the bounds (log-uniform for positive parameters spanning a decade or more)
//! and fitted in parallel; the best fit is kept (the first on a tie, as if
//! they had run one after the other).

use std::cell::{Cell, RefCell};

use nalgebra::DMatrix;
use rayon::prelude::*;

use crate::description::{Core, Description, Drive};
use crate::model::{Model, ModelPlant};
use crate::replay::{replay_plant, Replay};
use crate::sim::{Options, Trajectory};

use super::identifiability::Sensitivity;
use super::lm::{self, LmError, Status};
use super::measured::Measured;
use super::params::{self, ParamError};
use super::sensitivity;
use super::weighted::{flux_from_data, flux_rate_weights, has_measured_flux, wnrmse};

/// One parameter to fit, by TOML key path, with its bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct FitParam {
    pub path: String,
    pub lower: f64,
    pub upper: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// Number of starts: the description's values, then those of
    /// [`FitOptions::also_from`], then the rest drawn from the bounds.
    pub starts: usize,
    /// Start points given (the fitted parameters' values, in order; clamped
    /// into the bounds), tried after the description's values and before
    /// the drawn ones, within `starts`.
    pub also_from: Vec<Vec<f64>>,
    /// Levenberg–Marquardt iterations per start.
    pub max_iterations: usize,
    /// Include the flux term of [JA 80].
    pub use_flux: bool,
    /// Include NRMSE²(z) when the data has a `z` column.
    pub use_position: bool,
    /// Seed of the drawn starts.
    pub seed: u64,
    /// Relative tolerance of the replays.
    pub rtol: f64,
    /// Forward-difference step (relative, in the solver's scaled variables).
    pub fd_step: f64,
    /// Relative decrease of the objective below which a start stops.
    pub ftol: f64,
    /// Integration steps (accepted and rejected) a replay may take per
    /// sample of the record: a trial parameter set that makes the model so
    /// stiff that it needs more fails fast, and the solver shrinks its step.
    pub max_steps_per_sample: usize,
    /// A trial replay may take at most this many times the steps of the
    /// start's replay (None: only the per-sample cap); see
    /// [`TRIAL_STEPS_OVER_START`], the default.
    pub trial_steps_over_start: Option<usize>,
    /// How the Jacobian is computed (analytic falls back to finite
    /// differences when a fitted parameter has no analytic sensitivity).
    pub sensitivities: Sensitivities,
    /// Stops the fit before its next trial step once raised (its report
    /// then has the status [`lm::Status::Stopped`]).
    pub stop: Option<lm::Stop>,
    /// Gives each start up that is still above a cost after some
    /// iterations ([`lm::GiveUp`], in the solver's ½‖r‖²: half the report's
    /// `cost`).
    pub give_up: Option<lm::GiveUp>,
    /// Fits only this one of the `starts` (0: the description's values),
    /// drawn as always: the same fit as that start's among all of them.
    pub only_start: Option<usize>,
}

/// How the fit's Jacobian is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sensitivities {
    /// Forward sensitivity equations along the replay (see
    /// [`sensitivity`](super::sensitivity)).
    Analytic,
    /// Forward differences of whole replays.
    FiniteDifference,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            starts: 1,
            max_iterations: 50,
            use_flux: true,
            use_position: true,
            seed: 1,
            rtol: 1e-10,
            fd_step: 1e-6,
            ftol: 1e-8,
            max_steps_per_sample: 200,
            trial_steps_over_start: Some(TRIAL_STEPS_OVER_START),
            sensitivities: Sensitivities::Analytic,
            stop: None,
            give_up: None,
            only_start: None,
            also_from: Vec::new(),
        }
    }
}

/// Reported after every iteration of every start (the starts run in
/// parallel: their reports interleave).
#[derive(Debug, Clone, PartialEq)]
pub struct FitProgress {
    /// 0-based start index.
    pub start: usize,
    pub starts: usize,
    pub iteration: usize,
    /// The objective [JA 80] at the current iterate.
    pub objective: f64,
}

#[derive(Debug, Clone)]
pub struct FitReport {
    /// The description with the fitted values.
    pub description: Description,
    /// (path, fitted value), in the order of the fitted parameters.
    pub values: Vec<(String, f64)>,
    /// [JA 81] for the current, after the fit.
    pub wnrmse_current: f64,
    /// [JA 81] for the flux, after the fit (when a flux reference exists).
    pub wnrmse_flux: Option<f64>,
    /// RMS position error over the stroke (when the data has `z`).
    pub nrmse_position: Option<f64>,
    /// The objective [JA 80] minimised: the sum of the squared errors used.
    pub cost: f64,
    /// Solver iterations, all starts.
    pub iterations: usize,
    /// Replays, all starts, finite differences and sensitivity replays
    /// included.
    pub simulations: usize,
    /// The Jacobian actually used (analytic only when every fitted
    /// parameter has an analytic sensitivity).
    pub sensitivities: Sensitivities,
    /// Of an analytic fit's Jacobians, those made by finite differences
    /// instead (the sensitivities gave up: a stiff field, a failed replay).
    pub differenced_jacobians: usize,
    /// Why the best start stopped.
    pub status: Status,
    /// Which start gave the best fit (0 = the description's values).
    pub best_start: usize,
    pub sensitivity: Sensitivity,
    /// Where a scan after the fit moved the bounce threshold v_ε
    /// (`diagnose::bounce_threshold`, which has no gradient): the interval
    /// of v_ε whose replay is the same as the one chosen (between two
    /// levels of the impact speeds of the model the scan started from).
    /// `None` otherwise.
    pub scanned_threshold: Option<[f64; 2]>,
}

/// Simulated signals at the data's sample times.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutputs {
    pub t: Vec<f64>,
    pub current: Vec<f64>,
    pub voltage: Vec<f64>,
    pub z: Vec<f64>,
    pub phi: Vec<f64>,
    /// H_c (Jiles–Atherton core only).
    pub h_c: Option<Vec<f64>>,
    /// Automaton mode 1, 2, 3 (stuck at z_min, free, stuck at z_max).
    pub mode: Vec<u8>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error("{model}: fitting replays the measured voltage, but supply.drive = \"current\"; use drive = \"voltage\"")]
    CurrentDrive { model: String },
    #[error("{file}: the voltage column cannot be replayed: {message}")]
    Input { file: String, message: String },
    #[error("{file}: the replay through {model} failed: {message}")]
    Simulation {
        file: String,
        model: String,
        message: String,
    },
    #[error("no parameter to fit: give at least one")]
    NoParameters,
    #[error("parameter `{path}` is given twice")]
    Duplicate { path: String },
    #[error("parameter `{path}`: bounds [{lower:e}, {upper:e}] must satisfy lower < upper within the parameter's domain")]
    Bounds {
        path: String,
        lower: f64,
        upper: f64,
    },
    #[error(
        "{file}: the measured current is zero wherever the flux changes: wNRMSE (81) has no scale"
    )]
    NoScale { file: String },
    #[error("{file}: no start point could be simulated: {message}")]
    Solver { file: String, message: String },
}

/// [JA 81] of the current for one replay of `d` (the diagnose baseline).
pub fn current_wnrmse(d: &Description, data: &Measured) -> Result<f64, FitError> {
    let out = simulate_outputs(d, data)?;
    let w = flux_rate_weights(data, d.coil.turns, d.coil.resistance);
    Ok(wnrmse(&out.current, &data.i, &w))
}

/// Replays the measured voltage through `d` (default fit tolerance).
pub fn simulate_outputs(d: &Description, data: &Measured) -> Result<SimOutputs, FitError> {
    simulate_with(d, data, &Budget::of(&FitOptions::default()))
}

/// Accuracy and effort of one replay.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Budget {
    rtol: f64,
    max_steps_per_sample: usize,
    /// At most this many steps in all (as well as per sample).
    max_steps: usize,
}

impl Budget {
    fn of(options: &FitOptions) -> Budget {
        Budget {
            rtol: options.rtol,
            max_steps_per_sample: options.max_steps_per_sample,
            max_steps: usize::MAX,
        }
    }

    /// The steps one replay of `samples` samples may take (at least 10 000).
    fn steps_for(&self, samples: usize) -> usize {
        (self.max_steps_per_sample.saturating_mul(samples))
            .min(self.max_steps)
            .max(10_000)
    }
}

/// A trial replay may take at most this many times the steps of the start's
/// replay (within the options' own per-sample cap) by default
/// ([`FitOptions::trial_steps_over_start`]). A trial that makes the
/// model stiff fails fast and the solver shortens its step: on the
/// benchmark's 40 000-sample Jiles–Atherton fit the first step reached
/// c's bound, where the replay took 93 steps a sample against the start's
/// 2.3 (3 s a replay), and the Jacobian there, differenced since the
/// sensitivities give up on so stiff a field, took five more: 18 of the
/// fit's 20 s. (The diagnosis's ranking fits cap every replay at 4 steps a
/// sample in all, `diagnose::Options::max_steps_per_sample`.) A fit that
/// caps its trials also halves the step after a failed one
/// ([`lm::OnFailedEvaluation::HalveStep`]).
pub const TRIAL_STEPS_OVER_START: usize = 4;

/// The replays of one start: the first (the start's) at the options'
/// budget, every later one within `over_start` times its steps.
struct TrialReplays<'a> {
    budget: Budget,
    over_start: Option<usize>,
    data: &'a Measured,
    start_steps: std::cell::OnceCell<usize>,
}

impl<'a> TrialReplays<'a> {
    fn new(options: &FitOptions, data: &'a Measured) -> Self {
        TrialReplays {
            budget: Budget::of(options),
            over_start: options.trial_steps_over_start,
            data,
            start_steps: std::cell::OnceCell::new(),
        }
    }

    fn replay(&self, d: &Description) -> Option<Replay> {
        let budget = match (self.start_steps.get(), self.over_start) {
            (Some(&steps), Some(k)) => Budget {
                max_steps: steps.saturating_mul(k),
                ..self.budget
            },
            _ => self.budget,
        };
        let replay = replay(d, self.data, &budget).ok()?;
        self.start_steps
            .get_or_init(|| replay.trajectory.stats.attempted());
        Some(replay)
    }
}

fn simulate_with(
    d: &Description,
    data: &Measured,
    budget: &Budget,
) -> Result<SimOutputs, FitError> {
    Ok(outputs(d, &replay(d, data, budget)?))
}

/// The signals of one replay of `d`.
pub(crate) fn outputs(d: &Description, replay: &Replay) -> SimOutputs {
    let tr = &replay.trajectory;
    let field = matches!(d.core, Core::JilesAtherton(_));
    SimOutputs {
        t: tr.t.clone(),
        current: replay.current.clone(),
        voltage: replay.voltage.clone(),
        z: tr.x.iter().map(|x| x[0]).collect(),
        phi: tr.x.iter().map(|x| x[2]).collect(),
        h_c: field.then(|| tr.x.iter().map(|x| x[3]).collect()),
        mode: tr.mode.iter().map(|m| m.number()).collect(),
    }
}

/// The measured voltage replayed through `d` from rest.
pub(crate) fn replay(
    d: &Description,
    data: &Measured,
    budget: &Budget,
) -> Result<Replay, FitError> {
    if d.supply.drive == Drive::Current {
        return Err(FitError::CurrentDrive {
            model: d.source.file_name.clone(),
        });
    }
    let input = super::edges::replay_input(data).map_err(|e| FitError::Input {
        file: data.file_name.clone(),
        message: e.to_string(),
    })?;
    let mut model = Model::build(d);
    let plant = ModelPlant::new(&mut model);
    let options = Options {
        rtol: budget.rtol,
        max_steps: budget.steps_for(data.t.len()),
        ..Options::default()
    };
    replay_plant(&plant, &model, &input, &data.t, &options).map_err(|e| FitError::Simulation {
        file: data.file_name.clone(),
        model: d.source.file_name.clone(),
        message: e.to_string(),
    })
}

/// The measured references of [JA 80] and their weights.
pub(crate) struct Objective<'a> {
    data: &'a Measured,
    weights: Vec<f64>,
    /// √(Σ w·i²)
    current_norm: f64,
    /// The flux reference, when the flux term is used.
    flux: Option<FluxReference>,
    /// Stroke·√n, when the position is used.
    position_norm: Option<f64>,
    pub(crate) budget: Budget,
}

/// The φ of the flux term: measured, or integrated from v − R·i with the
/// candidate's own R and N (the integral drifts with a wrong R, so a
/// reference fixed at the start's R would pull R away from the truth).
enum FluxReference {
    Measured(Vec<f64>),
    Integrated,
}

/// The errors of one replay.
pub(crate) struct Errors {
    pub(crate) current: f64,
    pub(crate) flux: Option<f64>,
    pub(crate) position: Option<f64>,
}

impl<'a> Objective<'a> {
    fn new(d: &Description, data: &'a Measured, options: &FitOptions) -> Result<Self, FitError> {
        let (turns, resistance) = (d.coil.turns, d.coil.resistance);
        let weights = flux_rate_weights(data, turns, resistance);
        let weighted_norm = |x: &[f64]| {
            x.iter()
                .zip(&weights)
                .map(|(x, w)| w * x * x)
                .sum::<f64>()
                .sqrt()
        };
        let current_norm = weighted_norm(&data.i);
        if !(current_norm > 0.0) {
            return Err(FitError::NoScale {
                file: data.file_name.clone(),
            });
        }
        let flux = options.use_flux.then(|| match has_measured_flux(data) {
            true => FluxReference::Measured(flux_from_data(data, turns, resistance)),
            false => FluxReference::Integrated,
        });
        let stroke = d.mechanics.z_max - d.mechanics.z_min;
        let position_norm = match (&data.z, options.use_position) {
            (Some(z), true) => Some(stroke * (z.len() as f64).sqrt()),
            _ => None,
        };
        Ok(Objective {
            data,
            weights,
            current_norm,
            flux,
            position_norm,
            budget: Budget::of(options),
        })
    }

    /// The flux reference for `d` and its weighted norm √(Σ w·φ²) (none
    /// when not used or identically zero).
    fn flux_reference(&self, d: &Description) -> Option<(Vec<f64>, f64)> {
        let phi = match self.flux.as_ref()? {
            FluxReference::Measured(phi) => phi.clone(),
            FluxReference::Integrated => flux_from_data(self.data, d.coil.turns, d.coil.resistance),
        };
        let norm = phi
            .iter()
            .zip(&self.weights)
            .map(|(x, w)| w * x * x)
            .sum::<f64>()
            .sqrt();
        (norm > 0.0).then_some((phi, norm))
    }

    /// Residuals √w·(sim − exp)/norm: ‖r‖² is the objective [JA 80].
    fn residuals(&self, d: &Description) -> Result<Vec<f64>, FitError> {
        Ok(self.residuals_of(d, &simulate_with(d, self.data, &self.budget)?))
    }

    /// The |φ̇| weights of the current's residuals and their norm √(Σ w·i²):
    /// the current's row k of the residuals is √w_k·(i_sim − i_k)/norm.
    pub(crate) fn current_weights(&self) -> (&[f64], f64) {
        (&self.weights, self.current_norm)
    }

    /// [`residuals`](Self::residuals) of the signals `out` of `d`.
    pub(crate) fn residuals_of(&self, d: &Description, out: &SimOutputs) -> Vec<f64> {
        let sw: Vec<f64> = self.weights.iter().map(|w| w.sqrt()).collect();
        let mut r: Vec<f64> = (0..self.data.len())
            .map(|k| sw[k] * (out.current[k] - self.data.i[k]) / self.current_norm)
            .collect();
        if let Some((phi, norm)) = self.flux_reference(d) {
            r.extend((0..phi.len()).map(|k| sw[k] * (out.phi[k] - phi[k]) / norm));
        }
        if let (Some(norm), Some(z)) = (self.position_norm, &self.data.z) {
            r.extend(z.iter().zip(&out.z).map(|(e, s)| (s - e) / norm));
        }
        r
    }

    /// ∂r/∂θ of [`residuals`](Self::residuals) from the forward
    /// sensitivities along `trajectory`, the replay of `d` (none: an
    /// unsupported parameter).
    fn jacobian(
        &self,
        d: &Description,
        paths: &[&str],
        trajectory: &Trajectory,
    ) -> Option<DMatrix<f64>> {
        self.jacobian_with_steps(d, paths, &[], self.data, trajectory)
    }

    /// [`jacobian`](Self::jacobian) with one more column per step of
    /// `steps` (∂r/∂t of its instant), `driven` the record whose edges
    /// drove the replay.
    pub(crate) fn jacobian_with_steps(
        &self,
        d: &Description,
        paths: &[&str],
        steps: &[sensitivity::InputStep],
        driven: &Measured,
        trajectory: &Trajectory,
    ) -> Option<DMatrix<f64>> {
        let input = super::edges::replay_input(driven).ok()?;
        let mut model = Model::build(d);
        let s =
            sensitivity::forward_with_steps(&mut model, paths, steps, trajectory, &input).ok()?;
        let (n, p) = (self.data.len(), paths.len() + steps.len());
        let sw: Vec<f64> = self.weights.iter().map(|w| w.sqrt()).collect();
        let flux = self.flux_reference(d).map(|(phi, norm)| {
            let x = &trajectory.x;
            let mut block = DMatrix::zeros(n, p);
            for j in 0..p {
                // (the reference does not depend on the edges' instants)
                let dphi = match paths.get(j) {
                    Some(path) => self.flux_reference_derivative(d, path, &phi),
                    None => vec![0.0; n],
                };
                // ∂‖φ_ref‖_w = Σ w·φ_ref·∂φ_ref / ‖φ_ref‖_w
                let dnorm = (0..n)
                    .map(|k| self.weights[k] * phi[k] * dphi[k])
                    .sum::<f64>()
                    / norm;
                for k in 0..n {
                    let r = sw[k] * (x[k][2] - phi[k]) / norm;
                    block[(k, j)] = sw[k] * (s.phi[(k, j)] - dphi[k]) / norm - r * dnorm / norm;
                }
            }
            block
        });
        Some(self.residual_rows(&s, flux))
    }

    /// The rows of the residuals [`residuals_of`](Self::residuals_of) from
    /// output sensitivities `s` (a column per parameter or perturbation):
    /// the current's, `flux`'s (the flux term's, when the objective has
    /// one), then the position's where the data has it.
    fn residual_rows(
        &self,
        s: &sensitivity::OutputSensitivities,
        flux: Option<DMatrix<f64>>,
    ) -> DMatrix<f64> {
        let (n, p) = (self.data.len(), s.current.ncols());
        let sw: Vec<f64> = self.weights.iter().map(|w| w.sqrt()).collect();
        let mut blocks = vec![DMatrix::from_fn(n, p, |k, j| {
            sw[k] * s.current[(k, j)] / self.current_norm
        })];
        blocks.extend(flux);
        if let (Some(norm), Some(_)) = (self.position_norm, &self.data.z) {
            blocks.push(&s.z / norm);
        }
        let rows = blocks.iter().map(|b| b.nrows()).sum();
        let mut stacked = DMatrix::zeros(rows, p);
        let mut at = 0;
        for b in blocks {
            stacked.rows_mut(at, b.nrows()).copy_from(&b);
            at += b.nrows();
        }
        stacked
    }

    /// The residuals' linearised response to perturbations of the voltage's
    /// samples (`columns`, one per sample of `driven` each), along the
    /// replay of `d` on `driven`: one column per perturbation (None: not
    /// computable, or the objective has the flux term, whose reference the
    /// voltage moves too).
    pub(crate) fn voltage_response(
        &self,
        d: &Description,
        driven: &Measured,
        columns: &[Vec<f64>],
    ) -> Option<DMatrix<f64>> {
        if self.flux_reference(d).is_some() {
            return None;
        }
        let trajectory = replay(d, driven, &self.budget).ok()?.trajectory;
        let input = super::edges::replay_input(driven).ok()?;
        let (knots, sample) = super::edges::replay_knots(driven);
        let perturbations = sensitivity::InputPerturbations {
            knots: &knots,
            sample: &sample,
            columns,
        };
        let mut model = Model::build(d);
        let s = sensitivity::input_response(&mut model, perturbations, &trajectory, &input).ok()?;
        Some(self.residual_rows(&s, None))
    }

    /// ∂φ_ref/∂θ for the parameter `path`: the integrated reference
    /// φ = ∫(v − R·i)/N depends on R and N, a flux linkage λ/N on N.
    fn flux_reference_derivative(&self, d: &Description, path: &str, phi: &[f64]) -> Vec<f64> {
        let integrated = matches!(self.flux, Some(FluxReference::Integrated));
        let n_turns = d.coil.turns;
        match path {
            "coil.turns" if integrated => phi.iter().map(|x| -x / n_turns).collect(),
            "coil.resistance" if integrated => {
                // −∫i dt / N (trapezoidal, as the reference itself)
                let (t, i) = (&self.data.t, &self.data.i);
                let mut acc = 0.0;
                (0..phi.len())
                    .map(|k| {
                        if k > 0 {
                            acc += 0.5 * (t[k] - t[k - 1]) * (i[k - 1] + i[k]);
                        }
                        -acc / n_turns
                    })
                    .collect()
            }
            _ => vec![0.0; phi.len()],
        }
    }

    /// The errors of `d` replayed on `driven` (the record, its edges
    /// perhaps moved).
    pub(crate) fn errors(&self, d: &Description, driven: &Measured) -> Result<Errors, FitError> {
        Ok(self.errors_of(d, &simulate_with(d, driven, &self.budget)?))
    }

    /// The errors of `out`, a replay of `d` already made.
    pub(crate) fn errors_of(&self, d: &Description, out: &SimOutputs) -> Errors {
        Errors {
            current: wnrmse(&out.current, &self.data.i, &self.weights),
            flux: self
                .flux_reference(d)
                .map(|(phi, _)| wnrmse(&out.phi, &phi, &self.weights)),
            position: match (self.position_norm, &self.data.z) {
                (Some(norm), Some(z)) => Some(
                    z.iter()
                        .zip(&out.z)
                        .map(|(e, s)| (s - e).powi(2))
                        .sum::<f64>()
                        .sqrt()
                        / norm,
                ),
                _ => None,
            },
        }
    }
}

/// `d` with the parameters `paths` set to `theta`.
pub(crate) fn with_values(
    d: &Description,
    paths: &[FitParam],
    theta: &[f64],
) -> Result<Description, ParamError> {
    let mut d = d.clone();
    for (p, &x) in paths.iter().zip(theta) {
        params::set(&mut d, &p.path, x)?;
    }
    Ok(d)
}

/// Fits `params` of `description` to `data` (see the module docs).
pub fn fit(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
    progress: &(dyn Fn(FitProgress) + Sync),
) -> Result<FitReport, FitError> {
    let starts = options.starts.max(1);
    if let Some(k) = options.only_start.filter(|&k| k >= starts) {
        return Err(FitError::Solver {
            file: data.file_name.clone(),
            message: format!(
                "start {k} asked for, of {starts} starts (0 to {})",
                starts - 1
            ),
        });
    }
    let setup = Setup::new(description, data, params, options)?;
    let (start0, bounds) = (&setup.x0, &setup.bounds);
    let residual = |theta: &[f64]| setup.residuals(description, params, theta);
    let paths: Vec<&str> = params.iter().map(|p| p.path.as_str()).collect();
    let analytic = analytic_jacobian(description, &paths, options);
    let lm_options = lm_options(options);
    // The starts in parallel (each on its own replays), reduced in their
    // order below: the same best start, sums and report every run.
    let solve = |(k, x0): (usize, &Vec<f64>)| {
        let mut monitor = |it: &lm::Iteration| {
            progress(FitProgress {
                start: k,
                starts,
                iteration: it.iteration,
                objective: 2.0 * it.cost,
            })
        };
        let kept = KeptReplay::default();
        let trials = TrialReplays::new(options, data);
        let keeping = |theta: &[f64]| {
            let d = with_values(description, params, theta).ok()?;
            let replay = trials.replay(&d)?;
            let r = setup.objective.residuals_of(&d, &outputs(&d, &replay));
            kept.keep(theta, replay.trajectory);
            Some(r)
        };
        let jacobian = |theta: &[f64]| {
            let d = with_values(description, params, theta).ok()?;
            let trajectory = kept.at(theta, || trials.replay(&d).map(|r| r.trajectory))?;
            // none (or not finite): `lm` differences the residual instead
            setup.objective.jacobian(&d, &paths, &trajectory)
        };
        let result = match analytic {
            true => {
                lm::minimize_with_jacobian(keeping, jacobian, x0, bounds, &lm_options, &mut monitor)
            }
            false => lm::minimize(residual, x0, bounds, &lm_options, &mut monitor),
        };
        (result, kept.replays())
    };
    let points = start_points(start0, &options.also_from, params, starts, options.seed);
    let results: Vec<_> = (points.par_iter().enumerate())
        .filter(|(k, _)| options.only_start.is_none_or(|only| only == *k))
        .map(|(k, x0)| (k, solve((k, x0))))
        .collect();
    let mut best: Option<(usize, lm::Report)> = None;
    let (mut iterations, mut simulations, mut differenced) = (0, 0, 0);
    let mut jacobian_replays = 0;
    let mut last_error = None;
    for (k, (result, replays)) in results {
        jacobian_replays += replays;
        match result {
            Ok(report) => {
                iterations += report.iterations;
                simulations += report.evaluations;
                differenced += report.differenced_jacobians;
                if best.as_ref().is_none_or(|(_, b)| report.cost < b.cost) {
                    best = Some((k, report));
                }
            }
            Err(e) => last_error = Some(e),
        }
    }
    let (best_start, report) = best.ok_or_else(|| FitError::Solver {
        file: data.file_name.clone(),
        message: last_error.map_or_else(String::new, |e: LmError| e.to_string()),
    })?;
    let fitted = with_values(description, params, &report.theta)?;
    let errors = setup.objective.errors(&fitted, data)?;
    let names: Vec<String> = params.iter().map(|p| p.path.clone()).collect();
    Ok(FitReport {
        sensitivity: Sensitivity::from_jacobian(
            &names,
            &report.jacobian,
            &report.theta,
            &report.residuals,
        ),
        values: names
            .iter()
            .cloned()
            .zip(report.theta.iter().copied())
            .collect(),
        description: fitted,
        wnrmse_current: errors.current,
        wnrmse_flux: errors.flux,
        nrmse_position: errors.position,
        cost: 2.0 * report.cost,
        iterations,
        simulations: simulations + 1 + jacobian_replays,
        sensitivities: match analytic {
            true => Sensitivities::Analytic,
            false => Sensitivities::FiniteDifference,
        },
        status: report.status,
        best_start,
        differenced_jacobians: differenced,
        scanned_threshold: None,
    })
}

/// Whether the fit of `paths` of `d` takes the analytic Jacobian (asked for,
/// and every parameter has a sensitivity).
pub(crate) fn analytic_jacobian(d: &Description, paths: &[&str], options: &FitOptions) -> bool {
    options.sensitivities == Sensitivities::Analytic && sensitivity::check(d, paths).is_ok()
}

/// The replay of the point the solver last evaluated, for the analytic
/// Jacobian it asks for next at the same point (it asks for J where it has
/// just evaluated and accepted); any other point is replayed again, and
/// counted.
#[derive(Default)]
pub(crate) struct KeptReplay {
    last: RefCell<Option<(Vec<f64>, Trajectory)>>,
    replays: Cell<usize>,
}

impl KeptReplay {
    /// Keeps the trajectory replayed at `at`.
    pub(crate) fn keep(&self, at: &[f64], trajectory: Trajectory) {
        *self.last.borrow_mut() = Some((at.to_vec(), trajectory));
    }

    /// The trajectory kept at `at`, or else `replay`'s.
    pub(crate) fn at(
        &self,
        at: &[f64],
        replay: impl FnOnce() -> Option<Trajectory>,
    ) -> Option<Trajectory> {
        match self.last.borrow_mut().take().filter(|(kept, _)| kept == at) {
            Some((_, trajectory)) => Some(trajectory),
            None => {
                self.replays.set(self.replays.get() + 1);
                replay()
            }
        }
    }

    /// Replays made for a Jacobian (none kept at its point).
    pub(crate) fn replays(&self) -> usize {
        self.replays.get()
    }
}

/// The solver's settings of a fit.
pub(crate) fn lm_options(options: &FitOptions) -> lm::Options {
    lm::Options {
        max_iterations: options.max_iterations,
        ftol: options.ftol,
        fd_step: options.fd_step,
        stop: options.stop.clone(),
        give_up: options.give_up,
        // a fit that caps its trials' replays halves the step after a trial
        // over the cap (Nielsen's growth left the benchmark fit's damping
        // 2¹⁵-fold after five such trials)
        on_failed_evaluation: match options.trial_steps_over_start {
            Some(_) => lm::OnFailedEvaluation::HalveStep,
            None => lm::OnFailedEvaluation::Nielsen,
        },
        ..lm::Options::default()
    }
}

/// The sensitivity report of `params` at the description's values (no fit).
pub fn sensitivity_at(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> Result<Sensitivity, FitError> {
    let report = linearised(description, data, params, options)?;
    let names: Vec<String> = params.iter().map(|p| p.path.clone()).collect();
    Ok(Sensitivity::from_jacobian(
        &names,
        &report.jacobian,
        &report.theta,
        &report.residuals,
    ))
}

/// The residuals of [JA 80] and their Jacobian ∂r/∂θ (forward differences)
/// at the description's values of `params` (no fit).
pub fn linearisation(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> Result<(DMatrix<f64>, Vec<f64>), FitError> {
    let report = linearised(description, data, params, options)?;
    Ok((report.jacobian, report.residuals))
}

/// The solver's report after no iteration: residuals and Jacobian at the
/// description's values.
fn linearised(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> Result<lm::Report, FitError> {
    let setup = Setup::new(description, data, params, options)?;
    let residual = |theta: &[f64]| setup.residuals(description, params, theta);
    let lm_options = lm::Options {
        max_iterations: 0,
        fd_step: options.fd_step,
        ..lm::Options::default()
    };
    lm::minimize(residual, &setup.x0, &setup.bounds, &lm_options, &mut |_| {}).map_err(|e| {
        FitError::Solver {
            file: data.file_name.clone(),
            message: e.to_string(),
        }
    })
}

/// The residuals of [JA 80] at the description's values of `params`.
pub fn residuals_at(
    description: &Description,
    data: &Measured,
    params: &[FitParam],
    options: &FitOptions,
) -> Result<Vec<f64>, FitError> {
    let setup = Setup::new(description, data, params, options)?;
    setup
        .residuals(description, params, &setup.x0)
        .ok_or_else(|| FitError::Solver {
            file: data.file_name.clone(),
            message: "the model cannot replay the record at these values".into(),
        })
}

/// The checked start values, the objective [JA 80] and the box of one fit.
pub(crate) struct Setup<'a> {
    pub(crate) x0: Vec<f64>,
    pub(crate) objective: Objective<'a>,
    pub(crate) bounds: Vec<(f64, f64)>,
}

impl<'a> Setup<'a> {
    pub(crate) fn new(
        description: &Description,
        data: &'a Measured,
        params: &[FitParam],
        options: &FitOptions,
    ) -> Result<Self, FitError> {
        Ok(Setup {
            x0: check_params(description, params)?,
            objective: Objective::new(description, data, options)?,
            bounds: params.iter().map(|p| (p.lower, p.upper)).collect(),
        })
    }

    /// The residuals of [JA 80] at θ (none: invalid values or a failed replay).
    fn residuals(
        &self,
        description: &Description,
        params: &[FitParam],
        theta: &[f64],
    ) -> Option<Vec<f64>> {
        let d = with_values(description, params, theta).ok()?;
        self.objective.residuals(&d).ok()
    }
}

/// Checks paths, duplicates and bounds; returns the start values (the
/// description's, clamped into the bounds).
fn check_params(d: &Description, params: &[FitParam]) -> Result<Vec<f64>, FitError> {
    if params.is_empty() {
        return Err(FitError::NoParameters);
    }
    let mut x0 = Vec::with_capacity(params.len());
    for (k, p) in params.iter().enumerate() {
        if params[..k].iter().any(|q| q.path == p.path) {
            return Err(FitError::Duplicate {
                path: p.path.clone(),
            });
        }
        let value = params::get(d, &p.path)?;
        let domain = params::domain(d, &p.path)?;
        let inside = |x: f64| domain.contains(x);
        if !(p.lower < p.upper) || !inside(p.lower) || !inside(p.upper) {
            return Err(FitError::Bounds {
                path: p.path.clone(),
                lower: p.lower,
                upper: p.upper,
            });
        }
        x0.push(value.clamp(p.lower, p.upper));
    }
    Ok(x0)
}

/// The start points: `x0`, those `given` (clamped into the bounds; only
/// those of `params`' length), then points drawn from the bounds, `starts`
/// in all. The drawn ones are the same whatever is given.
fn start_points(
    x0: &[f64],
    given: &[Vec<f64>],
    params: &[FitParam],
    starts: usize,
    seed: u64,
) -> Vec<Vec<f64>> {
    let mut rng = SplitMix64(seed);
    let mut points = vec![x0.to_vec()];
    let clamped = |x: &Vec<f64>| {
        (x.iter().zip(params))
            .map(|(v, p)| v.clamp(p.lower, p.upper))
            .collect::<Vec<f64>>()
    };
    let given =
        (given.iter()).filter(|x| x.len() == params.len() && x.iter().all(|v| v.is_finite()));
    points.extend(given.map(clamped).take(starts.saturating_sub(1)));
    while points.len() < starts {
        points.push(
            params
                .iter()
                .map(|p| {
                    let u = rng.uniform();
                    if p.lower > 0.0 && p.upper >= 10.0 * p.lower {
                        (p.lower.ln() + u * (p.upper / p.lower).ln()).exp()
                    } else {
                        p.lower + u * (p.upper - p.lower)
                    }
                })
                .collect(),
        );
    }
    points
}

/// SplitMix64: a small deterministic generator for the start points.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1).
    fn uniform(&mut self) -> f64 {
        ((self.next() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::{start_points, FitParam};

    fn param(lower: f64, upper: f64) -> FitParam {
        FitParam {
            path: "p".into(),
            lower,
            upper,
        }
    }

    #[test]
    fn given_starts_come_before_the_drawn_ones_which_stay_the_same() {
        let params = [param(1.0, 100.0), param(-1.0, 1.0)];
        let x0 = [10.0, 0.0];
        let drawn = start_points(&x0, &[], &params, 3, 7);
        let given = vec![vec![500.0, 0.5], vec![f64::NAN, 0.0], vec![2.0]];
        let with = start_points(&x0, &given, &params, 4, 7);
        assert_eq!(with[0], x0);
        // clamped into the bounds; a non-finite or short point is skipped
        assert_eq!(with[1], vec![100.0, 0.5]);
        assert_eq!(&with[2..], &drawn[1..]);
        // `starts` counts the given points
        assert_eq!(start_points(&x0, &given, &params, 2, 7).len(), 2);
        assert_eq!(start_points(&x0, &given, &params, 1, 7), vec![x0.to_vec()]);
    }

    /// The benchmark's first trial (`benches/fit.sh`: c on its bound)
    /// replayed after the Jiles–Atherton valve's own: it takes many times
    /// the start's steps, so with the default cap it fails, without it
    /// it finishes.
    #[test]
    fn a_trial_far_stiffer_than_the_start_fails_fast() {
        use super::{params, FitOptions, TrialReplays};
        use crate::description::parse_file;
        let path = support::example_path("jiles-atherton-valve.toml");
        let start = parse_file(&path).unwrap();
        let mut stiff = start.clone();
        for (key, value) in [
            ("core.m_sat", 1.5556e6),
            ("core.b", 3.303e-3),
            ("core.c", 0.3),
            ("core.kappa", 1058.8),
            ("core.alpha", 4.201e-3),
        ] {
            params::set(&mut stiff, key, value).unwrap();
        }
        let dt = 1e-5;
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * dt).collect();
        // ±24 V, 20 ms period, with a deterministic ±15 mV ripple (the
        // measured voltage's noise is what makes the stiff trial slow)
        let v = (t.iter().enumerate())
            .map(|(k, t)| {
                let level = if (t / 20e-3).fract() < 0.5 {
                    24.0
                } else {
                    -24.0
                };
                level + 15e-3 * ((k * 7919 % 101) as f64 / 50.0 - 1.0)
            })
            .collect();
        let data = crate::Measured {
            i: vec![0.0; t.len()],
            z: None,
            phi: None,
            lambda: None,
            dt,
            file_name: "ripple.csv".into(),
            edges: None,
            t,
            v,
        };
        let steps = |r: &super::Replay| r.trajectory.stats.attempted();
        let uncapped = FitOptions {
            trial_steps_over_start: None,
            ..FitOptions::default()
        };
        let free = TrialReplays::new(&uncapped, &data);
        let own = steps(&free.replay(&start).unwrap());
        let far = steps(&free.replay(&stiff).expect("uncapped, the trial finishes"));
        assert!(far > 8 * own, "{far} steps against the start's {own}");
        let capped = TrialReplays::new(&FitOptions::default(), &data);
        assert!(capped.replay(&start).is_some());
        assert!(
            capped.replay(&stiff).is_none(),
            "the cap lets {far} steps through"
        );
        assert!(
            capped.replay(&start).is_some(),
            "the start itself still replays"
        );
    }
}
