//! The unscented Kalman filter on the discretised model (84)–(87), as in
//! jiles-atherton-actuator-model §6.1: the f64 reference of the emitted UKF
//! (`codegen::emit_ukf`), step for step the same algorithm.
//!
//! Sigma points: χ₀ = x̄, χ_{1+j} = x̄ + γ·Lⱼ, χ_{1+n+j} = x̄ − γ·Lⱼ, where
//! Lⱼ is column j of the lower Cholesky factor of P and γ, W₀ᵐ, W₀ᶜ, Wᵢ come
//! from α, β, κ (`KalmanSettings::unscented`). One [`Ukf::step`] at sample
//! k, with the input u held over the last sample and the output y_k
//! measured now (see `discrete.rs`, "Timing"):
//!
//! 1. prediction with u (the last finite input if u is not): sigma points
//!    of the last posterior through F (84), x̄ = Σ Wᵢᵐ·F(χᵢ),
//!    P = Σ Wᵢᶜ·(F(χᵢ) − x̄)(F(χᵢ) − x̄)ᵀ + Q, Q as in the EKF (g = ∂F/∂u at
//!    the posterior mean). At a stop (the posterior mean in mode 1 or 3 or
//!    (84a) of the mean saturating there, and f_v at the mean into the stop)
//!    every propagated point gets z = the stop (see `discrete.rs`);
//! 2. update of the prior with y_k: sigma points of (x̄, P), yᵢ = h(χᵢ, u),
//!    ŷ = Σ Wᵢᵐ·yᵢ, S = Σ Wᵢᶜ·(yᵢ − ŷ)² + R (R = σ_y² + σ_u²·(∂h/∂u)² at x̄),
//!    P_xy = Σ Wᵢᶜ·(χᵢ − x̄)·(yᵢ − ŷ), K = P_xy/S, x̄ ← x̄ + K·(y_k − ŷ),
//!    P ← P − S·K·Kᵀ (exactly symmetric). Skipped (and counted) when u,
//!    y_k, S or the innovation is not finite;
//! 3. projection of z, z_prev onto [z_min, z_max]; the estimate: v (85),
//!    mode (86), a (87) = f_v at the posterior mean.
//!
//! **Factorisation.** Both steps factor P. When the Cholesky factorisation
//! fails (P not numerically positive definite), P is repaired: first by
//! jitter on the diagonal, Pᵢᵢ ← Pᵢᵢ + ε·(|Pᵢᵢ| + P₀ᵢᵢ) with ε =
//! [`REPAIR_JITTER`], and if that still fails by a reset to the initial
//! covariance P₀; each repair is counted ([`Ukf::repairs`]), never hidden. A
//! non-finite prediction restarts the filter from x₀, P₀ (counted too).

// index loops over the leading n ≤ 4 entries mirror the algebra
#![allow(clippy::needless_range_loop)]

use crate::model::Model;

use super::discrete::{
    dense, resting_stop, DiscreteModel, Estimate, KalmanError, KalmanSettings, UnscentedWeights,
};
use super::filter::FilterCore;

/// Relative diagonal jitter of the first repair of a failed factorisation
/// (f64; the emitted f32 filter uses [`REPAIR_JITTER_F32`]).
pub const REPAIR_JITTER: f64 = 1e-9;
/// The same for the emitted f32 filter (f32 rounds at ~6e-8).
pub const REPAIR_JITTER_F32: f64 = 1e-5;

/// Largest number of sigma points (2·4 + 1).
const MAX_POINTS: usize = 9;

/// The f64 reference UKF.
#[derive(Clone, Debug)]
pub struct Ukf {
    core: FilterCore,
    weights: UnscentedWeights,
    /// chol P₀ (P₀ is positive definite by construction).
    l0: [[f64; 4]; 4],
}

impl Ukf {
    /// A filter at its initial state (at rest at z_max, φ = 0, H_c = 0).
    pub fn new(discrete: &DiscreteModel) -> Ukf {
        Ukf {
            core: FilterCore::new(discrete),
            weights: discrete.settings.unscented(discrete.dim()),
            l0: discrete.initial_factor(),
        }
    }

    /// Discretises `model` and builds the filter.
    pub fn from_model(model: &Model, settings: &KalmanSettings) -> Result<Ukf, KalmanError> {
        Ok(Ukf::new(&DiscreteModel::new(model, settings)?))
    }

    /// The lower Cholesky factor of P, repairing P if it fails (see the
    /// module docs).
    fn factor(&mut self) -> dense::M4 {
        let c = &mut self.core;
        let n = c.n;
        if let Some(l) = dense::cholesky(n, &c.p) {
            return l;
        }
        c.repairs += 1;
        let mut q = c.p;
        for i in 0..n {
            q[i][i] += REPAIR_JITTER * (q[i][i].abs() + c.p0[i][i]);
        }
        if let Some(l) = dense::cholesky(n, &q) {
            c.p = q;
            return l;
        }
        c.p = c.p0;
        self.l0
    }

