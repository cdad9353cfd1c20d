//! Position control by backstepping through the magnetic force with the
//! switching strategies of switched-force-backstepping [SB §IV], written
//! once for every design and both floats.
//!
//! The emitted module holds the model: F_d ([`Backstepping::desired_force`],
//! [SB Theorem 1]) and the law u ([`Backstepping::law`], [SB 19]), and the
//! numbers ([`BacksteppingSettings`]): α₁, P and the level C of the certified
//! region D = {V ≤ C} per target, V = ZᵀPZ, Z = (z − y_r, v + α₁·(z − y_r))
//! [SB 9], [SB 21]. Per sample:
//!
//! - the reference y_r: a constant position, or a square wave (`low` for the
//!   first half of each period, then `high`); each change of y_r starts the
//!   switching afresh (a new initial condition of [SB Theorems 4–5]);
//! - the mode ([`Mode`], the token M of [SB 31–33]):
//!   - `None`: the law everywhere [SB 19];
//!   - `Intuitive` [SB 28]: u = 0 until V ≤ C, then the law (one switch at
//!     most, Remark 4);
//!   - `Hybrid` [SB 31–33]: inside D the law; outside D the law while
//!     F_d > 0, and from F_d ≤ 0 on u = 0 until V ≤ C (two switches at most,
//!     Remark 6);
//!   once in D the law stays (D is invariant under it);
//! - where φ ≤ `phi_guard` (g_F ∝ φ vanishes at φ = 0) the law is not
//!   evaluated and u = u_max builds the flux;
//! - every output is saturated to [u_min, u_max] (NaN → the bound nearest 0).
//!
//! No allocation, no panic path, no `as`.

use core::marker::PhantomData;

use crate::control::ConstPlan;
use crate::linalg::Scalar;

/// What happens where F_d < 0 (the magnet cannot push).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switching {
    None,
    Intuitive,
    Hybrid,
}

/// One constant reference and the level C of its region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target<T> {
    /// y_r [m].
    pub position: T,
    /// C of D = {ZᵀPZ ≤ C} [SB lemma 1].
    pub level: T,
}

/// The reference y_r.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SetPoint<T> {
    Position(Target<T>),
    /// `low` for the first half of each `period` [s], then `high`.
    Square {
        low: Target<T>,
        high: Target<T>,
        period: T,
    },
}

/// The design values (the consts of the emitted module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BacksteppingSettings<T> {
    /// Supply limits: every output lies in [u_min, u_max].
    pub u_min: T,
    pub u_max: T,
    /// [Wb]: where φ ≤ `phi_guard` the law is not evaluated and u = u_max.
    pub phi_guard: T,
    /// α₁ of z₂ = v + α₁·z₁ [SB 9].
    pub alpha1: T,
    /// P of V = ZᵀPZ as [p₁₁, p₁₂, p₂₂] [SB 21].
    pub p: [T; 3],
    pub switching: Switching,
    pub reference: SetPoint<T>,
}

/// A backstepping module: its settings, F_d and the law.
pub trait Backstepping<T> {
    fn settings(&self) -> BacksteppingSettings<T>;
    /// F_d [N] at (z, v) for y_r [SB Theorem 1].
    fn desired_force(&self, z: T, v: T, y_r: T) -> T;
    /// u [SB 19] at x = [z, v, φ, H_c] for y_r: not guarded, not saturated.
    fn law(&self, x: [T; 4], y_r: T) -> T;
}

/// The switching state: the token M of [SB 31–33] and where the state was
/// first seen. Numbered (`mode as u8`) as recordings give it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Mode {
    /// No sample since the reference last changed.
    Start = 0,
    /// Outside D with F_d > 0 (hybrid, M = 1): the law.
    Approaching = 1,
    /// Outside D, u = 0: the spring carries the state towards X₀ ∈ D.
    Waiting = 2,
    /// In D (once): the law.
    Inside = 3,
}

/// `u` clamped to [u_min, u_max] (NaN → the bound nearest 0).
#[inline]
fn saturate<T: Scalar>(u: T, s: &BacksteppingSettings<T>) -> T {
    crate::control::saturate_to(u, s.u_min, s.u_max)
}

/// V(Z) = ZᵀPZ at (z, v) for y_r [SB 21].
#[inline]
pub fn lyapunov<T: Scalar>(s: &BacksteppingSettings<T>, z: T, v: T, y_r: T) -> T {
    let z1 = z - y_r;
    let z2 = v + s.alpha1 * z1;
    let [p11, p12, p22] = s.p;
    p11 * z1 * z1 + (p12 + p12) * z1 * z2 + p22 * z2 * z2
}

