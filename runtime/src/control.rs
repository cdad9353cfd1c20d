//! The soft-landing controller's operation logic, written once for every
//! design and both floats (perfect-tracking-soft-landing [PT §3.2] and [PT §4]).
//!
//! Generated code holds the model: the tracking law [PT 50] ([`Law::law`]), the
//! design values ([`Settings`]) and one reference table per operation
//! ([`Motion`]). [`SoftLanding`] runs one operation over them:
//!
//! - before t₀ (pre-movement stage, [PT §4]): ξ_r = [z₀, 0, 0], j_r = 0, so the law
//!   brings ξ₃ = a(x) to 0, i.e. the forces into balance at takeoff;
//! - on [t₀, t_f]: ξ_r, j_r from the table ([`eval_segment`]), the segment
//!   cursor advanced monotonically (lookup with `.get()`);
//! - after t_f: ξ_r = [z_f + (z_f − z₀)·(press + creep·(t − t_f)), (z_f − z₀)·creep, 0],
//!   a reference just beyond the end stop that keeps creeping beyond it up to
//!   `creep_max`, so the loop closes whatever gap the tracking error left and
//!   still lands where the plant differs from the model; once the armature is
//!   at its end stop (within `landed_band`: contact, not proximity) the expert
//!   rules of model-free-sliding-mode-soft-landing [SM 43] apply: closing →
//!   u = u_max·sgn φ (holds it closed; sgn 0 taken as +1, a NaN φ gives 0),
//!   opening → u = 0; they hold for the rest of the operation (an estimate
//!   flickering in and out of the band at its clamp would otherwise hand the
//!   held armature back to the law, sample by sample, at ±u_max);
//! - no hover: after t_f + `arrival_margin` an armature not yet at its end
//!   stop is driven there ([`finish_stroke`]), and the operation is flagged
//!   late ([`SoftLanding::finished_late`]) where it was then neither held nor
//!   read within `arrival_band` of its stop;
//! - guard at φ → 0: where φ ≤ `phi_guard` the law is not evaluated and
//!   u = u_max drives the flux into D₀⁺ = {φ > 0} ([`guarded_law`]);
//! - every output is saturated to [u_min, u_max] (NaN → the bound nearest 0,
//!   ±∞ → the bounds), so any input gives a finite u.
//!
//! No allocation, no panic path, no `as`; generic over the float ([`Scalar`]
//! plus `From<u8>` for the polynomial's small integer divisors).

use core::fmt::Debug;

use crate::linalg::Scalar;

/// One segment of a reference table: [t_k, z_k, v_k, c0, c1, c2, c3], t_k
/// from the operation's start; a(τ) = c0 + c1·τ + c2·τ² + c3·τ³ with
/// τ = t − t_k, v and z its integrals from v_k and z_k.
pub type Row<T> = [T; 7];

/// Which end stop an operation lands on, which decides its hold rule [SM 43].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Landing {
    /// Closing, z_max → z_min: at the stop u = u_max·sgn φ holds it closed.
    Closing,
    /// Opening, z_min → z_max: at the stop u = 0 lets the spring hold it open.
    Opening,
}

/// One designed operation [PT 51]: the reference on [t₀, t_f] and its rest positions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion<'a, T> {
    pub landing: Landing,
    /// z₀: the rest position before t₀.
    pub z0: T,
    /// z_f: the end stop held after t_f.
    pub zf: T,
    /// One [`Row`] per segment, in time order.
    pub table: &'a [Row<T>],
}

/// The design values the operation logic reads (the consts of the emitted module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings<T> {
    /// Supply limits: every output lies in [u_min, u_max].
    pub u_min: T,
    pub u_max: T,
    /// t₀ [s] from the operation's start: end of the pre-movement stage.
    pub takeoff: T,
    /// t_f [s] from the operation's start: end of the motion.
    pub landing: T,
    /// [Wb]: where φ ≤ `phi_guard` the law is not evaluated and u = u_max.
    pub phi_guard: T,
    /// [m]: within this distance of its end stop the armature is in contact.
    pub landed_band: T,
    /// After t_f the reference lies `press`·stroke beyond the end stop …
    pub press: T,
    /// … and creeps on at `creep`·stroke per second [1/s] …
    pub creep: T,
    /// … up to `creep_max`·stroke beyond it.
    pub creep_max: T,
    /// [s] after t_f: an armature not at its end stop by t_f +
    /// `arrival_margin` is driven there ([`finish_stroke`]): no operation
    /// hovers, whatever the model error.
    pub arrival_margin: T,
    /// [m]: an armature read farther than this from its end stop at t_f +
    /// `arrival_margin`, and not held there by then, landed late
    /// ([`arrived`]). At least `landed_band`: a sensorless estimate creeps
    /// onto its clamp and need not reach the contact band to have arrived.
    pub arrival_band: T,
}

