//! The integrator of the automaton between events: it advances over
//! intervals on which the input is one affine piece, stops at every guard
//! crossing or branch switch, and hands the instant to the resets.
//!
//! **Event refinement.** The stages of a step that crosses a position limit
//! see the field beyond it. Unless the plant continues its field smoothly
//! there ([`Plant::smooth_beyond_limits`]), the step's dense output loses
//! order near the crossing: a step that finds an impact is then repeated with
//! the located time as its end, so that the impact is located on a step
//! whose stages lie (almost) all before it.

use super::field::rhs;
use super::options::{check_initial, check_plant, make_rk, Options, SimError};
use super::quadrature::{plant_state, Ext, Quadrature, EXT};
use super::trajectory::{Switch, Trajectory};
use crate::sim::input::Affine;
use crate::sim::rk::Dopri5;
use crate::sim::switching::Locking;
use crate::sim::{Limits, Mode, Plant, State, MAX_SWITCHES};

/// Rollbacks per event located (see `Engine::integrate`).
const MAX_REFINEMENTS: usize = 2;

/// The hybrid-automaton integrator shared by [`super::simulate`] and the
/// sampled mode: it advances over intervals on which the input is one affine
/// piece. Its guards, resets and recording are in the sibling modules.
pub(crate) struct Engine<'a, P: Plant, Q: Quadrature> {
    pub(super) plant: &'a P,
    pub(super) quad: &'a Q,
    pub(super) pd: usize,
    pub(super) nq: usize,
    pub(super) lim: Limits,
    pub(super) opts: Options,
    pub(super) rk: Dopri5<EXT>,
    pub(super) t: f64,
    pub(super) x: Ext,
    pub(super) mode: Mode,
    pub(super) need_init: bool,
    /// Branches held for the plant's switching functions.
    pub(super) lock: Locking,
    /// Time of the last impact at each limit (Zeno rule).
    pub(super) last_impact: [f64; 2],
    pub(super) extra_evals: usize,
    pub(super) out_times: &'a [f64],
    pub(super) next_out: usize,
    pub(super) traj: Trajectory,
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
        if self.rk.stats().attempted() >= self.opts.max_steps {
            return Err(SimError::TooManySteps {
                t: self.rk.t(),
                max: self.opts.max_steps,
            });
        }
        Ok(())
    }

    /// Ends the integration at `t` inside the last step: records the outputs
    /// before it and takes the state there from the dense output.
    pub(super) fn stop_at(&mut self, t: f64, piece: Affine, t_target: f64) {
        self.emit_dense(t, false, piece, t_target);
        self.rk.dense(t, &mut self.x);
        self.t = t;
    }
}
