//! Event-driven simulation of the three-mode hybrid automaton
//! ([PT Fig. 3]: free motion, and at rest on either stop).
//!
//! Between events the continuous state is integrated by [`Dopri5`](super::Dopri5); the mode
//! decides the vector field (free motion, or stuck at a limit with `ż = v̇ = 0`
//! while the other states evolve at `v = 0`). After every accepted step the
//! guards are checked on the dense output and, if one fired, its crossing time
//! is located by an Illinois (modified regula falsi) bracketing root finder to
//! `event_tol·max(1, |t|)`; the step is cut there, the reset applied and the
//! integrator restarted (keeping its step size: the motion just before an
//! event predicts the next step better than a fresh heuristic). Input
//! breakpoints are hard stops too, so no step ever spans a jump or kink of
//! the input. A plant's switching functions are handled alike (see
//! `switching.rs`): the field runs on held branches and a sign change is
//! located and cut at, with the other branch after it (recorded in
//! [`Trajectory::switches`]).
//!
//! One concept per module:
//! - `engine.rs`: the integration between events, the event refinement;
//! - `guards.rs`: the guards, and where inside a step one fired;
//! - `events.rs`: the resets at one instant, the Zeno rule, the events;
//! - `field.rs`: the vector field of each mode;
//! - `quadrature.rs`: extra integrals, the state they extend;
//! - `trajectory.rs`: the result, recorded at the output times;
//! - `options.rs`: the settings, the errors, the checks of the inputs.

// `!(a > b)` comparisons are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod engine;
mod events;
mod field;
mod guards;
mod options;
mod quadrature;
mod trajectory;

pub(crate) use engine::Engine;
pub use events::{Event, EventKind, Limit, MAX_EVENTS_PER_INSTANT};
pub use options::{Options, SimError};
pub use quadrature::{NoQuadrature, QuadState, Quadrature, MAX_QUAD};
pub use trajectory::{Switch, Trajectory};

use super::input::Input;
use super::{Mode, Plant, State};

/// Simulates from `output_times[0]` to its last entry (non-decreasing),
/// recording at every output time. See the module docs for the automaton
/// and [`Trajectory`] for what is recorded.
pub fn simulate<P: Plant, I: Input + ?Sized>(
    plant: &P,
    input: &I,
    x0: State,
    mode0: Mode,
    output_times: &[f64],
    opts: &Options,
) -> Result<Trajectory, SimError> {
    simulate_with(plant, input, x0, mode0, output_times, &NoQuadrature, opts)
}

/// [`simulate`] with extra integrals (see [`Quadrature`]).
pub fn simulate_with<P: Plant, I: Input + ?Sized, Q: Quadrature>(
    plant: &P,
    input: &I,
    x0: State,
    mode0: Mode,
    output_times: &[f64],
    quad: &Q,
    opts: &Options,
) -> Result<Trajectory, SimError> {
    check_times(output_times)?;
    let (t0, t_end) = (output_times[0], output_times[output_times.len() - 1]);
    let mut eng = Engine::new(plant, quad, t0, x0, mode0, output_times, opts)?;
    let mut t = t0;
    while t < t_end {
        let stop = input.next_breakpoint(t).min(t_end);
        eng.advance(stop, input.piece(t))?;
        t = stop;
    }
    eng.finish(input.piece(t_end))
}

/// Output times must be non-empty, finite and non-decreasing.
pub(crate) fn check_times(times: &[f64]) -> Result<(), SimError> {
    if times.is_empty() {
        return Err(SimError::OutputTimes("no output times"));
    }
    // Folds without early exits (they vectorise): this runs per simulation.
    if !times.iter().fold(true, |ok, t| ok & t.is_finite()) {
        return Err(SimError::OutputTimes("not finite"));
    }
    if times.windows(2).fold(false, |bad, w| bad | (w[1] < w[0])) {
        return Err(SimError::OutputTimes("decreasing"));
    }
    Ok(())
}