/// What every controller module provides: its operations, design values and
/// reference tables. The emitted modules implement it on a unit struct (and
/// [`ConstPlan`], so that their controllers have a `const fn new`); the
/// designer on its run-time design, so that `reldesign loop` runs this very
/// code.
pub trait Plan<T> {
    /// The designed operations (an enum of the emitted module).
    type Operation: Copy + Debug + PartialEq;
    fn settings(&self) -> Settings<T>;
    /// The reference and rest positions of `operation`.
    fn motion(&self, operation: Self::Operation) -> Motion<'_, T>;
}

/// A plan that exists at compile time (an emitted unit struct).
pub trait ConstPlan: Sized {
    const PLAN: Self;
}

/// A feedback-linearizing module: its plan and the tracking law [PT 50].
pub trait Law<T>: Plan<T> {
    /// u of the tracking law [PT 50] at the state x = [z, v, φ, H_c] and the
    /// reference [z_r, v_r, a_r, j_r]: not guarded, not saturated. H_c, the
    /// core's field, is read only by a design on a Jiles–Atherton core
    /// (jiles-atherton-actuator-model [JA 89]: it enters L_f³z through dφ/dt).
    fn law(&self, x: [T; 4], reference: [T; 4]) -> T;
}

/// [z_r, v_r, a_r, j_r] of one table row at τ = t − t_k (the integrals of
/// the cubic acceleration, `designer::design::Segments`).
#[inline]
pub fn eval_segment<T: Scalar + From<u8>>(row: &Row<T>, tau: T) -> [T; 4] {
    let [_, z, v, c0, c1, c2, c3] = *row;
    let n = |k: u8| T::from(k);
    [
        z + tau
            * (v + tau * (c0 / n(2) + tau * (c1 / n(6) + tau * (c2 / n(12) + tau * c3 / n(20))))),
        v + tau * (c0 + tau * (c1 / n(2) + tau * (c2 / n(3) + tau * c3 / n(4)))),
        c0 + tau * (c1 + tau * (c2 + tau * c3)),
        c1 + tau * (n(2) * c2 + tau * n(3) * c3),
    ]
}

/// `u` clamped to [u_min, u_max]; a NaN gives the bound nearest 0 (so a
/// numerical failure never commands full voltage), ±∞ the bounds (as
/// [`crate::saturate`]).
#[inline]
pub fn saturate<T: Scalar>(u: T, settings: &Settings<T>) -> T {
    saturate_to(u, settings.u_min, settings.u_max)
}

/// `u` clamped to [lo, hi] (lo ≤ hi); a NaN gives the bound nearest 0, ±∞
/// the bounds: [`saturate`] for any pair of limits.
#[inline]
pub fn saturate_to<T: Scalar>(u: T, lo: T, hi: T) -> T {
    // NaN is the one value unordered with itself
    let u = if u.partial_cmp(&u).is_none() {
        T::ZERO
    } else {
        u
    };
    let u = if u > lo { u } else { lo };
    if u < hi {
        u
    } else {
        hi
    }
}

/// sgn φ as the expert rules and the sliding mode read it: −1 below 0, +1 at
/// or above it (sgn 0 = +1), 0 for NaN (no input).
#[inline]
pub fn flux_sign<T: Scalar>(phi: T) -> T {
    if phi < T::ZERO {
        -T::ONE
    } else if phi >= T::ZERO {
        T::ONE
    } else {
        T::ZERO
    }
}

/// The expert rule [SM 43] at the end stop z_f (within `landed_band`):
/// closing → u = u_max·sgn φ holds it closed, opening → u = 0 lets the
/// spring hold it open; `None` away from z_f. Saturated.
#[inline]
pub fn expert_rule<T: Scalar>(
    motion: &Motion<T>,
    settings: &Settings<T>,
    z: T,
    phi: T,
) -> Option<T> {
    match motion.landing {
        Landing::Closing if z <= motion.zf + settings.landed_band => {
            Some(saturate(settings.u_max * flux_sign(phi), settings))
        }
        Landing::Opening if z >= motion.zf - settings.landed_band => {
            Some(saturate(T::ZERO, settings))
        }
        _ => None,
    }
}

/// Whether the position read `z` is within `arrival_band` (and never less
/// than `landed_band`) of the end stop: at t_f + `arrival_margin` it had
/// arrived in time (a NaN has not).
#[inline]
pub fn arrived<T: Scalar>(motion: &Motion<T>, settings: &Settings<T>, z: T) -> bool {
    let band = if settings.arrival_band > settings.landed_band {
        settings.arrival_band
    } else {
        settings.landed_band
    };
    match motion.landing {
        Landing::Closing => z <= motion.zf + band,
        Landing::Opening => z >= motion.zf - band,
    }
}

