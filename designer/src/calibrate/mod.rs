//! Run-to-run self-calibration, the designer's side: which parameters the
//! emitted code adapts and within which bounds ([`CalibrationDesign`], chosen
//! by the identifiability of the planned operations, `choice.rs`), the
//! calibration's model on tapes (`predictor.rs`), the design a run uses with
//! the adapted values ([`adapted_design`]) and successive runs on a plant
//! with the runtime's own update between them (`runs.rs`, `reldesign loop
//! --runs`).
//!
//! The algorithm is `reldesign_runtime::calibrate`'s; nothing here
//! re-implements it.

mod choice;
pub mod innovations;
mod predictor;
mod runs;

pub use choice::{candidates, choose, Candidate, ChoiceError, UNEXPLAINED};
pub use predictor::{PredictorExpressions, TapePredictor};
pub use reldesign_runtime::calibrate::{Outcome, Refusal};
pub use runs::{run_runs, run_runs_updated_by, OperationRun, Run, RunUpdate, RunsError, Update};

use reldesign_runtime::calibrate::{Record, Settings};

use crate::closed_loop::LoopRun;
use crate::description::Operation;

use crate::description::{params, Description};
use crate::design::{design_kalman, Design, Linearization};
use crate::model::Model;

pub use crate::closed_loop::operation_window;

/// One adapted parameter: its description key, the model's symbol, the
/// design's value and the physical domain the update keeps it in.
#[derive(Debug, Clone, PartialEq)]
pub struct Adapted {
    pub key: &'static str,
    pub symbol: &'static str,
    pub nominal: f64,
    pub lower: f64,
    pub upper: f64,
    /// Its share of the planned operations' current sensitivity that no
    /// parameter chosen before it explains (the identifiability analysis):
    /// why it was chosen.
    pub new_information: f64,
}

/// How θ is updated between runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The observer's innovations over the run (`innovations.rs`): every
    /// physics parameter the filter's model reads; for designs whose law is
    /// driven by an observer.
    Innovations,
    /// The record's voltage replayed open-loop (`reldesign_runtime::calibrate`):
    /// the parameters the planned operations' current identifies.
    Replay,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Innovations => "innovations",
            Method::Replay => "replay",
        }
    }
}

/// What the emitted calibration adapts and how (the design report states it).
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationDesign {
    pub method: Method,
    /// The adapted parameters θ, in the order of the emitted arrays.
    pub parameters: Vec<Adapted>,
    /// The candidates the analysis looked at and why each was not chosen.
    pub rejected: Vec<(&'static str, String)>,
    /// Samples per stored sample.
    pub decimation: u32,
    /// Stored samples per operation (the record's buffer).
    pub capacity: usize,
    pub sample_period: f64,
    pub z_min: f64,
    pub z_max: f64,
    /// Largest change of a parameter in one update, relative to its design value.
    pub max_step: f64,
    pub iterations: u32,
    pub min_samples: usize,
    pub current_limit: f64,
    pub dip_tolerance: f64,
    pub dip_share: f64,
    pub motion_evidence: f64,
    /// The innovations update's forward-difference step, relative to θ_d.
    pub difference_step: f64,
    /// [A²]: an update that leaves a larger mean squared current error
    /// leaves the valve's current unexplained (`Settings::unexplained`):
    /// [`UNEXPLAINED`]·σ_i² where an observer drives the law, ∞ otherwise.
    pub unexplained: f64,
}

impl CalibrationDesign {
    /// Whether an update left the valve's current unexplained (its mean
    /// squared error above [`CalibrationDesign::unexplained`]); `None` for a
    /// refusal, and where the design states no threshold (∞).
    pub fn leaves_unexplained(&self, outcome: &Outcome<f64>) -> Option<bool> {
        match outcome {
            // a NaN error explains nothing
            Outcome::Updated { after, .. } if self.unexplained.is_finite() => {
                Some(!(*after <= self.unexplained))
            }
            _ => None,
        }
    }

    /// The runtime's settings for P = `parameters.len()` parameters.
    ///
    /// # Panics
    /// Where P differs from the number of adapted parameters.
    pub fn settings<const P: usize>(&self) -> Settings<f64, P> {
        assert_eq!(P, self.parameters.len(), "P adapted parameters");
        let pick = |f: fn(&Adapted) -> f64| {
            let mut out = [0.0; P];
            for (o, a) in out.iter_mut().zip(&self.parameters) {
                *o = f(a);
            }
            out
        };
        Settings {
            nominal: pick(|a| a.nominal),
            lower: pick(|a| a.lower),
            upper: pick(|a| a.upper),
            max_step: self.max_step,
            sample_period: self.sample_period,
            decimation: self.decimation,
            z_min: self.z_min,
            z_max: self.z_max,
            iterations: self.iterations,
            min_samples: self.min_samples,
            current_limit: self.current_limit,
            dip_tolerance: self.dip_tolerance,
            dip_share: self.dip_share,
            motion_evidence: self.motion_evidence,
            difference_step: self.difference_step,
            unexplained: self.unexplained,
        }
    }
}

/// `design` with the adapted parameters at `values` (keys of the
/// description): the law's α, β and the observer's model derived again on
/// the adapted model; gains, references and every decision kept, as the
/// emitted code keeps its tables and reads the parameters at run time.
pub fn adapted_design(design: &Design, values: &[(&str, f64)]) -> Result<Design, String> {
    let mut description: Description = design.description.clone();
    for (key, value) in values {
        params::set(&mut description, key, *value).map_err(|e| e.to_string())?;
    }
    let mut model = Model::build(&description);
    let controller = match &design.controller {
        Some(c) => {
            let linearization = Linearization::derive(&mut model).map_err(|e| e.to_string())?;
            Some(crate::design::ControllerDesign {
                linearization,
                ..c.clone()
            })
        }
        None => None,
    };
    let kalman = design_kalman(&description, &model).map_err(|e| e.to_string())?;
    Ok(Design {
        description,
        model,
        controller,
        hold: design.hold.clone(),
        backstepping: design.backstepping.clone(),
        kalman,
    })
}

/// The model's symbols of `names` (each a parameter of the model).
///
/// # Panics
/// Where a name is not a parameter of `model`, or there are not P names.
pub(crate) fn symbols<'a, const P: usize>(
    model: &Model,
    names: impl Iterator<Item = &'a str>,
) -> [crate::sym::Id; P] {
    let ids: Vec<crate::sym::Id> = names
        .map(|n| {
            model
                .params
                .symbol(n)
                .unwrap_or_else(|| panic!("`{n}` is not a parameter of the model"))
        })
        .collect();
    ids.try_into()
        .unwrap_or_else(|v: Vec<_>| panic!("{} symbols for {P} parameters", v.len()))
}

/// The designer's record buffer: larger than any design's capacity (the
/// design sizes its decimation so that an operation fits in its capacity).
const RECORD: usize = 4096;

/// The record the firmware keeps of `operation` (started at `start`): every
/// sample of the operation's window pushed as measured.
pub(crate) fn record<const P: usize>(
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
