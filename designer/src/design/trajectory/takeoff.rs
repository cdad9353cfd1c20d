//! The shortest pre-movement stage the supply allows.
//!
//! Every soft-landing reference rests at z₀ until t₀ (`trajectory.takeoff`)
//! and assumes the flux has reached takeoff by then. Whether it can depends
//! on the coil: strong eddy currents or a large inductance need longer than
//! the design's pre-movement stage to build (or drain) the flux even at full
//! supply. The model is driven at the supply's limit from the rest the
//! operation starts at, and the instant its armature would leave the stop is
//! the shortest takeoff:
//!
//! - closing, from z_max without flux, at u_max;
//! - opening, from z_min with the flux that holding at u_max leaves
//!   (`Statics::hold_flux`), at the lowest input.

use crate::description::{Description, Operation};
use crate::model::{Model, ModelPlant, Statics};
use crate::sim::{simulate, EventKind, Mode, Options, PiecewiseLinear, MAX_DIM};

/// How far past the design's takeoff the model is driven looking for the
/// lift-off: beyond it the answer is "longer than this".
const HORIZON: f64 = 50.0;

/// The shortest takeoff of `operation`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shortest {
    /// The armature leaves its stop this long [s] after the supply's limit is applied.
    After(f64),
    /// Not within `horizon` [s].
    Longer(f64),
}

/// The shortest pre-movement stage of `operation` on `model`, driven at
/// `input` [V or A] from its starting rest; `takeoff` [s] the design's, to
/// size the horizon. Simulated on a copy of `model`: compiling a plant adds
/// to the model's expression graph, which the design's later derivations
/// would then evaluate in another order, and the emitted tables must keep
/// their bits.
pub fn shortest_takeoff(
    description: &Description,
    model: &Model,
    operation: Operation,
    input: f64,
    takeoff: f64,
) -> Result<Shortest, String> {
    let mut model = model.clone();
    let model = &mut model;
    let m = &description.mechanics;
    let mut x0 = [0.0; MAX_DIM];
    let mode = match operation {
        Operation::Closing => {
            x0[0] = m.z_max;
            Mode::StuckMax
        }
        Operation::Opening => {
            x0[0] = m.z_min;
            x0[2] = Statics::of(model).hold_flux;
            Mode::StuckMin
        }
    };
    let horizon = HORIZON * takeoff;
    let plant = ModelPlant::new(model);
    let u =
        PiecewiseLinear::new(vec![0.0, horizon], vec![input, input]).map_err(|e| e.to_string())?;
    let trajectory = simulate(&plant, &u, x0, mode, &[0.0, horizon], &Options::default())
        .map_err(|e| e.to_string())?;
    Ok(trajectory
        .events
        .iter()
        .find_map(|e| matches!(e.kind, EventKind::LiftOff { .. }).then_some(e.t))
        .map_or(Shortest::Longer(horizon), Shortest::After))
}
