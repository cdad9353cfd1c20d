//! The prediction-error update of an observer-driven design, as the emitted
//! code runs it: `reldesign_runtime::calibrate::innovations` (θ chosen so
//! that the UKF's one-step current predictions over a run are right) on the
//! design's discretised model compiled to tapes with θ as inputs
//! (`TapeModel::adaptive`), over the record the firmware keeps of a run.

use reldesign_runtime::calibrate::{Calibration, Outcome, Record};

use crate::closed_loop::Measured;
use crate::design::Design;
use crate::observe::discrete::{DiscreteModel, TapeModel};

use super::CalibrationDesign;

/// The designer's run record: larger than any design's capacity at the
/// sample periods `loop --runs` accepts (a run of 25 ms windows at 1 µs).
pub const RUN_RECORD: usize = 65_536;

/// The record the firmware keeps of a run: every sample as measured.
pub fn run_record<const P: usize>(
    settings: &reldesign_runtime::calibrate::Settings<f64, P>,
    measured: &[Measured],
    z0: f64,
) -> Box<Record<f64, RUN_RECORD>> {
    let mut record = Box::new(Record::<f64, RUN_RECORD>::new());
    record.start(z0);
    for m in measured {
        record.push(settings, m.commanded, m.voltage, m.current);
    }
    record
}

/// The filter's model with the adapted parameters as tape inputs.
fn adaptive<const N: usize>(
    discrete: &DiscreteModel,
    c: &CalibrationDesign,
) -> Result<TapeModel<N>, String> {
    let names: Vec<&str> = c.parameters.iter().map(|a| a.symbol).collect();
    let free = discrete
        .param_symbols(&names)
        .ok_or("an adapted parameter is not one of the filter's model")?;
    Ok(TapeModel::adaptive(discrete, &free))
}

/// One update of `calibration` from a run's `measured` samples by the
/// runtime's innovations update on the design's filter model.
pub fn update<const P: usize>(
    design: &Design,
    c: &CalibrationDesign,
    calibration: &mut Calibration<f64, P>,
    measured: &[Measured],
) -> Result<Outcome<f64>, String> {
    let discrete = design
        .kalman
        .as_ref()
        .ok_or("the design has no Kalman filter")?;
    let settings = c.settings::<P>();
    let record = run_record(&settings, measured, design.description.mechanics.z_max);
    Ok(match discrete.dim() {
        3 => calibration.update_innovations::<_, 3, 7, RUN_RECORD>(
            &adaptive::<3>(discrete, c)?,
            &settings,
            &record,
        ),
        4 => calibration.update_innovations::<_, 4, 9, RUN_RECORD>(
            &adaptive::<4>(discrete, c)?,
            &settings,
            &record,
        ),
        _ => calibration.update_innovations::<_, 5, 11, RUN_RECORD>(
            &adaptive::<5>(discrete, c)?,
            &settings,
            &record,
        ),
    })
}