    /// The 2n + 1 sigma points of (x, P), factoring P (see [`Ukf::factor`]).
    fn sigma_points(&mut self) -> [[f64; 4]; MAX_POINTS] {
        let l = self.factor();
        let n = self.core.n;
        let mut pts = [self.core.x; MAX_POINTS];
        let lt = dense::transpose(n, &l);
        let g = self.weights.gamma;
        for j in 0..n {
            dense::axpy(n, &mut pts[1 + j], g, &lt[j]);
            dense::axpy(n, &mut pts[1 + n + j], -g, &lt[j]);
        }
        pts
    }

    fn weight_mean(&self, k: usize) -> f64 {
        if k == 0 {
            self.weights.mean0
        } else {
            self.weights.other
        }
    }

    fn weight_cov(&self, k: usize) -> f64 {
        if k == 0 {
            self.weights.cov0
        } else {
            self.weights.other
        }
    }

    /// One sample: predict with u (held over the last sample), update with
    /// y (measured now), report the posterior.
    pub fn step(&mut self, u: f64, y: f64) -> Estimate {
        let input = self.core.input(u);
        let u = input.u;
        self.predict(u);
        let t = self.core.tape_time();
        let updated = input.u_ok && y.is_finite() && self.update(u, y, t);
        let post = self.core.project(updated);
        self.core.estimate(&post, u)
    }

    /// Prediction: the posterior's sigma points through F (84) with u held
    /// over the sample; at a stop every point keeps z = the stop.
    fn predict(&mut self, u: f64) {
        let n = self.core.n;
        let m = 2 * n + 1;
        let t = self.core.tape_time();
        let pts = self.sigma_points();
        let mut next = [[0.0; 4]; MAX_POINTS];
        let mut accel = 0.0;
        for k in 0..m {
            let pr = self.core.tapes.predict(&pts[k], u, t);
            next[k] = pr.next;
            if k == 0 {
                accel = pr.acceleration;
            }
        }
        // the centre point is the posterior mean
        let c = &self.core;
        if let Some(stop) = resting_stop(c.mode(), accel, next[0][0], c.z_min, c.z_max) {
            for pt in next.iter_mut().take(m) {
                pt[0] = stop;
            }
        }
        let mut mean = [0.0; 4];
        for k in 0..m {
            dense::axpy(n, &mut mean, self.weight_mean(k), &next[k]);
        }
        let mut p = [[0.0; 4]; 4];
        for k in 0..m {
            let mut d = next[k];
            dense::axpy(n, &mut d, -1.0, &mean);
            dense::rank1_update(n, &mut p, self.weight_cov(k), &d);
        }
        let c = &mut self.core;
        let gain = c.tapes.input_gain(&c.x, u, t);
        c.add_process_noise(&mut p, &gain);
        c.accept(mean, p);
    }

    /// Measurement update of the prior with y; whether it was applied.
    fn update(&mut self, u: f64, y: f64, t: f64) -> bool {
        let n = self.core.n;
        let m = 2 * n + 1;
        let pts = self.sigma_points();
        let mut ys = [0.0; MAX_POINTS];
        let mut dy_du = 0.0;
        for k in 0..m {
            let e = self.core.tapes.measure(&pts[k], u, t);
            ys[k] = e.y;
            if k == 0 {
                dy_du = e.dy_du;
            }
        }
        let mut y_mean = 0.0;
        for k in 0..m {
            y_mean += self.weight_mean(k) * ys[k];
        }
        let mut s = 0.0;
        for k in 0..m {
            let d = ys[k] - y_mean;
            s += self.weight_cov(k) * (d * d);
        }
        let s = s + self.core.output_variance(dy_du);
        let mut pxy = [0.0; 4];
        for k in 0..m {
            let dy = self.weight_cov(k) * (ys[k] - y_mean);
            for i in 0..n {
                pxy[i] += (pts[k][i] - self.core.x[i]) * dy;
            }
        }
        match self.core.correct(y - y_mean, s, &pxy) {
            Some(k) => {
                dense::rank1_update(n, &mut self.core.p, -s, &k);
                true
            }
            None => false,
        }
    }

    /// The posterior mean x_{k|k} (first `dim` entries).
    pub fn state(&self) -> [f64; 4] {
        self.core.x
    }

    /// The posterior covariance (leading `dim`×`dim` block).
    pub fn covariance(&self) -> [[f64; 4]; 4] {
        self.core.p
    }

    pub fn dim(&self) -> usize {
        self.core.n
    }

    /// Samples whose measurement update was skipped (non-finite data).
    pub fn skipped(&self) -> usize {
        self.core.skipped
    }

    /// Repaired factorisations and restarts after a non-finite prediction.
    pub fn repairs(&self) -> usize {
        self.core.repairs
    }
}
