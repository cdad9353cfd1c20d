//! The result of a simulation, recorded at the output times: states, input,
//! mode, quadratures, and every event and branch switch. Recorded by the
//! engine from the dense output of its steps, all output times of a step at
//! once.

use super::events::Event;
use super::quadrature::{head_state, plant_state, quad_state, Ext, QuadState, Quadrature, EXT};
use super::Engine;
use crate::sim::input::Affine;
use crate::sim::rk::StepStats;
use crate::sim::{Mode, Plant, State};

/// The simulated trajectory at the output times.
///
/// **Output convention.** Values at an output time equal to an event time are
/// the post-event ones (after all resets at that instant); `u` is recorded
/// right-continuous (the value after a jump at that time).
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

impl<P: Plant, Q: Quadrature> Engine<'_, P, Q> {
    /// Records the outputs at or before the current time (and before `limit`).
    pub(super) fn emit_current(&mut self, piece: Affine, limit: f64) {
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
    pub(super) fn emit_dense(&mut self, t_hi: f64, inclusive: bool, piece: Affine, limit: f64) {
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
