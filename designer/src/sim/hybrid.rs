//! Event-driven simulation of the three-mode hybrid automaton
//! ([PT Fig. 3]: free motion, and at rest on either stop).
//!
//! Between events the continuous state is integrated by [`Dopri5`]; the mode
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
//! **Event refinement.** The stages of a step that crosses a position limit
//! see the field beyond it. Unless the plant continues its field smoothly
//! there ([`Plant::smooth_beyond_limits`]), the step's dense output loses
//! order near the crossing: a step that finds an impact is then repeated with
//! the located time as its end, so that the impact is located on a step
//! whose stages lie (almost) all before it.
//!
//! Guards (all fire when strictly positive):
//! - Free: `z_min − z` (impact at the lower limit), `z − z_max` (upper limit);
//! - StuckMin: the free acceleration `a = deriv(t, (z_min, 0, …), u)[1]` (lift-off);
//! - StuckMax: `−a`.
//!
//! Resets at one instant are applied until none applies (bounded by
//! [`MAX_EVENTS_PER_INSTANT`]): an impact with `|v| > v_ε` bounces
//! (`v⁺ = −γ·v`, stays Free), a slower one sticks (`v⁺ = 0`); a stuck armature
//! whose free acceleration points away lifts off at once.
//!
//! **Zeno rule.** With `v_ε = 0` and `γ > 0` a bounce sequence never ends by
//! itself. An impact that would bounce sticks instead (and its event carries
//! `zeno: true`) when the time since the previous impact at the same limit is
//! below `Options::zeno_time` (1e-12 s), or when the apex of the next bounce
//! (`v⁺²/2a`, `a` the acceleration towards the limit) is too small to be
//! represented in `z` (a few ulp of the limit, more for γ near 1).
//!
//! **Output convention.** Values at an output time equal to an event time are
//! the post-event ones (after all resets at that instant); `u` is recorded
//! right-continuous (the value after a jump at that time).
//!
//! **Extra integrals.** [`simulate_with`] integrates `Q ≤ MAX_QUAD` quadratures
//! `q̇ = integrand(t, x, ẋ, u, mode)` together with the plant (they take part in
//! the error control), e.g. the terms of an energy balance. Internally the
//! integrator is const-generic and runs on `[f64; MAX_DIM + MAX_QUAD]`, so the
//! plant interface keeps `State = [f64; MAX_DIM]`.

// `!(a > b)` comparisons are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use thiserror::Error;

use super::input::{Affine, Input};
use super::locate::locate;
use super::rk::{Dopri5, RkError, StepStats};
use super::switching::Locking;
use super::{Branches, Limits, Mode, Plant, State, MAX_DIM, MAX_SWITCHES};

/// Largest number of extra integrals (quadratures) of [`simulate_with`].
pub const MAX_QUAD: usize = 8;
/// Values of the quadratures (the first `Quadrature::len` are used).
pub type QuadState = [f64; MAX_QUAD];
/// Cap on the number of events at a single instant.
pub const MAX_EVENTS_PER_INSTANT: usize = 16;

const EXT: usize = MAX_DIM + MAX_QUAD;
/// Plant states followed by quadratures, packed: `[x_0..x_pd, q_0..q_nq, 0…]`.
type Ext = [f64; EXT];

/// Which mechanical limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Limit {
    /// `z_min`.
    Min,
    /// `z_max`.
    Max,
}

impl Limit {
    fn stuck_mode(self) -> Mode {
        match self {
            Limit::Min => Mode::StuckMin,
            Limit::Max => Mode::StuckMax,
        }
    }
    /// Sign of a velocity pointing into the limit.
    fn inward(self) -> f64 {
        match self {
            Limit::Min => -1.0,
            Limit::Max => 1.0,
        }
    }
    fn index(self) -> usize {
        self as usize
    }
}

