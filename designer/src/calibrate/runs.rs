//! Successive runs of a design on a plant, the calibration updated between
//! them by the runtime's own code (`reldesign loop --runs`): each run every
//! operation once from rest (`closed_loop::run_loop`) with the parameters
//! adapted so far; then each operation's record, as the firmware's
//! `Record` keeps it from the measured voltage and current, updates θ.

use reldesign_runtime::calibrate::{Calibration, Outcome};

use crate::closed_loop::{run_spaced_loop, LoopError, LoopRun, Measured, Noise, OperationOutcome};
use crate::description::Description;
use crate::design::Design;
use crate::sim::Options;

use super::{adapted_design, CalibrationDesign, Method, TapePredictor};

/// Why the runs stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunsError {
    #[error(transparent)]
    Loop(#[from] LoopError),
    #[error("run {run}: the adapted design: {message}")]
    Adapted { run: usize, message: String },
    #[error("the calibration adapts {0} parameters; at most 12 are supported")]
    TooMany(usize),
}

/// What an update did, and by which method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Update {
    /// The runtime's replay update of one operation's record.
    Replay(Outcome<f64>),
    /// The runtime's innovations update of a whole run's record.
    Innovations(Outcome<f64>),
}

/// One operation of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct OperationRun {
    pub outcome: OperationOutcome,
    /// What the update after it did (`None`: no calibration, or no update
    /// after this operation).
    pub update: Option<Update>,
}

/// One run: the parameters it used and its operations.
#[derive(Debug, Clone)]
pub struct Run {
    /// 1 … N.
    pub run: usize,
    /// The adapted parameters' values during the run, by description key.
    pub parameters: Vec<(&'static str, f64)>,
    pub operations: Vec<OperationRun>,
    /// The loop itself (for plots).
    pub run_loop: LoopRun,
}

/// `runs` runs of `design` on `plant` (default: its own model) at
/// `sample_period`, the measurement noise `noise` with run k seeded by `noise.seed + k`, with the
/// calibration (where given) updated after every operation's run.
pub fn run_runs(
    design: &Design,
    calibration: Option<&CalibrationDesign>,
    plant: Option<&Description>,
    runs: usize,
    sample_period: f64,
    noise: Noise,
    options: &Options,
) -> Result<Vec<Run>, RunsError> {
    let study = Study {
        design,
        plant,
        sample_period,
        noise,
        options,
    };
    let p = calibration.map_or(0, |c| c.parameters.len());
    let innovations = calibration.filter(|c| c.method == Method::Innovations);
    macro_rules! with_p {
        ($($n:literal)*) => {
            match (p, innovations) {
                $(($n, Some(c)) => study.innovations::<$n>(c, runs),)*
                $(($n, None) => study.replays::<$n>(calibration, runs),)*
                (n, _) => Err(RunsError::TooMany(n)),
            }
        };
    }
    with_p!(0 1 2 3 4 5 6 7 8 9 10 11 12)
}

/// An update of θ (the adapted parameters' values, in the order of
/// `CalibrationDesign::parameters`) from a run's measured samples.
pub type RunUpdate<'a> = dyn FnMut(&[Measured], &mut [f64]) -> Result<Outcome<f64>, String> + 'a;

/// `runs` runs of `design` with its innovations calibration `c`, like
/// [`run_runs`], θ updated after each run by `update` instead of the
/// designer's (e.g. by the emitted f32 code's own: the self-calibration
/// study, `tests/tests/self_calibration.rs`).
#[allow(clippy::too_many_arguments)]
pub fn run_runs_updated_by(
    design: &Design,
    c: &CalibrationDesign,
    plant: Option<&Description>,
    runs: usize,
    sample_period: f64,
    noise: Noise,
    options: &Options,
    update: &mut RunUpdate,
) -> Result<Vec<Run>, RunsError> {
    let study = Study {
        design,
        plant,
        sample_period,
        noise,
        options,
    };
    study.updated_by(c, runs, update)
}

/// What every run shares.
struct Study<'a> {
    design: &'a Design,
    plant: Option<&'a Description>,
    sample_period: f64,
    noise: Noise,
    options: &'a Options,
}

