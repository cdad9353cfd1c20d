//! The unscented Kalman filter on the discretised model [JA 84–87]
//! ([`Sampled`]), as in jiles-atherton-actuator-model [JA §6.1].
//!
//! Sigma points χ₀ = x̄, χ_{1+j} = x̄ + γ·Lⱼ, χ_{1+N+j} = x̄ − γ·Lⱼ (Lⱼ the
//! columns of the lower Cholesky factor of P; γ and the weights in
//! [`Weights`](super::Weights)). One [`Ukf::step`] at sample k, with the
//! input u held over the last sample and the output y_k measured now:
//!
//! 1. prediction with u (the last finite input if u is not): the last
//!    posterior's sigma points through F [JA 84], x̄ = Σ Wᵢᵐ·F(χᵢ),
//!    P = Σ Wᵢᶜ·(F(χᵢ) − x̄)(F(χᵢ) − x̄)ᵀ + Q, Q as in the EKF with g = ∂F/∂u
//!    at the posterior mean; on a stop (or reaching it, f_v into it) every
//!    point keeps z = the stop. A non-finite result restarts the filter from
//!    (x₀, P₀);
//! 2. update with y_k: the prior's sigma points through h, ŷ = Σ Wᵢᵐ·yᵢ,
//!    S = Σ Wᵢᶜ·(yᵢ − ŷ)² + R (R = σ_y² + σ_u²·(∂h/∂u)² at x̄),
//!    P_xy = Σ Wᵢᶜ·(χᵢ − x̄)·(yᵢ − ŷ), K = P_xy/S, x̄ ← x̄ + K·(y_k − ŷ),
//!    P ← P − S·K·Kᵀ (exactly symmetric). Skipped, and counted, when u, y_k,
//!    S or the innovation is not finite;
//! 3. z, z_prev projected onto [z_min, z_max]; the estimate [JA 85–87].
//!
//! Both steps factor P. When the factorisation fails (P not numerically
//! positive definite) P is repaired, first by jitter on the diagonal,
//! Pᵢᵢ ← Pᵢᵢ + ε·(|Pᵢᵢ| + P₀ᵢᵢ) with ε = [`Jitter::REPAIR_JITTER`], then by a
//! reset to P₀; each repair and restart is counted in [`Ukf::repairs`].

use crate::linalg::{self, Matrix, Scalar};
use crate::math::Real;

use super::filter::{first, mode_of, resting_stop, Estimate, Posterior};
use super::model::{Sampled, Settings, Stateless};
use super::Sizes;

/// The relative diagonal jitter of the first repair of a failed
/// factorisation, per float type.
pub trait Jitter: Scalar {
    const REPAIR_JITTER: Self;
}

impl Jitter for f64 {
    const REPAIR_JITTER: f64 = 1e-9;
}

/// f32 rounds at ~6e-8: a jitter far above it.
impl Jitter for f32 {
    const REPAIR_JITTER: f32 = 1e-5;
}

/// The unscented Kalman filter on the model `M` with N states in `T` and
/// P = 2N + 1 sigma points. Allocation- and panic-free.
#[derive(Clone, Debug, PartialEq)]
pub struct Ukf<M, T, const N: usize, const P: usize> {
    model: M,
    post: Posterior<T, N>,
}

impl<M: Stateless<T, N>, T: Scalar, const N: usize, const P: usize> Ukf<M, T, N, P> {
    /// At x₀, P₀ (at rest at z_max).
    #[must_use]
    pub const fn new() -> Self {
        Self::with_model(M::MODEL, &M::SETTINGS)
    }
}

