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
//! - opening, at the lowest input, from the hold the design's own cycle
//!   leaves: landed at rest on z_min with the forces balanced (the
//!   reference's end), then held for t₀ at u_max (the expert rule on
//!   contact [SM 43] from t_f until the operation ends at t_f + t₀ [SM 45],
//!   `operation_end`, where the next one starts). A longer hold builds more
//!   flux, up to the steady flux at u_max, and needs a longer stage than
//!   this: that is outside the timing the design is made for, and not
//!   checked (the 12 V relay would need 3.54 ms from there).

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
/// `input` [V or A] from its starting rest (module docs; the opening's after
/// the hold at `hold_input` the design's cycle gives it); `takeoff` [s] the
/// design's, the hold's length and the horizon's scale. Simulated on a copy
/// of `model`: compiling a plant adds to the model's expression graph, which
/// the design's later derivations would then evaluate in another order, and
/// the emitted tables must keep their bits.
pub fn shortest_takeoff(
    description: &Description,
    model: &Model,
    operation: Operation,
    input: f64,
    hold_input: f64,
    takeoff: f64,
) -> Result<Shortest, String> {
    let mut model = model.clone();
    let model = &mut model;
    let m = &description.mechanics;
    let mut x0 = [0.0; MAX_DIM];
    let balance = match operation {
        Operation::Closing => None,
        Operation::Opening => Some(Statics::of(model).drop_out.map_or(0.0, |p| p.flux)),
    };
    let plant = ModelPlant::new(model);
    let constant = |u: f64, end: f64| {
        PiecewiseLinear::new(vec![0.0, end], vec![u, u]).map_err(|e| e.to_string())
    };
    let mode = match balance {
        None => {
            x0[0] = m.z_max;
            Mode::StuckMax
        }
        Some(flux) => {
            // landed at rest (the reference's end, forces balanced), then
            // held at hold_input for t₀ [SM 45]
            x0[0] = m.z_min;
            x0[2] = flux;
            let held = simulate(
                &plant,
                &constant(hold_input, takeoff)?,
                x0,
                Mode::StuckMin,
                &[0.0, takeoff],
                &Options::default(),
            )
            .map_err(|e| e.to_string())?;
            let (Some(x), Some(&mode)) = (held.x.last(), held.mode.last()) else {
                return Err("the hold before the opening has no state".to_string());
            };
            x0 = *x;
            mode
        }
    };
    let horizon = HORIZON * takeoff;
    let trajectory = simulate(
        &plant,
        &constant(input, horizon)?,
        x0,
        mode,
        &[0.0, horizon],
        &Options::default(),
    )
    .map_err(|e| e.to_string())?;
    Ok(trajectory
        .events
        .iter()
        .find_map(|e| matches!(e.kind, EventKind::LiftOff { .. }).then_some(e.t))
        .map_or(Shortest::Longer(horizon), Shortest::After))
}