/// What happened at an event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EventKind {
    /// The armature hit `limit` with velocity `v_before`. Either it bounced
    /// (`v_after = −γ·v_before`, mode stays Free) or it stuck (`v_after = 0`,
    /// stuck mode; `|v_before| ≤ v_ε`, `γ = 0`, or `zeno` is set).
    /// The kinetic energy removed is `½m(v_before² − v_after²)`.
    Impact {
        limit: Limit,
        v_before: f64,
        v_after: f64,
        /// The bounce was suppressed by the Zeno rule (see the module docs).
        zeno: bool,
    },
    /// Free at `limit` with `v = 0` and the acceleration not pointing away:
    /// becomes stuck without an impact.
    Stick { limit: Limit },
    /// The free acceleration points away from `limit`: stuck → Free. Also
    /// recorded at the start time when the initial mode is stuck but the
    /// acceleration already points away.
    LiftOff { limit: Limit },
}

/// A discrete transition of the automaton.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    pub t: f64,
    pub kind: EventKind,
    pub mode_after: Mode,
}

/// Integration settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Relative tolerance (default 1e-8).
    pub rtol: f64,
    /// Absolute tolerance per plant state (default `rtol × plant.scale()`).
    pub atol: Option<State>,
    /// Largest step (default ∞).
    pub max_step: f64,
    /// Smallest step before giving up (default 0: only the ulp floor).
    pub min_step: f64,
    /// First step at the start and after every event (default: Hairer's
    /// heuristic at the start; after an event the step size in force, which
    /// fits the motion just before it better than the heuristic does).
    pub first_step: Option<f64>,
    /// Accepted plus rejected steps before giving up (default 1 000 000).
    pub max_steps: usize,
    /// Impacts at the same limit closer than this stick (default 1e-12 s).
    pub zeno_time: f64,
    /// Relative event-time tolerance: `event_tol·max(1, |t|)` (default 1e-13).
    pub event_tol: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            atol: None,
            max_step: f64::INFINITY,
            min_step: 0.0,
            first_step: None,
            max_steps: 1_000_000,
            zeno_time: 1e-12,
            event_tol: 1e-13,
        }
    }
}

/// The simulated trajectory at the output times.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trajectory {
    pub t: Vec<f64>,
    /// Plant states (first `plant.dim()` entries used).
    pub x: Vec<State>,
    /// Input (right-continuous at jumps).
    pub u: Vec<f64>,
    pub mode: Vec<Mode>,
    /// Quadratures at the output times (empty without quadratures).
    pub q: Vec<QuadState>,
    /// All events, in time order.
    pub events: Vec<Event>,
    /// The located sign changes of the plant's switching functions, in time
    /// order (see [`Plant::switches`]).
    pub switches: Vec<Switch>,
    /// Integrator work; `evaluations` counts every evaluation of the plant's
    /// field or acceleration (integration stages, guards and reset checks).
    pub stats: StepStats,
}

/// A located sign change of a switching function: from `t` on, the field
/// runs on the other branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Switch {
    pub t: f64,
    /// Which switching function.
    pub index: usize,
}

impl Trajectory {
    pub fn len(&self) -> usize {
        self.t.len()
    }
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    /// State component `i` at every output time.
    pub fn component(&self, i: usize) -> Vec<f64> {
        self.x.iter().map(|x| x[i]).collect()
    }
}