/// The next mode from `mode` (module docs); `inside`: V ≤ C.
#[inline]
pub fn next_mode<T: Scalar>(switching: Switching, mode: Mode, inside: bool, desired: T) -> Mode {
    if mode == Mode::Inside || inside {
        return Mode::Inside;
    }
    match (switching, mode) {
        (Switching::None, _) => Mode::Approaching,
        (Switching::Intuitive, _) | (Switching::Hybrid, Mode::Waiting) => Mode::Waiting,
        // hybrid: the law while F_d > 0, then u = 0 until D (NaN: wait)
        (Switching::Hybrid, _) if desired > T::ZERO => Mode::Approaching,
        (Switching::Hybrid, _) => Mode::Waiting,
    }
}

/// The armature positioned at the design's reference. Allocation- and
/// panic-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwitchedBackstepping<B, T> {
    plan: B,
    mode: Mode,
    /// Square reference: at `high`, the next change at `next_change` [s].
    high: bool,
    next_change: T,
    float: PhantomData<T>,
}

impl<B: Backstepping<T> + ConstPlan, T: Scalar> SwitchedBackstepping<B, T> {
    /// The controller of the emitted module's plan, started at t = 0.
    #[must_use]
    pub fn new() -> Self {
        Self::with(B::PLAN)
    }
}

impl<B: Backstepping<T> + ConstPlan, T: Scalar> Default for SwitchedBackstepping<B, T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<B: Backstepping<T>, T: Scalar> SwitchedBackstepping<B, T> {
    /// The controller of `plan`, started at t = 0.
    #[must_use]
    pub fn with(plan: B) -> Self {
        let mut controller = SwitchedBackstepping {
            plan,
            mode: Mode::Start,
            high: false,
            next_change: T::ZERO,
            float: PhantomData,
        };
        controller.start(T::ZERO);
        controller
    }

    /// Starts at `t_start` [s]: the square reference's first half period
    /// begins, and the switching starts afresh.
    pub fn start(&mut self, t_start: T) {
        self.mode = Mode::Start;
        self.high = false;
        self.next_change = t_start + self.half_period();
    }

    fn half_period(&self) -> T {
        match self.plan.settings().reference {
            SetPoint::Position(_) => T::ZERO,
            SetPoint::Square { period, .. } => period / (T::ONE + T::ONE),
        }
    }

    /// The plan the controller runs (its settings, F_d and law).
    #[must_use]
    pub const fn plan(&self) -> &B {
        &self.plan
    }

    /// The switching state.
    #[must_use]
    pub const fn mode(&self) -> Mode {
        self.mode
    }

    /// The target at `t` (y_r and C). It advances the square reference: a
    /// change of y_r restarts the switching, as [`SwitchedBackstepping::step`]
    /// (which calls it) does; call it with the times `step` sees.
    pub fn target(&mut self, t: T) -> Target<T> {
        match self.plan.settings().reference {
            SetPoint::Position(target) => target,
            SetPoint::Square { low, high, .. } => {
                let half = self.half_period();
                // one change per call at most: a sample period is far below
                // half a period (checked by the description)
                if t >= self.next_change && half > T::ZERO {
                    self.high = !self.high;
                    self.next_change = self.next_change + half;
                    self.mode = Mode::Start;
                }
                if self.high {
                    high
                } else {
                    low
                }
            }
        }
    }

    /// The input u in [u_min, u_max] at `t` [s] for the state [z, v, φ, H_c]
    /// (H_c = 0 where the core has none): the rules in the module docs.
    /// Finite for any input.
    pub fn step(&mut self, t: T, z: T, v: T, phi: T, hc: T) -> T {
        let s = self.plan.settings();
        let target = self.target(t);
        let y_r = target.position;
        // [SB lemma 1] Z ∈ D
        let inside = lyapunov(&s, z, v, y_r) <= target.level;
        let desired = self.plan.desired_force(z, v, y_r);
        self.mode = next_mode(s.switching, self.mode, inside, desired);
        if self.mode == Mode::Waiting {
            // [SB 28] u = 0 outside D
            return saturate(T::ZERO, &s);
        }
        if phi <= s.phi_guard {
            return saturate(s.u_max, &s);
        }
        // [SB 19]
        saturate(self.plan.law([z, v, phi, hc], y_r), &s)
    }
}