/// No hover, ever: after t_f + `arrival_margin` the armature is driven to
/// its end stop, wherever its (estimated) position says it is — closing:
/// u = u_max·sgn φ pulls it in (at the stop, the expert rule [SM 43]);
/// opening: u = u_min while φ > `phi_guard` drains the flux, then u = 0 lets
/// the spring open it (at the stop, the rule's 0 V a little sooner). A
/// sensorless estimate that has lost the armature cannot hold it short of
/// its stop. `None` before. Saturated.
#[inline]
pub fn finish_stroke<T: Scalar>(
    motion: &Motion<T>,
    settings: &Settings<T>,
    time: T,
    phi: T,
) -> Option<T> {
    if !(time > settings.landing + settings.arrival_margin) {
        return None;
    }
    let u = match motion.landing {
        Landing::Closing => settings.u_max * flux_sign(phi),
        Landing::Opening if phi > settings.phi_guard => settings.u_min,
        Landing::Opening => T::ZERO,
    };
    Some(saturate(u, settings))
}

/// The law [PT 50] as applied: where φ ≤ `phi_guard` (φ → 0, where β = 1/L_g L_f²h
/// blows up and D₀⁺ is left) it is not evaluated and u = u_max drives the flux
/// back into D₀⁺; otherwise [`Law::law`]. Saturated.
#[inline]
pub fn guarded_law<L: Law<T>, T: Scalar>(law: &L, x: [T; 4], reference: [T; 4]) -> T {
    let settings = law.settings();
    let [_, _, phi, _] = x;
    if phi <= settings.phi_guard {
        return saturate(settings.u_max, &settings);
    }
    saturate(law.law(x, reference), &settings)
}

/// Where an operation stands: which, its start time and the table segment it
/// is in. [`Tracker::reference`] is the reference every law of a [`Plan`]
/// tracks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tracker<O, T> {
    operation: O,
    /// Time at which the operation started [s].
    start: T,
    /// Current segment of the table (only moves forward).
    cursor: usize,
}

impl<O: Copy, T: Scalar + From<u8>> Tracker<O, T> {
    /// A tracker of `operation`, started at t = 0.
    #[must_use]
    pub const fn new(operation: O) -> Self {
        Tracker {
            operation,
            start: T::ZERO,
            cursor: 0,
        }
    }

    /// Starts the operation at `t_start` [s]: reference times count from here.
    pub fn start(&mut self, t_start: T) {
        self.start = t_start;
        self.cursor = 0;
    }

    /// The operation tracked.
    #[must_use]
    pub const fn operation(&self) -> O {
        self.operation
    }

    /// Time since the operation's start [s].
    #[must_use]
    pub fn elapsed(&self, t: T) -> T {
        t - self.start
    }

    /// [z_r, v_r, a_r, j_r] at `t` [PT 51]: z₀ at rest before t₀, the table on
    /// [t₀, t_f], after t_f just beyond z_f and creeping on (press, creep).
    /// Advances the segment cursor.
    pub fn reference<P: Plan<T, Operation = O>>(&mut self, plan: &P, t: T) -> [T; 4] {
        let settings = plan.settings();
        let motion = plan.motion(self.operation);
        let time = t - self.start;
        let rest = [motion.z0, T::ZERO, T::ZERO, T::ZERO];
        if (settings.takeoff..=settings.landing).contains(&time) {
            while let Some(&[t_next, ..]) = motion.table.get(self.cursor.saturating_add(1)) {
                if t_next <= time {
                    self.cursor = self.cursor.saturating_add(1);
                } else {
                    break;
                }
            }
            match motion.table.get(self.cursor) {
                Some(row) => {
                    let [t_k, ..] = *row;
                    eval_segment(row, time - t_k)
                }
                None => rest,
            }
        } else if time > settings.landing {
            let stroke = motion.zf - motion.z0;
            let creep = settings.creep * (time - settings.landing);
            if creep < settings.creep_max {
                let z = motion.zf + stroke * (settings.press + creep);
                [z, stroke * settings.creep, T::ZERO, T::ZERO]
            } else {
                let z = motion.zf + stroke * (settings.press + settings.creep_max);
                [z, T::ZERO, T::ZERO, T::ZERO]
            }
        } else {
            // before t₀ (and a NaN time): the pre-movement stage
            rest
        }
    }
}