/// Why a simulation failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SimError {
    #[error("invalid options: {0}")]
    Options(&'static str),
    #[error("invalid plant: {0}")]
    Plant(&'static str),
    #[error("invalid output times: {0}")]
    OutputTimes(&'static str),
    #[error("invalid initial state: {0}")]
    InitialState(&'static str),
    #[error("the input is not finite at t = {t}")]
    NonFiniteInput { t: f64 },
    #[error(transparent)]
    Integrator(#[from] RkError),
    #[error("more than {max} steps before t = {t}")]
    TooManySteps { t: f64, max: usize },
    #[error("more than {n} events at the single instant t = {t} (Zeno behaviour)")]
    EventLoop { t: f64, n: usize },
}

/// Extra integrals computed along the trajectory: `q̇ = integrand(…)`, `q(t0) = 0`.
pub trait Quadrature {
    /// Number of integrals (≤ [`MAX_QUAD`]).
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Writes the `len()` integrands at `(t, x, ẋ, u, mode)`; `ẋ` is the
    /// derivative actually integrated (`ż = v̇ = 0` when stuck).
    fn integrand(&self, t: f64, x: &State, dx: &State, u: f64, mode: Mode, out: &mut QuadState);
    /// Typical magnitude of each integral (absolute tolerance = rtol × scale).
    fn scale(&self) -> QuadState {
        [1.0; MAX_QUAD]
    }
}

/// No extra integrals.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoQuadrature;

impl Quadrature for NoQuadrature {
    fn len(&self) -> usize {
        0
    }
    fn integrand(&self, _: f64, _: &State, _: &State, _: f64, _: Mode, _: &mut QuadState) {}
}

/// Rollbacks per event located (see `Engine::integrate`).
const MAX_REFINEMENTS: usize = 2;

/// Simulates from `output_times[0]` to its last entry (non-decreasing),
/// recording at every output time. See the module docs for conventions.
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
    if times.iter().any(|t| !t.is_finite()) {
        return Err(SimError::OutputTimes("not finite"));
    }
    if times.windows(2).any(|w| w[1] < w[0]) {
        return Err(SimError::OutputTimes("decreasing"));
    }
    Ok(())
}

/// The plant's states of an extended state (unused entries 0). Element by
/// element over the fixed size: a `memcpy` call would cost more (hot path).
#[inline]
fn plant_state(x: &Ext, pd: usize) -> State {
    std::array::from_fn(|i| if i < pd { x[i] } else { 0.0 })
}

/// The hybrid-automaton integrator shared by [`simulate`] and the sampled mode:
/// it advances over intervals on which the input is one affine piece.
pub(crate) struct Engine<'a, P: Plant, Q: Quadrature> {
    plant: &'a P,
    quad: &'a Q,
    pd: usize,
    nq: usize,
    lim: Limits,
    opts: Options,
    rk: Dopri5<EXT>,
    t: f64,
    x: Ext,
    mode: Mode,
    need_init: bool,
    /// Branches held for the plant's switching functions.
    lock: Locking,
    /// Time of the last impact at each limit (Zeno rule).
    last_impact: [f64; 2],
    extra_evals: usize,
    out_times: &'a [f64],
    next_out: usize,
    traj: Trajectory,
}

impl<'a, P: Plant, Q: Quadrature> Engine<'a, P, Q> {
    pub(crate) fn new(
        plant: &'a P,
        quad: &'a Q,
        t0: f64,
        x0: State,
        mode0: Mode,
        out_times: &'a [f64],
        opts: &Options,
    ) -> Result<Self, SimError> {
        let (pd, nq, lim) = (plant.dim(), quad.len(), plant.limits());
        check_plant(pd, nq, &lim)?;
        if plant.switches() > MAX_SWITCHES {
            return Err(SimError::Plant(
                "more switching functions than MAX_SWITCHES",
            ));
        }
        let rk = make_rk(plant, quad, opts)?;
        let mut x = [0.0; EXT];
        x[..pd].copy_from_slice(&x0[..pd]);
        check_initial(plant, &mut x, mode0, &lim)?;
        let n = out_times.len();
        let traj = Trajectory {
            t: Vec::with_capacity(n),
            x: Vec::with_capacity(n),
            u: Vec::with_capacity(n),
            mode: Vec::with_capacity(n),
            q: Vec::with_capacity(if nq > 0 { n } else { 0 }),
            ..Default::default()
        };
        Ok(Self {
            plant,
            quad,
            pd,
            nq,
            lim,
            opts: *opts,
            rk,
            t: t0,
            x,
            mode: mode0,
            need_init: true,
            lock: Locking::new(plant.switches()),
            last_impact: [f64::NEG_INFINITY; 2],
            extra_evals: 0,
            out_times,
            next_out: 0,
            traj,
        })
    }

    pub(crate) fn t(&self) -> f64 {
        self.t
    }
    pub(crate) fn mode(&self) -> Mode {
        self.mode
    }
    pub(crate) fn state(&self) -> State {
        plant_state(&self.x, self.pd)
    }

    /// Integrates from the current time to `t_target` with input `piece`,
    /// handling every event on the way. Outputs at `t_target` itself are left
    /// for the next call (or [`finish`](Self::finish)), which knows the input
    /// after `t_target`.
    pub(crate) fn advance(&mut self, t_target: f64, piece: Affine) -> Result<(), SimError> {
        if !(piece.u0.is_finite() && piece.slope.is_finite() && piece.value(t_target).is_finite()) {
            return Err(SimError::NonFiniteInput { t: self.t });
        }
        self.lock.start_piece();
        loop {
            self.resolve(piece)?;
            self.emit_current(piece, t_target);
            if self.t >= t_target || self.integrate(t_target, piece)? {
                return Ok(());
            }
        }
    }

    /// Applies the events at the final time with the input `piece` in force
    /// there, records the remaining outputs and returns the trajectory.
    pub(crate) fn finish(mut self, piece: Affine) -> Result<Trajectory, SimError> {
        self.resolve(piece)?;
        self.emit_current(piece, f64::INFINITY);
        let mut traj = self.traj;
        traj.stats = self.rk.stats();
        traj.stats.evaluations += self.extra_evals;
        Ok(traj)
    }

    /// Integrates until `t_target` (returns true) or until a guard fires or
    /// a switching function changes sign (returns false, with the state at
    /// that time, before any reset).
    fn integrate(&mut self, t_target: f64, piece: Affine) -> Result<bool, SimError> {
        self.choose_branches(t_target, piece);
        let (mut f, mut dom) = (self.field_fn(piece), self.domain_fn());
        if std::mem::take(&mut self.need_init) {
            self.rk.init(self.t, &self.x, &mut f, &mut dom);
        } else {
            self.rk.restart(self.t, &self.x, &mut f, &mut dom);
        }
        let steps0 = self.rk.stats().accepted;
        // Event refinement (module docs): roll back to the step's start and
        // integrate with the located impact time as a ceiling, at most
        // `MAX_REFINEMENTS` times per event.
        let refine = self.mode == Mode::Free && !self.plant.smooth_beyond_limits();
        let (mut ceiling, mut refinements) = (f64::INFINITY, 0);
        loop {
            self.check_step_budget()?;
            let (t_start, x_start) = (self.rk.t(), *self.rk.x());
            if ceiling < t_target {
                self.rk.step(&mut f, &mut dom, ceiling)?;
            } else {
                self.rk.step_to_breakpoint(&mut f, &mut dom, t_target)?;
            }
            let switch = self.find_switch(piece);
            let t_hi = switch.map_or(self.rk.t(), |s| s.0);
            if let Some(te) = self.find_event(piece, t_hi) {
                if refine && refinements < MAX_REFINEMENTS && te > t_start {
                    refinements += 1;
                    ceiling = te;
                    self.rk.restart(t_start, &x_start, &mut f, &mut dom);
                    continue;
                }
                self.stop_at(te, piece, t_target);
                self.need_init = self.opts.first_step.is_some();
                return Ok(false);
            }
            if let Some((ts, index)) = switch {
                self.traj.switches.push(Switch { t: ts, index });
                self.stop_at(ts, piece, t_target);
                self.lock.switched(self.rk.stats().accepted - steps0);
                return Ok(false);
            }
            self.emit_dense(self.rk.t(), true, piece, t_target);
            if self.rk.t() >= ceiling {
                ceiling = f64::INFINITY;
            }
            if self.rk.t() >= t_target {
                self.t = t_target;
                self.x = *self.rk.x();
                return Ok(true);
            }
        }
    }

    /// Chooses the branches of the switching functions for a (re)start.
    fn choose_branches(&mut self, t_target: f64, piece: Affine) {
        let h = self.rk.step_size();
        let probe = if h > 0.0 { h } else { t_target - self.t }.min(t_target - self.t);
        let x = plant_state(&self.x, self.pd);
        self.lock.choose(self.plant, self.t, &x, piece, probe);
    }

    /// The vector field integrated in the current mode and branches.
    fn field_fn(&self, piece: Affine) -> impl FnMut(f64, &Ext, &mut Ext) + 'a {
        let (plant, quad, pd, nq, mode) = (self.plant, self.quad, self.pd, self.nq, self.mode);
        let branch = self.lock.held();
        move |t: f64, x: &Ext, dx: &mut Ext| rhs(plant, quad, pd, nq, mode, branch, piece, t, x, dx)
    }

    /// The plant's domain predicate on extended states.
    fn domain_fn(&self) -> impl FnMut(&Ext) -> bool + 'a {
        let (plant, pd) = (self.plant, self.pd);
        move |x: &Ext| plant.in_domain(&plant_state(x, pd))
    }

    fn check_step_budget(&self) -> Result<(), SimError> {
        let s = self.rk.stats();
        if s.accepted + s.rejected >= self.opts.max_steps {
            return Err(SimError::TooManySteps {
                t: self.rk.t(),
                max: self.opts.max_steps,
            });
        }
        Ok(())
    }

    /// Ends the integration at `t` inside the last step: records the outputs
    /// before it and takes the state there from the dense output.
    fn stop_at(&mut self, t: f64, piece: Affine, t_target: f64) {
        self.emit_dense(t, false, piece, t_target);
        self.rk.dense(t, &mut self.x);
        self.t = t;
    }

    /// Earliest guard crossing inside the last accepted step up to `tb`, if any.
    fn find_event(&mut self, piece: Affine, tb: f64) -> Option<f64> {
        let ta = self.rk.t_prev();
        let tol = self.opts.event_tol * tb.abs().max(1.0);
        match self.mode {
            Mode::Free => self.find_impact(ta, tb, tol),
            Mode::StuckMin => self.find_lift_off(ta, tb, tol, 1.0, piece),
            Mode::StuckMax => self.find_lift_off(ta, tb, tol, -1.0, piece),
        }
    }

    /// Earliest sign change of a switching function inside the last accepted
    /// step, if any: (time, which function) (see `switching.rs`).
    fn find_switch(&self, piece: Affine) -> Option<(f64, usize)> {
        let (rk, pd) = (&self.rk, self.pd);
        let (ta, tb) = (rk.t_prev(), rk.t());
        let tol = self.opts.event_tol * tb.abs().max(1.0);
        let x_end = plant_state(rk.x(), pd);
        let s_end = self
            .lock
            .values_at(self.plant, tb, &x_end, rk.dx(), piece.value(tb))?;
        let dense = |t: f64| head_state(rk.dense_head(t), pd);
        self.lock
            .find(self.plant, ta, tb, &s_end, dense, piece, tol)
    }

    /// Position guards, checked at 4 points of the step (cheap: dense output
    /// of `z` only) so that a brief excursion inside the step is not missed.
    fn find_impact(&self, ta: f64, tb: f64, tol: f64) -> Option<f64> {
        let (rk, lim) = (&self.rk, self.lim);
        let g = |t: f64| {
            let z = rk.dense_component(0, t);
            (lim.z_min - z, z - lim.z_max)
        };
        let (mut tp, mut gp) = (ta, g(ta));
        for j in 1..=4 {
            let tj = if j == 4 {
                tb
            } else {
                ta + (tb - ta) * (j as f64 / 4.0)
            };
            let gj = g(tj);
            if gj.0 > 0.0 || gj.1 > 0.0 {
                let mut te = tj;
                if gj.0 > 0.0 {
                    te = te.min(locate(|t| g(t).0, tp, gp.0, tj, gj.0, tol));
                }
                if gj.1 > 0.0 {
                    te = te.min(locate(|t| g(t).1, tp, gp.1, tj, gj.1, tol));
                }
                return Some(te);
            }
            (tp, gp) = (tj, gj);
        }
        None
    }

    /// Lift-off guard `sign·a(t) > 0`, checked at the middle and end of the step.
    fn find_lift_off(
        &mut self,
        ta: f64,
        tb: f64,
        tol: f64,
        sign: f64,
        piece: Affine,
    ) -> Option<f64> {
        let mut evals = 0;
        let branch = self.lock.held();
        let mut g = |t: f64| {
            evals += 1;
            let mut x = [0.0; EXT];
            self.rk.dense(t, &mut x);
            sign * free_accel(self.plant, self.pd, branch, t, &x, piece)
        };
        let (mut tp, mut gp) = (ta, f64::NEG_INFINITY);
        let mut found = None;
        for tj in [ta + 0.5 * (tb - ta), tb] {
            let gj = g(tj);
            if gj > 0.0 {
                if gp == f64::NEG_INFINITY {
                    gp = g(tp);
                }
                found = Some(locate(&mut g, tp, gp, tj, gj, tol));
                break;
            }
            (tp, gp) = (tj, gj);
        }
        self.extra_evals += evals;
        found
    }

    /// Applies resets at the current instant until none applies.
    fn resolve(&mut self, piece: Affine) -> Result<(), SimError> {
        for _ in 0..MAX_EVENTS_PER_INSTANT {
            if !self.reset_once(piece) {
                return Ok(());
            }
            self.need_init = self.opts.first_step.is_some();
        }
        Err(SimError::EventLoop {
            t: self.t,
            n: MAX_EVENTS_PER_INSTANT,
        })
    }

    /// One reset, if the current state calls for one.
    fn reset_once(&mut self, piece: Affine) -> bool {
        match self.mode {
            Mode::Free => {
                if self.x[0] <= self.lim.z_min {
                    self.x[0] = self.lim.z_min;
                    self.at_limit(Limit::Min, piece)
                } else if self.x[0] >= self.lim.z_max {
                    self.x[0] = self.lim.z_max;
                    self.at_limit(Limit::Max, piece)
                } else {
                    false
                }
            }
            Mode::StuckMin => self.lift_off_if(Limit::Min, piece),
            Mode::StuckMax => self.lift_off_if(Limit::Max, piece),
        }
    }

    /// Free exactly at `limit`: impact if moving into it, stick if resting
    /// with the acceleration not pointing away.
    fn at_limit(&mut self, limit: Limit, piece: Affine) -> bool {
        let v_in = limit.inward() * self.x[1];
        if v_in > 0.0 {
            self.impact(limit, piece);
            return true;
        }
        if v_in < 0.0 || -limit.inward() * self.accel(piece) > 0.0 {
            return false;
        }
        self.x[1] = 0.0;
        self.push(EventKind::Stick { limit }, limit.stuck_mode());
        true
    }

    fn impact(&mut self, limit: Limit, piece: Affine) {
        let lim = self.lim;
        let v = self.x[1];
        let bounce = -lim.restitution * v;
        let (v_after, zeno) = if v.abs() <= lim.bounce_threshold || bounce == 0.0 {
            (0.0, false)
        } else if self.is_zeno(limit, bounce, piece) {
            (0.0, true)
        } else {
            (bounce, false)
        };
        self.last_impact[limit.index()] = self.t;
        self.x[1] = v_after;
        let mode = if v_after == 0.0 {
            limit.stuck_mode()
        } else {
            Mode::Free
        };
        let kind = EventKind::Impact {
            limit,
            v_before: v,
            v_after,
            zeno,
        };
        self.push(kind, mode);
    }

    /// The Zeno rule of the module docs.
    fn is_zeno(&mut self, limit: Limit, v_after: f64, piece: Affine) -> bool {
        if self.t - self.last_impact[limit.index()] < self.opts.zeno_time {
            return true;
        }
        let a_in = limit.inward() * self.accel(piece);
        if !(a_in > 0.0) {
            return false;
        }
        let g2 = self.lim.restitution.powi(2);
        let z_lim = match limit {
            Limit::Min => self.lim.z_min,
            Limit::Max => self.lim.z_max,
        };
        let ulp = z_lim.abs().max(f64::MIN_POSITIVE) * f64::EPSILON;
        let factor = 4.0 + (g2 / (1.0 - g2)).min(1e4);
        v_after * v_after / (2.0 * a_in) <= factor * ulp
    }

    fn lift_off_if(&mut self, limit: Limit, piece: Affine) -> bool {
        if -limit.inward() * self.accel(piece) > 0.0 {
            self.push(EventKind::LiftOff { limit }, Mode::Free);
            true
        } else {
            false
        }
    }

    /// Free-motion acceleration at the current state.
    fn accel(&mut self, piece: Affine) -> f64 {
        self.extra_evals += 1;
        free_accel(
            self.plant,
            self.pd,
            self.lock.held(),
            self.t,
            &self.x,
            piece,
        )
    }

    fn push(&mut self, kind: EventKind, mode_after: Mode) {
        self.mode = mode_after;
        self.traj.events.push(Event {
            t: self.t,
            kind,
            mode_after,
        });
    }

    /// Records the outputs at or before the current time (and before `limit`).
    fn emit_current(&mut self, piece: Affine, limit: f64) {
        while let Some(&to) = self.out_times.get(self.next_out) {
            if to > self.t || to >= limit {
                break;
            }
            let x = self.x;
            self.record(to, &x, piece.value(to));
        }
    }

    /// Records the outputs before `t_hi` (or at it if `inclusive`) and before
    /// `limit` from the dense output of the last step.
    fn emit_dense(&mut self, t_hi: f64, inclusive: bool, piece: Affine, limit: f64) {
        let pending = &self.out_times[self.next_out..];
        let n = pending
            .iter()
            .take_while(|&&to| (to < t_hi || (inclusive && to == t_hi)) && to < limit)
            .count();
        if n == 0 {
            return;
        }
        // All of them at once: one capacity check per column, tight loops.
        let (times, rk, pd, nq) = (&pending[..n], &self.rk, self.pd, self.nq);
        let dense = |&to: &f64| {
            let mut x = [0.0; EXT];
            rk.dense(to, &mut x);
            x
        };
        let tr = &mut self.traj;
        tr.t.extend_from_slice(times);
        tr.x.extend(times.iter().map(|&to| head_state(rk.dense_head(to), pd)));
        tr.u.extend(times.iter().map(|&to| piece.value(to)));
        tr.mode.extend(std::iter::repeat_n(self.mode, n));
        if nq > 0 {
            tr.q.extend(times.iter().map(|to| quad_state(&dense(to), pd, nq)));
        }
        self.next_out += n;
    }

    fn record(&mut self, t: f64, x: &Ext, u: f64) {
        let tr = &mut self.traj;
        tr.t.push(t);
        tr.x.push(plant_state(x, self.pd));
        tr.u.push(u);
        tr.mode.push(self.mode);
        if self.nq > 0 {
            tr.q.push(quad_state(x, self.pd, self.nq));
        }
        self.next_out += 1;
    }
}

