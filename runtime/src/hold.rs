//! Position hold by the model-based sliding mode of
//! jiles-atherton-actuator-model [JA §6.2], written once for every design and
//! both floats.
//!
//! The emitted module holds the model (the law's functions) and the numbers
//! ([`HoldSettings`]). Per sample, from the observed ẑ, v̂, φ̂, Ĥ_c:
//!
//! - [JA 86] the mode from ẑ: q = 1 within `landed_band` of z_min, q = 3
//!   within it of z_max, q = 2 between;
//! - [JA 94] at a stop: q = 1 → u_max if the reference is z_min, else 0;
//!   q = 3 → 0 if the reference is z_max, else u_max;
//! - in motion (q = 2): [JA 89] u₂ on the surface [JA 88]
//!   s = (â − a_r) + 2p·(v̂ − v_r) + p²·(ẑ − z_r), which is the tracking law
//!   u = α + β·(K·(ξ_r − T(x̂)) + j_r) of perfect-tracking-soft-landing
//!   [PT 50] with K = [K·p², p² + 2p·K, 2p + K] (the error dynamics
//!   (d/dt + p)²(d/dt + K)): the emitted [`Hold::law`] is that law;
//! - where φ̂ ≤ `phi_guard` (φ → 0, where β = 1/L_g L_f²z blows up) the law
//!   is not evaluated and u = u_max builds the flux;
//! - [JA 94] every output is saturated to [0, u_max]; a NaN gives 0.
//!
//! No allocation, no panic path, no `as`.

use core::marker::PhantomData;

use crate::control::ConstPlan;
use crate::linalg::Scalar;

/// The design values of a position hold (the consts of the emitted module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoldSettings<T> {
    /// z_ref [m]: the constant reference [JA 88].
    pub position: T,
    /// The stroke's stops [m].
    pub z_min: T,
    pub z_max: T,
    /// The supply's upper limit [V or A]: u ∈ [0, u_max] [JA 94].
    pub u_max: T,
    /// [Wb]: where φ̂ ≤ `phi_guard` the law is not evaluated and u = u_max.
    pub phi_guard: T,
    /// [m]: within this distance of a stop the armature is at it [JA 86].
    pub landed_band: T,
}

/// A position-hold module: its settings and the law [JA 89].
pub trait Hold<T> {
    fn settings(&self) -> HoldSettings<T>;
    /// u₂ of [JA 89] at x = [z, v, φ, H_c] for the reference [z_r, v_r, a_r,
    /// j_r]: not guarded, not saturated.
    fn law(&self, x: [T; 4], reference: [T; 4]) -> T;
}

/// `u` clamped to [0, u_max] [JA 94]; NaN → 0, ±∞ → the bounds.
#[inline]
pub fn saturate_nonnegative<T: Scalar>(u: T, u_max: T) -> T {
    // NaN is the one value unordered with itself
    if u.partial_cmp(&u).is_none() || u <= T::ZERO {
        T::ZERO
    } else if u < u_max {
        u
    } else {
        u_max
    }
}

/// [JA 94] the input at a stop: `None` in motion (q = 2).
#[inline]
pub fn stop_rule<T: Scalar>(settings: &HoldSettings<T>, z: T) -> Option<T> {
    let s = settings;
    let at_min = |x: T| x <= s.z_min + s.landed_band;
    let at_max = |x: T| x >= s.z_max - s.landed_band;
    if at_min(z) {
        Some(if at_min(s.position) { s.u_max } else { T::ZERO })
    } else if at_max(z) {
        Some(if at_max(s.position) { T::ZERO } else { s.u_max })
    } else {
        None
    }
}

/// The armature held at the design's position. Allocation- and panic-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionHold<H, T> {
    plan: H,
    float: PhantomData<T>,
}

impl<H: Hold<T> + ConstPlan, T: Scalar> PositionHold<H, T> {
    /// The hold of the emitted module's plan.
    #[must_use]
    pub const fn new() -> Self {
        Self::with(H::PLAN)
    }
}

impl<H: Hold<T> + ConstPlan, T: Scalar> Default for PositionHold<H, T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<H: Hold<T>, T: Scalar> PositionHold<H, T> {
    /// The hold of `plan`.
    #[must_use]
    pub const fn with(plan: H) -> Self {
        PositionHold {
            plan,
            float: PhantomData,
        }
    }

    /// [z_ref, 0, 0, 0]: the constant reference.
    #[must_use]
    pub fn reference(&self) -> [T; 4] {
        [self.plan.settings().position, T::ZERO, T::ZERO, T::ZERO]
    }

    /// The input u in [0, u_max] for the observed state [ẑ, v̂, φ̂, Ĥ_c] (the
    /// rules in the module docs). Finite for any input.
    pub fn step(&self, z: T, v: T, phi: T, hc: T) -> T {
        let settings = self.plan.settings();
        // [JA 86], [JA 94]
        if let Some(u) = stop_rule(&settings, z) {
            return saturate_nonnegative(u, settings.u_max);
        }
        if phi <= settings.phi_guard {
            return saturate_nonnegative(settings.u_max, settings.u_max);
        }
        // [JA 89]
        let u = self.plan.law([z, v, phi, hc], self.reference());
        saturate_nonnegative(u, settings.u_max)
    }
}
