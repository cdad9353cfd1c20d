//! The model-free sliding-mode soft-landing law
//! (model-free-sliding-mode-soft-landing [SM §3]), written once for every
//! design and both floats.
//!
//! The emitted module holds only numbers: the plan (timing, limits, the
//! reference tables, [`Plan`]) and the surface's λ₁, λ₂ ([`Surface::surface`]).
//! Per sample, from the measured (or estimated) z, v, a and φ's sign:
//!
//! - [SM 43] at the end stop z_f (within `landed_band`, whenever the armature
//!   is there, also before t_f: a premature landing is held, not undone):
//!   closing → u = u_max·sgn φ, opening → u = 0; once the rule has held the
//!   armature after t_f it holds it for the rest of the operation, wherever a
//!   later position says it is (a sensorless estimate flickers in and out of
//!   the band at its clamp, and each flicker would hand the held armature
//!   back to the law for a sample at ±u_max);
//! - otherwise [SM 17] s = ã + (λ₁ + λ₂)·ṽ + λ₁λ₂·z̃ against the reference of
//!   [`Tracker::reference`] (z₀ at rest before t₀, the table, z_f after t_f),
//!   and [SM 34] u = u_max·sgn(φ)·sgn*(s) with [SM 35] sgn*(0) = −1 at
//!   z_min (mode q = 1), +1 elsewhere;
//! - with `nonnegative_current` [SM §5] the step reads the coil current: φ ≥ 0
//!   is taken (sgn φ = +1) and the current is never driven below 0 (u = 0
//!   where i ≤ 0 and the law asks for u < 0);
//! - every output is saturated to [u_min, u_max]; a NaN z, v, a or φ gives
//!   u = 0 away from the end stops (at a stop the expert rule needs only z and
//!   φ); a NaN time counts as the pre-movement stage, as in `control`.
//!
//! No model function is evaluated: the law is two comparisons and a
//! multiplication, with the reference lookup.

use crate::control::{
    arrived, expert_rule, finish_stroke, flux_sign, saturate, ConstPlan, Plan, Tracker,
};
use crate::linalg::Scalar;

/// The surface's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSettings<T> {
    /// λ₁ [1/s] of [SM 17].
    pub lambda1: T,
    /// λ₂ [1/s].
    pub lambda2: T,
    /// The step reads the coil current and keeps it ≥ 0 [SM §5].
    pub nonnegative_current: bool,
}

/// A sliding-mode module: its plan and its surface.
pub trait Surface<T>: Plan<T> {
    fn surface(&self) -> SurfaceSettings<T>;
}

/// [SM 17] s = ã + (λ₁ + λ₂)·ṽ + λ₁λ₂·z̃ of the state [z, v, a] against the
/// reference [z_r, v_r, a_r].
#[inline]
pub fn surface<T: Scalar>(settings: &SurfaceSettings<T>, x: [T; 3], reference: [T; 3]) -> T {
    let [z, v, a] = x;
    let [zr, vr, ar] = reference;
    let (l1, l2) = (settings.lambda1, settings.lambda2);
    (a - ar) + (l1 + l2) * (v - vr) + l1 * l2 * (z - zr)
}

/// [SM 35] sgn*(s): the sign of s; at s = 0, −1 in mode q = 1 (at z_min)
/// and +1 otherwise. `None` for a NaN s.
#[inline]
pub fn switching_sign<T: Scalar>(s: T, at_z_min: bool) -> Option<T> {
    if s < T::ZERO {
        Some(-T::ONE)
    } else if s > T::ZERO {
        Some(T::ONE)
    } else if s == T::ZERO {
        Some(if at_z_min { -T::ONE } else { T::ONE })
    } else {
        None
    }
}