/// The plant's states of the head of an extended state (unused entries 0).
#[inline]
fn head_state(x: State, pd: usize) -> State {
    std::array::from_fn(|i| if i < pd { x[i] } else { 0.0 })
}

/// The quadratures of an extended state (unused entries 0).
fn quad_state(x: &Ext, pd: usize, nq: usize) -> QuadState {
    let mut q = [0.0; MAX_QUAD];
    q[..nq].copy_from_slice(&x[pd..pd + nq]);
    q
}

/// The plant's field, on the held `branch` or (`None`) with the live signs.
#[inline]
fn field<P: Plant>(plant: &P, branch: Option<Branches>, t: f64, x: &State, u: f64) -> State {
    let mut dx = [0.0; MAX_DIM];
    match branch {
        Some(b) => plant.deriv_branch(t, x, u, &b, &mut dx),
        None => plant.deriv(t, x, u, &mut dx),
    }
    dx
}

/// The vector field of `mode`: plant derivative (`ż = v̇ = 0` when stuck),
/// then the quadratures' integrands.
#[allow(clippy::too_many_arguments)]
#[inline]
fn rhs<P: Plant, Q: Quadrature>(
    plant: &P,
    quad: &Q,
    pd: usize,
    nq: usize,
    mode: Mode,
    branch: Option<Branches>,
    piece: Affine,
    t: f64,
    x: &Ext,
    out: &mut Ext,
) {
    let xs = plant_state(x, pd);
    let u = piece.value(t);
    let mut dx = match (mode, branch) {
        (Mode::Free, _) | (_, None) => field(plant, branch, t, &xs, u),
        (_, Some(b)) => {
            let mut dx = [0.0; MAX_DIM];
            plant.deriv_resting(t, &xs, u, &b, &mut dx);
            dx
        }
    };
    if mode != Mode::Free {
        dx[0] = 0.0;
        dx[1] = 0.0;
    }
    for (i, o) in out.iter_mut().enumerate().take(MAX_DIM) {
        if i < pd {
            *o = dx[i];
        }
    }
    if nq > 0 {
        let mut q = [0.0; MAX_QUAD];
        quad.integrand(t, &xs, &dx, u, mode, &mut q);
        out[pd..pd + nq].copy_from_slice(&q[..nq]);
    }
}

