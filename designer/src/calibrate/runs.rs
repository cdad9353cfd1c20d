//! Successive runs of a design on a plant, the calibration updated between
//! them by the runtime's own code (`reldesign loop --runs`): each run every
//! operation once from rest (`closed_loop::run_loop`) with the parameters
//! adapted so far; then each operation's record, as the firmware's
//! `Record` keeps it from the measured voltage and current, updates θ.

use reldesign_runtime::calibrate::{Calibration, Outcome, Record};

use crate::closed_loop::{run_spaced_loop, LoopError, LoopRun, Noise, OperationOutcome};
use crate::description::{Description, Operation};
use crate::design::Design;
use crate::sim::Options;

use super::{adapted_design, CalibrationDesign, TapePredictor};

/// The designer's record buffer: larger than any design's capacity (the
/// design sizes its decimation so that an operation fits in its capacity).
const RECORD: usize = 4096;

/// Why the runs stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunsError {
    #[error(transparent)]
    Loop(#[from] LoopError),
    #[error("run {run}: the adapted design: {message}")]
    Adapted { run: usize, message: String },
    #[error("the calibration adapts {0} parameters; at most 8 are supported")]
    TooMany(usize),
}

/// One operation of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct OperationRun {
    pub outcome: OperationOutcome,
    /// What the update after it did (`None`: no calibration).
    pub update: Option<Outcome<f64>>,
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
/// `sample_period`, the noise of run k seeded by `seed + k`, with the
/// calibration (where given) updated after every operation's run.
pub fn run_runs(
    design: &Design,
    calibration: Option<&CalibrationDesign>,
    plant: Option<&Description>,
    runs: usize,
    sample_period: f64,
    seed: u64,
    options: &Options,
) -> Result<Vec<Run>, RunsError> {
    let p = calibration.map_or(0, |c| c.parameters.len());
    macro_rules! with_p {
        ($($n:literal)*) => {
            match p {
                $($n => runs_with::<$n>(design, calibration, plant, runs, sample_period, seed, options),)*
                n => Err(RunsError::TooMany(n)),
            }
        };
    }
    with_p!(0 1 2 3 4 5 6 7 8)
}

fn runs_with<const P: usize>(
    design: &Design,
    calibration: Option<&CalibrationDesign>,
    plant: Option<&Description>,
    runs: usize,
    sample_period: f64,
    seed: u64,
    options: &Options,
) -> Result<Vec<Run>, RunsError> {
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
        let run_design = if values.is_empty() {
            None
        } else {
            Some(
                adapted_design(design, &values)
                    .map_err(|message| RunsError::Adapted { run, message })?,
            )
        };
        let d = run_design.as_ref().unwrap_or(design);
        let noise = Noise::seeded(seed.wrapping_add(run as u64));
        let window = design
            .description
            .trajectory
            .as_ref()
            .map(super::operation_window);
        let looped = run_spaced_loop(d, plant, sample_period, None, window, noise, options)?;
        let (takeoff, landing) = design
            .description
            .trajectory
            .as_ref()
            .map_or((0.0, 0.0), |t| (t.takeoff, t.landing));
        let outcomes = looped.outcomes(takeoff, landing);
        let mut operations = Vec::with_capacity(outcomes.len());
        for (outcome, &(operation, start)) in outcomes.into_iter().zip(&looped.operations) {
            let update = match (&settings, &predictor, &mut state) {
                (Some(settings), Some(predictor), Some(state)) => {
                    let record = record::<P>(settings, &looped, operation, start, design);
                    Some(state.update(predictor, settings, &record))
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

/// The record the firmware keeps of `operation` (started at `start`): every
/// sample of the operation's window pushed as measured.
fn record<const P: usize>(
    settings: &reldesign_runtime::calibrate::Settings<f64, P>,
    looped: &LoopRun,
    operation: Operation,
    start: f64,
    design: &Design,
) -> Box<Record<f64, RECORD>> {
    let m = &design.description.mechanics;
    let z0 = match operation {
        Operation::Closing => m.z_max,
        Operation::Opening => m.z_min,
    };
    let end = start + looped.operation_length;
    let tolerance = 1e-9 * looped.operation_length;
    let mut record = Box::new(Record::<f64, RECORD>::new());
    record.start(z0);
    for s in &looped.measured {
        if s.t >= start - tolerance && s.t < end - tolerance {
            record.push(settings, s.commanded, s.voltage, s.current);
        }
    }
    record
}
