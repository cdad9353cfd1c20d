//! Coulomb friction on the armature: a plant no actuator description holds
//! (issue 17 §2 names it among the effects outside the diagnosis's
//! vocabulary). The description's plant with a force F_c opposing the
//! motion, −F_c·tanh(v/v_s): the sign regularised over [`SLIP_SPEED`] so
//! that the field stays smooth for the simulator; it neither holds the
//! armature at rest nor delays a lift-off (tanh 0 = 0), it brakes a moving
//! one at about F_c/m.

use designer::model::{Model, ModelPlant};
use designer::replay::{replay_through, Replay};
use designer::sim::{Branches, Input, Limits, Options, Plant, SimError, State};

/// The speed over which the friction force reaches 76 % of F_c (tanh 1) [m/s]:
/// far below a valve's 0.1–2 m/s, so the force is nearly constant in motion.
pub const SLIP_SPEED: f64 = 5e-3;

/// `inner` with a Coulomb force `force` [N] on its armature of mass `mass`.
pub struct WithFriction<'a> {
    pub inner: &'a ModelPlant,
    pub force: f64,
    pub mass: f64,
}

impl WithFriction<'_> {
    /// The friction's acceleration at velocity `v`.
    fn decel(&self, v: f64) -> f64 {
        -self.force / self.mass * (v / SLIP_SPEED).tanh()
    }
}

impl Plant for WithFriction<'_> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn deriv(&self, t: f64, x: &State, u: f64, dx: &mut State) {
        self.inner.deriv(t, x, u, dx);
        dx[1] += self.decel(x[1]);
    }
    fn in_domain(&self, x: &State) -> bool {
        self.inner.in_domain(x)
    }
    fn scale(&self) -> State {
        self.inner.scale()
    }
    fn limits(&self) -> Limits {
        self.inner.limits()
    }
    fn smooth_beyond_limits(&self) -> bool {
        self.inner.smooth_beyond_limits()
    }
    fn switches(&self) -> usize {
        self.inner.switches()
    }
    fn switching(&self, t: f64, x: &State, u: f64, s: &mut Branches) {
        self.inner.switching(t, x, u, s)
    }
    fn deriv_branch(&self, t: f64, x: &State, u: f64, branch: &Branches, dx: &mut State) {
        self.inner.deriv_branch(t, x, u, branch, dx);
        dx[1] += self.decel(x[1]);
    }
    fn deriv_resting(&self, t: f64, x: &State, u: f64, branch: &Branches, dx: &mut State) {
        // At rest v = 0: no friction force.
        self.inner.deriv_resting(t, x, u, branch, dx)
    }
    fn switching_component(&self, j: usize) -> Option<usize> {
        self.inner.switching_component(j)
    }
    fn accel_branch(&self, t: f64, x: &State, u: f64, branch: &Branches) -> f64 {
        self.inner.accel_branch(t, x, u, branch) + self.decel(x[1])
    }
}

/// `designer::replay::replay` of `model` with Coulomb friction `force` [N].
pub fn replay_with_friction<I: Input + ?Sized>(
    model: &mut Model,
    force: f64,
    input: &I,
    output_times: &[f64],
    options: &Options,
) -> Result<Replay, SimError> {
    let mass = model.description.mechanics.mass;
    let inner = ModelPlant::new(model);
    let plant = WithFriction {
        inner: &inner,
        force,
        mass,
    };
    replay_through(&plant, &inner, model, input, output_times, options)
}