fn free_accel<P: Plant>(
    plant: &P,
    pd: usize,
    branch: Option<Branches>,
    t: f64,
    x: &Ext,
    piece: Affine,
) -> f64 {
    let (xs, u) = (plant_state(x, pd), piece.value(t));
    match branch {
        Some(b) => plant.accel_branch(t, &xs, u, &b),
        None => field(plant, None, t, &xs, u)[1],
    }
}

fn check_plant(pd: usize, nq: usize, lim: &Limits) -> Result<(), SimError> {
    if !(2..=MAX_DIM).contains(&pd) {
        return Err(SimError::Plant(
            "dim must lie in 2..=MAX_DIM (z and v first)",
        ));
    }
    if nq > MAX_QUAD {
        return Err(SimError::Plant("more quadratures than MAX_QUAD"));
    }
    if !(lim.z_min.is_finite() && lim.z_max.is_finite() && lim.z_min < lim.z_max) {
        return Err(SimError::Plant("limits must be finite with z_min < z_max"));
    }
    if !(lim.restitution >= 0.0 && lim.restitution.is_finite()) {
        return Err(SimError::Plant("restitution must be finite and ≥ 0"));
    }
    if !(lim.bounce_threshold >= 0.0) {
        return Err(SimError::Plant("bounce threshold must be ≥ 0"));
    }
    Ok(())
}