impl Study<'_> {
    /// Run `run` with the adapted parameters at `values`, its operations a
    /// window apart, and its outcomes.
    fn run(
        &self,
        run: usize,
        values: &[(&'static str, f64)],
    ) -> Result<(LoopRun, Vec<OperationOutcome>), RunsError> {
        let adapted = if values.is_empty() {
            None
        } else {
            Some(
                adapted_design(self.design, values)
                    .map_err(|message| RunsError::Adapted { run, message })?,
            )
        };
        let d = adapted.as_ref().unwrap_or(self.design);
        let noise = Noise {
            seed: self.noise.seed.wrapping_add(run as u64),
            ..self.noise
        };
        let trajectory = self.design.description.trajectory.as_ref();
        let window = trajectory.map(super::operation_window);
        let looped = run_spaced_loop(
            d,
            self.plant,
            self.sample_period,
            None,
            window,
            noise,
            self.options,
        )?;
        let (takeoff, landing) = trajectory.map_or((0.0, 0.0), |t| (t.takeoff, t.landing));
        let outcomes = looped.outcomes(takeoff, landing);
        Ok((looped, outcomes))
    }

    /// The runtime's replay update after every operation (P parameters).
    fn replays<const P: usize>(
        &self,
        calibration: Option<&CalibrationDesign>,
        runs: usize,
    ) -> Result<Vec<Run>, RunsError> {
        let design = self.design;
        let adapted = calibration.filter(|_| P > 0);
        let settings = adapted.map(|c| c.settings::<P>());
        let predictor = adapted.map(|c| {
            let ids = super::symbols::<P>(&design.model, c.parameters.iter().map(|a| a.symbol));
            TapePredictor::<P>::new(&design.model, &ids)
        });
        let mut state = settings.as_ref().map(Calibration::new);
        let mut out = Vec::with_capacity(runs);
        for run in 1..=runs {
            let values: Vec<(&'static str, f64)> = match (adapted, &state) {
                (Some(c), Some(s)) => c.parameters.iter().map(|a| a.key).zip(s.theta).collect(),
                _ => Vec::new(),
            };
            let (looped, outcomes) = self.run(run, &values)?;
            let mut operations = Vec::with_capacity(outcomes.len());
            for (outcome, &(operation, start)) in outcomes.into_iter().zip(&looped.operations) {
                let update = match (&settings, &predictor, &mut state) {
                    (Some(settings), Some(predictor), Some(state)) => {
                        let record =
                            super::record::<P>(settings, &looped, operation, start, design);
                        Some(Update::Replay(state.update(predictor, settings, &record)))
                    }
                    _ => None,
                };
                operations.push(OperationRun { outcome, update });
            }
            out.push(Run {
                run,
                parameters: values,
                operations,
                run_loop: looped,
            });
        }
        Ok(out)
    }

    /// The runtime's innovations update (on tapes, f64) after every run,
    /// over the whole run.
    fn innovations<const P: usize>(
        &self,
        c: &CalibrationDesign,
        runs: usize,
    ) -> Result<Vec<Run>, RunsError> {
        let mut state = Calibration::<f64, P>::new(&c.settings());
        let design = self.design;
        let mut update = |measured: &[Measured], theta: &mut [f64]| {
            state.theta.copy_from_slice(theta);
            let outcome = super::innovations::update(design, c, &mut state, measured)?;
            theta.copy_from_slice(&state.theta);
            Ok(outcome)
        };
        self.updated_by(c, runs, &mut update)
    }

    /// Runs with `update` after each (θ in the order of `c.parameters`).
    fn updated_by(
        &self,
        c: &CalibrationDesign,
        runs: usize,
        update: &mut RunUpdate,
    ) -> Result<Vec<Run>, RunsError> {
        let mut theta: Vec<f64> = c.parameters.iter().map(|a| a.nominal).collect();
        let mut out = Vec::with_capacity(runs);
        for run in 1..=runs {
            let values: Vec<(&'static str, f64)> = (c.parameters.iter())
                .map(|a| a.key)
                .zip(theta.iter().copied())
                .collect();
            let (looped, outcomes) = self.run(run, &values)?;
            let outcome = update(&looped.measured, &mut theta)
                .map_err(|message| RunsError::Adapted { run, message })?;
            let last = outcomes.len().saturating_sub(1);
            let operations = outcomes
                .into_iter()
                .enumerate()
                .map(|(k, outcome_of_run)| OperationRun {
                    outcome: outcome_of_run,
                    // one update per run, after its last operation
                    update: (k == last).then_some(Update::Innovations(outcome)),
                })
                .collect();
            out.push(Run {
                run,
                parameters: values,
                operations,
                run_loop: looped,
            });
        }
        Ok(out)
    }
}