impl<M: Stateless<T, N>, T: Scalar, const N: usize, const P: usize> Default for Ukf<M, T, N, P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<M, T: Scalar, const N: usize, const P: usize> Ukf<M, T, N, P> {
    /// At x₀, P₀ of `settings` (the model's).
    pub const fn with_model(model: M, settings: &Settings<T, N>) -> Self {
        let () = Sizes::<N, P>::STATES;
        let () = Sizes::<N, P>::POINTS;
        Ukf {
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

    /// Repaired factorisations and restarts after a non-finite prediction.
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

impl<M: Sampled<T, N>, T: Jitter, const N: usize, const P: usize> Ukf<M, T, N, P> {
    /// One sample k: `u` is the measured input held over the last sample
    /// (what was applied since the previous call), `y` the output measured
    /// at t_k. Predicts the prior from the last posterior with u, updates it
    /// with y and returns the posterior estimate.
    pub fn step(&mut self, u: T, y: T) -> Estimate<T> {
        let s = self.model.settings();
        let held = self.post.hold(u, &s);
        self.predict(held.u, held.t, &s);
        let updated = held.finite && y.finite() && self.update(held.u, y, &s);
        self.post.estimate(&mut self.model, updated, held.u, &s)
    }

    /// The last posterior's sigma points through [JA 84], u held over the last
    /// sample; the mean, and their covariance plus Q.
    fn predict(&mut self, u: T, t: T, s: &Settings<T, N>) {
        let w = s.unscented;
        let pts: [[T; N]; P] = self.sigma_points(s);
        let mut next = pts;
        let (mut accel, mut z_next) = (T::ZERO, T::ZERO);
        // [JA 84] every sigma point through F
        for (k, (nk, pt)) in next.iter_mut().zip(&pts).enumerate() {
            let o = self.model.transition(pt, u, t);
            *nk = o.next;
            // the centre point is the posterior mean
            if k == 0 {
                accel = o.accel;
                z_next = first(&o.next);
            }
        }
        let z = first(&self.post.x);
        if let Some(stop) = resting_stop(mode_of(z, s), accel, z_next, s) {
            // [JA 86] on a stop, or reaching it: every point keeps z = the stop
            for z in next.iter_mut().filter_map(|nk| nk.first_mut()) {
                *z = stop;
            }
        }
        let mean = linalg::weighted_mean(&next, w.mean0, w.other);
        let mut p = linalg::weighted_covariance(&next, &mean, w.cov0, w.other);
        p = linalg::add(&p, &linalg::diagonal(&s.process_variance));
        // the input's noise: Q += σ_u²·g·gᵀ, g = ∂F/∂u at the posterior mean
        let g = self.model.input_gain(&self.post.x, u, t);
        linalg::rank1_update(&mut p, s.input_variance, &g);
        self.post.accept(mean, p, s);
    }

    /// The update of the prior with y through its sigma points; whether it
    /// was applied.
    fn update(&mut self, u: T, y: T, s: &Settings<T, N>) -> bool {
        let w = s.unscented;
        let weight = |k: usize, w0: T| if k == 0 { w0 } else { w.other };
        let t = self.post.now;
        let pts: [[T; N]; P] = self.sigma_points(s);
        let mut ys = [T::ZERO; P];
        let mut dy_du = T::ZERO;
        for (k, (yk, pt)) in ys.iter_mut().zip(&pts).enumerate() {
            let m = self.model.measurement(pt, u, t);
            *yk = m.y;
            if k == 0 {
                dy_du = m.dy_du;
            }
        }
        let enumerated = || ys.iter().enumerate();
        let y_mean = enumerated().fold(T::ZERO, |a, (k, &yk)| a + weight(k, w.mean0) * yk);
        let spread = enumerated().fold(T::ZERO, |a, (k, &yk)| {
            let d = yk - y_mean;
            a + weight(k, w.cov0) * (d * d)
        });
        let var = spread + (s.measurement_variance + s.input_variance * (dy_du * dy_du));
        let pxy = linalg::weighted_cross(&pts, &self.post.x, &ys, y_mean, w.cov0, w.other);
        match self.post.correct(y - y_mean, var, &pxy) {
            Some(k) => {
                linalg::rank1_update(&mut self.post.p, -var, &k);
                true
            }
            None => false,
        }
    }

    /// The sigma points of (x, P), factoring P (see [`Ukf::factor`]).
    #[inline]
    fn sigma_points(&mut self, s: &Settings<T, N>) -> [[T; N]; P] {
        let l = self.factor(s);
        linalg::sigma_points(&self.post.x, &l, s.unscented.gamma)
    }

    /// The lower Cholesky factor of P. If the factorisation fails, P is
    /// repaired and the repair counted: jitter on the diagonal first, P₀ if
    /// that fails too.
    fn factor(&mut self, s: &Settings<T, N>) -> Matrix<T, N> {
        if let Some(l) = linalg::cholesky(&self.post.p) {
            return l;
        }
        self.post.repairs = self.post.repairs.saturating_add(1);
        let d = linalg::diag_of(&self.post.p);
        let d0 = linalg::diag_of(&s.initial_covariance);
        let mut jitter = [T::ZERO; N];
        for ((j, &pi), &p0) in jitter.iter_mut().zip(&d).zip(&d0) {
            *j = T::REPAIR_JITTER * (Real::abs(pi) + p0);
        }
        let q = linalg::add(&self.post.p, &linalg::diagonal(&jitter));
        if let Some(l) = linalg::cholesky(&q) {
            self.post.p = q;
            return l;
        }
        self.post.p = s.initial_covariance;
        s.initial_factor
    }
}