/// Builds the integrator with the tolerances of `opts`.
fn make_rk<P: Plant, Q: Quadrature>(
    plant: &P,
    quad: &Q,
    opts: &Options,
) -> Result<Dopri5<EXT>, SimError> {
    let (pd, nq) = (plant.dim(), quad.len());
    if !(opts.rtol.is_finite() && opts.rtol >= 0.0) {
        return Err(SimError::Options("rtol must be finite and ≥ 0"));
    }
    if !(opts.max_step > 0.0 && opts.min_step >= 0.0 && opts.min_step.is_finite()) {
        return Err(SimError::Options(
            "max_step must be > 0 and min_step finite and ≥ 0",
        ));
    }
    if opts.first_step.is_some_and(|h| !(h > 0.0 && h.is_finite())) {
        return Err(SimError::Options("first_step must be positive and finite"));
    }
    if !(opts.zeno_time >= 0.0 && opts.event_tol >= 0.0) {
        return Err(SimError::Options("zeno_time and event_tol must be ≥ 0"));
    }
    let plant_atol = opts
        .atol
        .unwrap_or_else(|| plant.scale().map(|s| opts.rtol * s.abs()));
    let q_scale = quad.scale();
    let mut atol = [0.0; EXT];
    atol[..pd].copy_from_slice(&plant_atol[..pd]);
    for j in 0..nq {
        atol[pd + j] = opts.rtol * q_scale[j].abs();
    }
    if atol[..pd + nq].iter().any(|a| !(a.is_finite() && *a > 0.0)) {
        return Err(SimError::Options(
            "absolute tolerances must be positive and finite (check atol, rtol and the scales)",
        ));
    }
    let rk = Dopri5::new(pd + nq, opts.rtol, atol)
        .with_max_step(opts.max_step)
        .with_min_step(opts.min_step)
        .with_first_step(opts.first_step);
    Ok(rk)
}

/// Validates `x0` for `mode0` (a stuck mode pins `z` to its limit and `v` to 0).
fn check_initial<P: Plant>(
    plant: &P,
    x: &mut Ext,
    mode0: Mode,
    lim: &Limits,
) -> Result<(), SimError> {
    let pd = plant.dim();
    if x[..pd].iter().any(|v| !v.is_finite()) {
        return Err(SimError::InitialState("not finite"));
    }
    match mode0 {
        Mode::StuckMin => (x[0], x[1]) = (lim.z_min, 0.0),
        Mode::StuckMax => (x[0], x[1]) = (lim.z_max, 0.0),
        Mode::Free => {
            if x[0] < lim.z_min || x[0] > lim.z_max {
                return Err(SimError::InitialState("z outside [z_min, z_max]"));
            }
        }
    }
    if !plant.in_domain(&plant_state(x, pd)) {
        return Err(SimError::InitialState("outside the plant's domain"));
    }
    Ok(())
}
