//! The extended Kalman filter on the discretised model [JA 84–87] with the
//! model's symbolic Jacobians ([`Linearised`]).
//!
//! One [`Ekf::step`] at sample k, with the input u held over the last
//! sample and the output y_k measured now:
//!
//! 1. prediction from the last posterior with u (the last finite input if u
//!    is not finite): x ← F(x, u), P ← F_x·P·F_xᵀ + Q, Q = diag(q_z², 0,
//!    q_φ², …) + σ_u²·g·gᵀ, g = ∂F/∂u; on a stop (or reaching it, f_v into
//!    it) z = the stop and its row of F_x is zero. A non-finite result
//!    restarts the filter from (x₀, P₀), counted in [`Ekf::repairs`];
//! 2. update with y_k: R = σ_y² + σ_u²·(∂h/∂u)², S = H·P·Hᵀ + R, K = P·Hᵀ/S,
//!    x ← x + K·(y_k − h), P ← (I − K·H)·P·(I − K·H)ᵀ + R·K·Kᵀ (Joseph form:
//!    symmetric and positive semi-definite for any rounding of K). Skipped,
//!    and counted in [`Ekf::skipped`], when u, y_k, S or the innovation is
//!    not finite;
//! 3. z, z_prev projected onto [z_min, z_max]; the estimate [JA 85–87].

use crate::linalg::{self, Matrix, Scalar};

use super::filter::{first, mode_of, resting_stop, Estimate, Posterior};
use super::model::{Linearised, Settings, Stateless};
use super::Sizes;

/// The extended Kalman filter on the model `M` with N states in `T`.
/// Allocation- and panic-free.
#[derive(Clone, Debug, PartialEq)]
pub struct Ekf<M, T, const N: usize> {
    model: M,
    post: Posterior<T, N>,
}

impl<M: Stateless<T, N>, T: Scalar, const N: usize> Ekf<M, T, N> {
    /// At x₀, P₀ (at rest at z_max).
    #[must_use]
    pub const fn new() -> Self {
        Self::with_model(M::MODEL, &M::SETTINGS)
    }
}

impl<M: Stateless<T, N>, T: Scalar, const N: usize> Default for Ekf<M, T, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<M, T: Scalar, const N: usize> Ekf<M, T, N> {
    /// At x₀, P₀ of `settings` (the model's).
    pub const fn with_model(model: M, settings: &Settings<T, N>) -> Self {
        let () = Sizes::<N, 0>::STATES;
        Ekf {
            model,
            post: Posterior::new(settings),
        }
    }

    /// The posterior mean x_{k|k} (after the last `step`).
    #[must_use]
    pub const fn state(&self) -> [T; N] {
        self.post.x
    }

    /// The posterior covariance.
    #[must_use]
    pub const fn covariance(&self) -> Matrix<T, N> {
        self.post.p
    }

    /// Samples whose measurement update was skipped (non-finite data).
    #[must_use]
    pub const fn skipped(&self) -> u32 {
        self.post.skipped
    }

    /// Restarts after a non-finite prediction.
    #[must_use]
    pub const fn repairs(&self) -> u32 {
        self.post.repairs
    }

    /// The last step's innovation y − ŷ and its variance S ((0, 0) where its
    /// update was skipped).
    #[must_use]
    pub const fn innovation(&self) -> (T, T) {
        self.post.innovation
    }

    /// The model, e.g. to hand a self-calibrating model its adapted
    /// parameters between runs (the state and covariance are kept).
    pub fn model_mut(&mut self) -> &mut M {
        &mut self.model
    }
}

impl<M: Linearised<T, N>, T: Scalar, const N: usize> Ekf<M, T, N> {
    /// One sample k: `u` is the measured input held over the last sample
    /// (what was applied since the previous call), `y` the output measured
    /// at t_k. Predicts the prior from the last posterior with u, updates it
    /// with y and returns the posterior estimate.
    pub fn step(&mut self, u: T, y: T) -> Estimate<T> {
        let s = self.model.settings();
        let held = self.post.hold(u, &s);
        let u = held.u;

        // [JA 84] from the last posterior: x = F(x, u), P = F_x·P·F_xᵀ + Q
        let mut lin = self.model.transition(&self.post.x, u, held.t);
        let pred = &mut lin.prediction;
        let mode = mode_of(first(&self.post.x), &s);
        if let Some(stop) = resting_stop(mode, pred.accel, first(&pred.next), &s) {
            // [JA 86] on a stop, or reaching it: the prediction keeps z = the stop
            if let (Some(zn), Some(row)) = (pred.next.first_mut(), lin.f_x.first_mut()) {
                *zn = stop;
                *row = [T::ZERO; N];
            }
        }
        let mut p = linalg::sandwich(&lin.f_x, &self.post.p);
        p = linalg::add(&p, &linalg::diagonal(&s.process_variance));
        linalg::rank1_update(&mut p, s.input_variance, &lin.g);
        self.post.accept(lin.prediction.next, p, &s);

        // the update with y (Joseph form), skipped when anything is not finite
        let mut updated = false;
        if held.finite && y.finite() {
            let (m, h) = self.model.measurement(&self.post.x, u, self.post.now);
            let r = s.measurement_variance + s.input_variance * (m.dy_du * m.dy_du);
            let ph = linalg::mat_vec(&self.post.p, &h);
            let innovation_var = linalg::dot(&h, &ph) + r;
            if let Some(k) = self.post.correct(y - m.y, innovation_var, &ph) {
                self.post.p = linalg::joseph_update(&self.post.p, &k, &h, r);
                updated = true;
            }
        }
        self.post.estimate(&mut self.model, updated, u, &s)
    }
}