/// One operation of the actuator under the sliding-mode law of `S`.
/// Allocation- and panic-free.
#[derive(Clone, Debug, PartialEq)]
pub struct SlidingMode<S: Surface<T>, T> {
    plan: S,
    tracker: Tracker<S::Operation, T>,
    /// Once [`finish_stroke`] drives this operation: whether at its first
    /// sample the armature was neither at its stop (the expert rule's band)
    /// nor read within the arrival band.
    late: Option<bool>,
    /// The expert rule has held the armature at its stop after t_f: it holds
    /// it for the rest of the operation.
    held: bool,
}

impl<S: Surface<T> + ConstPlan, T: Scalar + From<u8>> SlidingMode<S, T> {
    /// A controller for `operation` of the emitted module's plan, started at t = 0.
    #[must_use]
    pub const fn new(operation: S::Operation) -> Self {
        Self::with(S::PLAN, operation)
    }
}

impl<S: Surface<T>, T: Scalar + From<u8>> SlidingMode<S, T> {
    /// A controller for `operation` of `plan`, started at t = 0.
    #[must_use]
    pub const fn with(plan: S, operation: S::Operation) -> Self {
        SlidingMode {
            plan,
            tracker: Tracker::new(operation),
            late: None,
            held: false,
        }
    }

    /// Starts the operation at `t_start` [s]: reference times count from here.
    pub fn start(&mut self, t_start: T) {
        self.tracker.start(t_start);
        self.late = None;
        self.held = false;
    }

    /// Whether, when [`finish_stroke`] took over at t_f + `arrival_margin`,
    /// the armature was neither at its stop nor read within `arrival_band`
    /// of it: a landing later than planned. Decided once, at the push's
    /// first sample.
    #[must_use]
    pub const fn finished_late(&self) -> bool {
        matches!(self.late, Some(true))
    }

    /// The operation this controller runs.
    #[must_use]
    pub const fn operation(&self) -> S::Operation {
        self.tracker.operation()
    }

    /// [z_r, v_r, a_r, j_r] at `t` ([`Tracker::reference`]).
    pub fn reference(&mut self, t: T) -> [T; 4] {
        self.tracker.reference(&self.plan, t)
    }

    /// The input u in [u_min, u_max] at time `t` [s] for the measured (or
    /// estimated) position `z`, velocity `v`, acceleration `a` and `phi`: the
    /// flux (only its sign is read), or the coil current where the surface
    /// keeps it non-negative. Finite for any input.
    pub fn step(&mut self, t: T, z: T, v: T, a: T, phi: T) -> T {
        let settings = self.plan.settings();
        let surface_settings = self.plan.surface();
        let motion = self.plan.motion(self.tracker.operation());
        let flux = if surface_settings.nonnegative_current {
            // the current, kept ≥ 0, stands for φ ≥ 0: its NaN still stops the drive
            if phi.partial_cmp(&phi).is_some() {
                T::ONE
            } else {
                T::ZERO
            }
        } else {
            flux_sign(phi)
        };
        let time = self.tracker.elapsed(t);
        let at_stop = if self.held { motion.zf } else { z };
        let landed = expert_rule(&motion, &settings, at_stop, flux);
        self.held = landed.is_some() && time > settings.landing;
        if let Some(u) = finish_stroke(&motion, &settings, time, phi) {
            (self.late).get_or_insert_with(|| landed.is_none() && !arrived(&motion, &settings, z));
            return u;
        }
        // [SM 43]
        if let Some(u) = landed {
            return u;
        }
        let [zr, vr, ar, _] = self.tracker.reference(&self.plan, t);
        // [SM 17]
        let s = surface(&surface_settings, [z, v, a], [zr, vr, ar]);
        let z_min = if motion.z0 < motion.zf {
            motion.z0
        } else {
            motion.zf
        };
        // [SM 35]
        let Some(sign) = switching_sign(s, z <= z_min + settings.landed_band) else {
            return saturate(T::ZERO, &settings);
        };
        // [SM 34]
        let u = settings.u_max * flux * sign;
        let u = if surface_settings.nonnegative_current && u < T::ZERO && phi <= T::ZERO {
            T::ZERO
        } else {
            u
        };
        saturate(u, &settings)
    }
}
