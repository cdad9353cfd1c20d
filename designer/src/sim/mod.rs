//! Hybrid simulation of a single-coil reluctance actuator.
//!
//! The plant is a three-mode hybrid automaton (stuck at `z_min`, free motion,
//! stuck at `z_max`) with impacts that bounce (`v⁺ = −γ·v`) or stick. The
//! continuous part is integrated by an adaptive embedded Runge–Kutta method with
//! dense output; guards are located precisely on the dense output (event
//! location), never by step-size luck. A sampled-data mode calls a controller
//! every `Ts` and holds its output (zero-order hold).
//!
//! The simulator knows nothing about reluctances or fluxes: it sees a [`Plant`]
//! whose first two states are position `z` and velocity `v`.

mod hybrid;
mod input;
mod rk;
mod sampled;

pub use hybrid::{
    simulate, simulate_with, Event, EventKind, Limit, NoQuadrature, Options, QuadState, Quadrature,
    SimError, Trajectory, MAX_EVENTS_PER_INSTANT, MAX_QUAD,
};
pub use input::{Affine, Cursor, Input, InputError, PiecewiseLinear};
pub use rk::{Dopri5, RkError, StepStats};
pub use sampled::{simulate_sampled, simulate_sampled_with, Controller, Measurement};

/// Largest number of continuous states a plant may have (z, v, φ, H_c).
pub const MAX_DIM: usize = 4;

/// A continuous state, of which the first [`Plant::dim`] entries are used.
pub type State = [f64; MAX_DIM];

/// Discrete mode of the automaton.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Mode 1: at `z_min`, v = 0.
    StuckMin,
    /// Mode 2: free motion.
    Free,
    /// Mode 3: at `z_max`, v = 0.
    StuckMax,
}

impl Mode {
    /// The numbering of the papers' automata (1, 2, 3).
    pub fn number(self) -> u8 {
        match self {
            Mode::StuckMin => 1,
            Mode::Free => 2,
            Mode::StuckMax => 3,
        }
    }
}

/// Mechanical limits and impact law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    pub z_min: f64,
    pub z_max: f64,
    /// γ: bounce `v⁺ = −γ·v` when `|v| > bounce_threshold`.
    pub restitution: f64,
    /// v_ε: at or below it the armature sticks.
    pub bounce_threshold: f64,
}

/// The continuous dynamics the simulator integrates.
///
/// `x[0]` is the position `z`, `x[1]` the velocity `v`; further states are the
/// plant's own (flux, core field…). `u` is the input (coil voltage or current).
pub trait Plant {
    /// Number of continuous states used (≤ [`MAX_DIM`]).
    fn dim(&self) -> usize;
    /// Free-motion derivative `dx = f(t, x, u)` (all `dim` entries written).
    fn deriv(&self, t: f64, x: &State, u: f64, dx: &mut State);
    /// Whether `x` is inside the model's domain (e.g. `|φ| < φ_sat`).
    /// Steps that leave it are rejected and retried smaller.
    fn in_domain(&self, _x: &State) -> bool {
        true
    }
    /// Typical magnitude of each state, used as the absolute-tolerance scale.
    fn scale(&self) -> State;
    fn limits(&self) -> Limits;
}