/// One operation of the actuator under the law `L` (the rules in the module
/// docs): pre-movement before t₀, tracking of the table on [t₀, t_f], hold at
/// z_f after t_f. Allocation- and panic-free.
#[derive(Clone, Debug, PartialEq)]
pub struct SoftLanding<L: Law<T>, T> {
    law: L,
    tracker: Tracker<L::Operation, T>,
    /// Once [`finish_stroke`] drives this operation: whether at its first
    /// sample the armature was neither held nor read within the arrival band.
    late: Option<bool>,
    /// The expert rule has held the armature at its stop after t_f: it
    /// holds it for the rest of the operation.
    held: bool,
}

impl<L: Law<T> + ConstPlan, T: Scalar + From<u8>> SoftLanding<L, T> {
    /// A controller for `operation` of the emitted module's plan, started at t = 0.
    #[must_use]
    pub const fn new(operation: L::Operation) -> Self {
        Self::with(L::PLAN, operation)
    }
}

impl<L: Law<T>, T: Scalar + From<u8>> SoftLanding<L, T> {
    /// A controller for `operation` of `law`, started at t = 0.
    #[must_use]
    pub const fn with(law: L, operation: L::Operation) -> Self {
        SoftLanding {
            law,
            tracker: Tracker::new(operation),
            late: None,
            held: false,
        }
    }

    /// The law, e.g. to hand a self-calibrating design its adapted
    /// parameters between operations.
    pub fn law_mut(&mut self) -> &mut L {
        &mut self.law
    }

    /// Starts the operation at `t_start` [s]: reference times count from here.
    pub fn start(&mut self, t_start: T) {
        self.tracker.start(t_start);
        self.late = None;
        self.held = false;
    }

    /// Whether, when [`finish_stroke`] took over at t_f + `arrival_margin`,
    /// the armature was neither held at its stop nor read within
    /// `arrival_band` of it: a landing later than planned, for the firmware
    /// to report (and its calibration to learn from). Decided once, at the
    /// push's first sample.
    #[must_use]
    pub const fn finished_late(&self) -> bool {
        matches!(self.late, Some(true))
    }

    /// The operation this controller runs.
    #[must_use]
    pub const fn operation(&self) -> L::Operation {
        self.tracker.operation()
    }

    /// [z_r, v_r, a_r, j_r] at `t` ([`Tracker::reference`]).
    pub fn reference(&mut self, t: T) -> [T; 4] {
        self.tracker.reference(&self.law, t)
    }

    /// After t_f at the end stop: the expert rule [SM 43] ([`expert_rule`]),
    /// and from then on for the rest of the operation, wherever the position
    /// read later says the armature is; `None` before.
    fn hold(&mut self, time: T, z: T, phi: T) -> Option<T> {
        let settings = self.law.settings();
        if !(time > settings.landing) {
            return None;
        }
        let motion = self.law.motion(self.tracker.operation());
        let at_stop = if self.held { motion.zf } else { z };
        let u = expert_rule(&motion, &settings, at_stop, phi);
        self.held = u.is_some();
        u
    }

    /// The input u in [u_min, u_max] at time `t` [s] for the measured state
    /// x = [z, v, φ]: the hold rule at the end stop, else [`guarded_law`] at
    /// the reference of [`SoftLanding::reference`]. Finite for any input.
    /// For a design on a Jiles–Atherton core use [`SoftLanding::step_with_field`].
    pub fn step(&mut self, t: T, z: T, v: T, phi: T) -> T {
        self.step_with_field(t, z, v, phi, T::ZERO)
    }

    /// [`SoftLanding::step`] with the core's field H_c [A/m] (estimated by the
    /// observer), which the law of a design on a Jiles–Atherton core reads.
    pub fn step_with_field(&mut self, t: T, z: T, v: T, phi: T, hc: T) -> T {
        let time = self.tracker.elapsed(t);
        let motion = self.law.motion(self.tracker.operation());
        let settings = self.law.settings();
        // the push comes first: at the stop it is the expert rule (closing)
        // or drains the flux the rule would leave to decay (opening), and it
        // does not trust a position estimate that may have lost the armature
        if let Some(u) = finish_stroke(&motion, &settings, time, phi) {
            let held = self.held;
            (self.late).get_or_insert_with(|| !held && !arrived(&motion, &settings, z));
            return u;
        }
        if let Some(u) = self.hold(time, z, phi) {
            return u;
        }
        let reference = self.reference(t);
        guarded_law(&self.law, [z, v, phi, hc], reference)
    }
}

impl<L: Law<T>, T: Scalar + From<u8>> crate::Controller<T> for SoftLanding<L, T> {
    fn step(&mut self, t: T, y: &crate::Measurement<T>) -> T {
        SoftLanding::step(self, t, y.z, y.v, y.phi)
    }
}
