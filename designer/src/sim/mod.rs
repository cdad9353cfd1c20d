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
//!
//! A plant whose field switches between smooth branches by the sign of some
//! function of the state (the Jiles–Atherton core's `sign(φ̇)`) can expose
//! those switching functions; the simulator then holds each branch fixed
//! during a step and switches at the located zero crossing (see
//! `switching.rs`), so that no step integrates across the kink.

mod hybrid;
mod input;
mod locate;
mod rk;
mod sampled;
mod switching;

pub use hybrid::{
    simulate, simulate_with, Event, EventKind, Limit, NoQuadrature, Options, QuadState, Quadrature,
    SimError, Switch, Trajectory, MAX_EVENTS_PER_INSTANT, MAX_QUAD,
};
pub use input::{Affine, Cursor, Input, InputError, PiecewiseLinear};
pub use rk::{Dopri5, RkError, StepStats};
pub use sampled::{simulate_sampled, simulate_sampled_with, Controller, Measurement};
pub use switching::MAX_CHATTER;

/// Largest number of continuous states a plant may have (z, v, φ, H_c).
pub const MAX_DIM: usize = 4;

/// Largest number of switching functions a plant may have (see
/// [`Plant::switches`]).
pub const MAX_SWITCHES: usize = 4;

/// One value per switching function (the first [`Plant::switches`] used):
/// the functions' values, or the branch held for each (+1, −1, or 0 while the
/// function is identically 0).
pub type Branches = [f64; MAX_SWITCHES];

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
    /// Whether [`deriv`](Self::deriv) continues the field beyond the position
    /// limits at least C¹ (e.g. by its tangent). Then a step that crosses a
    /// limit is as accurate as any other and the impact is located on it
    /// directly; otherwise (the default) the step is repeated up to the
    /// located impact, so that no stage sees the extension.
    fn smooth_beyond_limits(&self) -> bool {
        false
    }

    /// Number of switching functions (≤ [`MAX_SWITCHES`]; default none).
    ///
    /// A field containing `sign(s(t, x, u))` is not smooth where `s` changes
    /// sign: a Runge–Kutta step across that surface loses order, and its
    /// error estimate misleads the step-size control. A plant that exposes
    /// `s` (in [`switching`](Self::switching)) and the field with the sign
    /// held (in [`deriv_branch`](Self::deriv_branch)) is integrated one
    /// smooth branch at a time, switching at the located zero crossings.
    fn switches(&self) -> usize {
        0
    }
    /// Writes the switching functions `s_j(t, x, u)`, `j < switches()`.
    fn switching(&self, _t: f64, _x: &State, _u: f64, _s: &mut Branches) {}
    /// The field with `sign(s_j)` replaced by `branch[j]`: the smooth
    /// continuation of that branch beyond `s_j = 0`. Equal to
    /// [`deriv`](Self::deriv) when `branch[j] = sign(s_j(t, x, u))` for all j.
    fn deriv_branch(&self, t: f64, x: &State, u: f64, _branch: &Branches, dx: &mut State) {
        self.deriv(t, x, u, dx)
    }
    /// The field while the armature rests on a stop: only `dx[2..]` are used
    /// (ż = v̇ = 0 there). Default: [`deriv_branch`](Self::deriv_branch);
    /// override it when the rest is cheaper.
    fn deriv_resting(&self, t: f64, x: &State, u: f64, branch: &Branches, dx: &mut State) {
        self.deriv_branch(t, x, u, branch, dx)
    }
    /// The component `i ≥ 2` of the field that equals switching function `j`
    /// on every branch (e.g. s = φ̇ for δ = sign(φ̇)), if any: the simulator
    /// then reads the function's value at the end of a step from the
    /// derivative it has computed there anyway.
    fn switching_component(&self, _j: usize) -> Option<usize> {
        None
    }
    /// The free-motion acceleration `deriv_branch(t, x, u, branch)[1]` alone
    /// (the lift-off guard needs nothing else; override it when it is
    /// cheaper than the whole field).
    fn accel_branch(&self, t: f64, x: &State, u: f64, branch: &Branches) -> f64 {
        let mut dx = [0.0; MAX_DIM];
        self.deriv_branch(t, x, u, branch, &mut dx);
        dx[1]
    }
}
