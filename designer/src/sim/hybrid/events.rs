//! The discrete transitions: the resets applied at one instant and the
//! events they record.
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

use super::field::free_accel;
use super::options::SimError;
use super::quadrature::Quadrature;
use super::Engine;
use crate::sim::input::Affine;
use crate::sim::{Mode, Plant};

/// Cap on the number of events at a single instant.
pub const MAX_EVENTS_PER_INSTANT: usize = 16;

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
        /// The bounce was suppressed by the Zeno rule (see the module docs of
        /// `sim/hybrid/events.rs`).
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

impl<P: Plant, Q: Quadrature> Engine<'_, P, Q> {
    /// Applies resets at the current instant until none applies.
    pub(super) fn resolve(&mut self, piece: Affine) -> Result<(), SimError> {
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
}
