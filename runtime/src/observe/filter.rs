//! What the EKF and the UKF share: the posterior (x, P) with its
//! bookkeeping, and the steps around the two filters' own algebra — the held
//! input, the stop rule of the prediction, the restart after a non-finite
//! prediction, the correction, and the estimate [JA 85–87] of the projected
//! posterior.

use crate::linalg::{self, Matrix, Scalar};

use super::model::{DiscreteModel, Settings};

/// The estimate at one sample: what the controllers consume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate<T> {
    /// z [m], in [z_min, z_max].
    pub z: T,
    /// v [m/s] = (z − z_prev)/T_s [JA 85].
    pub v: T,
    /// a [m/s²] [JA 87]: f_v(z, v, φ) in mode 2, else 0.
    pub a: T,
    /// φ [Wb].
    pub phi: T,
    /// H_c [A/m], with the Jiles–Atherton core.
    pub hc: Option<T>,
    /// R [Ω], when the coil resistance is estimated.
    pub r: Option<T>,
    /// q of [JA 86]: 1 at z_min, 2 moving, 3 at z_max (within the mode band of
    /// a stop).
    pub mode: u8,
}

/// [JA 86] with the band: 1 within it of z_min, 3 within it of z_max, else 2
/// (also for a NaN z).
#[inline]
pub fn mode_of<T: Scalar, const N: usize>(z: T, s: &Settings<T, N>) -> u8 {
    if z <= s.z_min + s.mode_band {
        1
    } else if z >= s.z_max - s.mode_band {
        3
    } else {
        2
    }
}

/// The stop the estimate stays on over the next sample: the free
/// acceleration points into a stop (the automaton's lift-off guard does not
/// fire) and the estimate is on it by its mode [JA 86], or reaches it within the
/// sample (its own prediction [JA 84a] `z_next` saturates there); the
/// prediction then keeps z = the stop. A NaN acceleration stays nowhere.
#[inline]
pub fn resting_stop<T: Scalar, const N: usize>(
    mode: u8,
    accel: T,
    z_next: T,
    s: &Settings<T, N>,
) -> Option<T> {
    if accel <= T::ZERO && (mode == 1 || z_next == s.z_min) {
        Some(s.z_min)
    } else if accel >= T::ZERO && (mode == 3 || z_next == s.z_max) {
        Some(s.z_max)
    } else {
        None
    }
}

/// z of x = [z, z_prev, φ, …].
#[inline]
pub(crate) fn first<T: Scalar, const N: usize>(x: &[T; N]) -> T {
    x.first().copied().unwrap_or(T::ZERO)
}

/// z projected onto [z_min, z_max] (a NaN stays NaN).
#[inline]
fn project<T: Scalar, const N: usize>(z: T, s: &Settings<T, N>) -> T {
    if z < s.z_min {
        s.z_min
    } else if z > s.z_max {
        s.z_max
    } else {
        z
    }
}

/// The posterior and the counters of a filter.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Posterior<T, const N: usize> {
    /// Mean: x_{k|k} between steps, the prior x_{k|k−1} between a step's
    /// prediction and its update.
    pub x: [T; N],
    /// Its covariance.
    pub p: Matrix<T, N>,
    /// The last finite input.
    u_last: T,
    /// Time of the step's sample [s], from 0 at the first: the prior's and
    /// the posterior's; the last posterior's is one T_s earlier.
    pub now: T,
    pub skipped: u32,
    pub repairs: u32,
    /// The last update's innovation y − ŷ and its variance S (0 and 0 where
    /// the update was skipped): what a prediction-error calibration reads.
    pub innovation: (T, T),
}

/// The input of one step.
pub(crate) struct Held<T> {
    /// Whether the measured u was finite (else its update is skipped).
    pub finite: bool,
    /// The u used: the measured one if finite, else the last finite one.
    pub u: T,
    /// The time of the last posterior [s].
    pub t: T,
}

impl<T: Scalar, const N: usize> Posterior<T, N> {
    /// x₀, P₀, before the first sample.
    pub const fn new(s: &Settings<T, N>) -> Self {
        Posterior {
            x: s.initial_state,
            p: s.initial_covariance,
            u_last: T::ZERO,
            now: T::ZERO,
            skipped: 0,
            repairs: 0,
            innovation: (T::ZERO, T::ZERO),
        }
    }

    /// A non-finite u is replaced by the last finite one (and its update
    /// skipped).
    #[inline]
    pub fn hold(&mut self, u: T, s: &Settings<T, N>) -> Held<T> {
        let finite = u.finite();
        if finite {
            self.u_last = u;
        }
        Held {
            finite,
            u: self.u_last,
            t: self.now - s.sample_period,
        }
    }

    /// The predicted prior if finite, else a restart from (x₀, P₀), counted.
    #[inline]
    pub fn accept(&mut self, next: [T; N], p: Matrix<T, N>, s: &Settings<T, N>) {
        if linalg::all_finite(&next) && linalg::all_finite_matrix(&p) {
            self.x = next;
            self.p = p;
        } else {
            self.x = s.initial_state;
            self.p = s.initial_covariance;
            self.repairs = self.repairs.saturating_add(1);
        }
    }

    /// x ← x + innovation·K with K = gain/s, returning K; `None` (nothing
    /// changed) unless the innovation and s are finite and s > 0: a NaN or ∞
    /// never enters the state (where it would stay forever).
    #[inline]
    pub fn correct(&mut self, innovation: T, s: T, gain: &[T; N]) -> Option<[T; N]> {
        if !(innovation.finite() && s.finite() && s > T::ZERO) {
            self.innovation = (T::ZERO, T::ZERO);
            return None;
        }
        self.innovation = (innovation, s);
        let k = gain.map(|g| g / s);
        linalg::axpy(&mut self.x, innovation, &k);
        Some(k)
    }

    /// Counts a skipped update; projects z, z_prev onto [z_min, z_max]; the
    /// estimate [JA 85–87] at that posterior, f_v of [JA 87] only in mode 2; the
    /// clock moves on to the next sample.
    #[inline]
    pub fn estimate<M: DiscreteModel<T, N>>(
        &mut self,
        model: &mut M,
        updated: bool,
        u: T,
        s: &Settings<T, N>,
    ) -> Estimate<T> {
        if !updated {
            self.skipped = self.skipped.saturating_add(1);
        }
        for zi in self.x.iter_mut().take(2) {
            *zi = project(*zi, s);
        }
        let x = self.x;
        // x = [z, z_prev, φ, …] (N ≥ 3, checked when a filter is built)
        let [z, z_prev, phi] = match x.as_slice() {
            [z, z_prev, phi, ..] => [*z, *z_prev, *phi],
            _ => [T::ZERO; 3],
        };
        // [JA 86] the mode, [JA 87] a = f_v in mode 2, [JA 85] v below
        let mode = mode_of(z, s);
        let a = if mode == 2 {
            model.acceleration(&x, u, self.now)
        } else {
            T::ZERO
        };
        self.now = self.now + s.sample_period;
        let at = |i: Option<usize>| i.and_then(|i| x.get(i).copied());
        Estimate {
            z,
            v: (z - z_prev) / s.sample_period,
            a,
            phi,
            hc: at(s.field),
            r: at(s.resistance),
            mode,
        }
    }
}
