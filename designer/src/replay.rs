//! Replaying an input through the hybrid model: the library call behind
//! `reldesign simulate` (and, later, `diagnose`).
//!
//! The actuator starts at rest at z_max with zero flux (and H_c = 0:
//! demagnetised), in the mode the automaton's guards allow. The coil outputs
//! are computed after the simulation, for all output times at once
//! ([`ModelPlant::currents_and_voltages`]).

use crate::model::{Model, ModelPlant};
use crate::sim::{simulate, Input, Mode, Options, Plant, SimError, State, Trajectory};

/// A simulated experiment with the coil's electrical outputs.
#[derive(Debug, Clone)]
pub struct Replay {
    pub trajectory: Trajectory,
    /// Coil current at each output time.
    pub current: Vec<f64>,
    /// Coil voltage at each output time (the input itself for voltage drive).
    pub voltage: Vec<f64>,
}

/// The rest state: z = z_max, v = 0, φ = 0 (, H_c = 0).
pub fn rest_state(model: &Model) -> State {
    let mut x0 = [0.0; crate::sim::MAX_DIM];
    x0[0] = model.description.mechanics.z_max;
    x0
}

/// Simulates `input` from rest, recording at `output_times`.
pub fn replay<I: Input + ?Sized>(
    model: &mut Model,
    input: &I,
    output_times: &[f64],
    options: &Options,
) -> Result<Replay, SimError> {
    let plant = ModelPlant::new(model);
    replay_plant(&plant, model, input, output_times, options)
}

/// [`replay`] with an already compiled plant (repeated runs, benchmarks).
pub fn replay_plant<I: Input + ?Sized>(
    plant: &ModelPlant,
    model: &Model,
    input: &I,
    output_times: &[f64],
    options: &Options,
) -> Result<Replay, SimError> {
    replay_through(plant, plant, model, input, output_times, options)
}

/// [`replay`] of `plant`, a variant of `model`'s own plant `coil` (e.g.
/// with a force no description holds) whose coil outputs are `coil`'s.
pub fn replay_through<P: Plant, I: Input + ?Sized>(
    plant: &P,
    coil: &ModelPlant,
    model: &Model,
    input: &I,
    output_times: &[f64],
    options: &Options,
) -> Result<Replay, SimError> {
    let trajectory = simulate(
        plant,
        input,
        rest_state(model),
        Mode::StuckMax,
        output_times,
        options,
    )?;
    let tr = &trajectory;
    let (current, voltage) = coil.currents_and_voltages(&tr.t, &tr.x, &tr.u);
    Ok(Replay {
        trajectory,
        current,
        voltage,
    })
}
