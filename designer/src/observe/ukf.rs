//! The unscented Kalman filter on the discretised model (84)–(87), as in
//! jiles-atherton-actuator-model §6.1: the f64 reference of the emitted UKF
//! (`codegen::emit_ukf`), step for step the same algorithm.
//!
//! Sigma points: χ₀ = x̄, χ_{1+j} = x̄ + γ·Lⱼ, χ_{1+n+j} = x̄ − γ·Lⱼ, where
//! Lⱼ is column j of the lower Cholesky factor of P and γ, W₀ᵐ, W₀ᶜ, Wᵢ come
//! from α, β, κ (`KalmanSettings::unscented`). One [`Ukf::step`] at sample k,
//! with the measured input u_k and output y_k:
//!
//! 1. update of the prior with y_k: sigma points of (x̄, P), yᵢ = h(χᵢ, u_k),
//!    ŷ = Σ Wᵢᵐ·yᵢ, S = Σ Wᵢᶜ·(yᵢ − ŷ)² + R (R = σ_y² + σ_u²·(∂h/∂u)² at x̄),
//!    P_xy = Σ Wᵢᶜ·(χᵢ − x̄)·(yᵢ − ŷ), K = P_xy/S, x̄ ← x̄ + K·(y_k − ŷ),
//!    P ← P − S·K·Kᵀ (exactly symmetric). Skipped (and counted) when u_k,
//!    y_k, S or the innovation is not finite;
//! 2. projection of z, z_prev onto [z_min, z_max]; the estimate: v (85),
//!    mode (86), a (87) = f_v at x̄ (the centre sigma point of the prediction);
//! 3. prediction with u_k held (the last finite input if u_k is not):
//!    sigma points of the posterior through F (84), x̄ = Σ Wᵢᵐ·F(χᵢ),
//!    P = Σ Wᵢᶜ·(F(χᵢ) − x̄)(F(χᵢ) − x̄)ᵀ + Q, Q as in the EKF (g = ∂F/∂u at
//!    the posterior mean). At a stop (mode 1 or 3 or (84a) of the mean
//!    saturating there, and f_v at the mean into the stop) every propagated
//!    point gets z = the stop (see `discrete.rs`).
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
use crate::sim::Mode;

use super::discrete::{
    dense, mode_of, project, resting_stop, DiscreteModel, DiscreteTapes, Estimate, KalmanError,
    KalmanSettings, UnscentedWeights,
};

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
    tapes: DiscreteTapes,
    n: usize,
    weights: UnscentedWeights,
    ts: f64,
    z_min: f64,
    z_max: f64,
    mode_band: f64,
    input_var: f64,
    measurement_var: f64,
    process: [f64; 4],
    x0: [f64; 4],
    p0: [[f64; 4]; 4],
    /// chol P₀ (P₀ is positive definite by construction).
    l0: [[f64; 4]; 4],
    has_field: bool,
    uses_time: bool,
    /// Prior mean x_{k|k−1}.
    x: [f64; 4],
    /// Prior covariance.
    p: [[f64; 4]; 4],
    u_last: f64,
    time: f64,
    skipped: usize,
    repairs: usize,
}

impl Ukf {
    /// A filter at its initial state (at rest at z_max, φ = 0, H_c = 0).
    pub fn new(discrete: &DiscreteModel) -> Ukf {
        let n = discrete.dim();
        let x0 = discrete.initial_state();
        let p0 = discrete.initial_covariance();
        Ukf {
            tapes: discrete.tapes(),
            n,
            weights: discrete.settings.unscented(n),
            ts: discrete.settings.sample_period,
            z_min: discrete.z_min,
            z_max: discrete.z_max,
            mode_band: discrete.mode_band,
            input_var: discrete.input_noise * discrete.input_noise,
            measurement_var: discrete.measurement_noise * discrete.measurement_noise,
            process: discrete.process_variance(),
            x0,
            p0,
            l0: discrete.initial_factor(),
            has_field: discrete.has_field_state(),
            uses_time: discrete.uses_time,
            x: x0,
            p: p0,
            u_last: 0.0,
            time: 0.0,
            skipped: 0,
            repairs: 0,
        }
    }

    /// Discretises `model` and builds the filter.
    pub fn from_model(model: &Model, settings: &KalmanSettings) -> Result<Ukf, KalmanError> {
        Ok(Ukf::new(&DiscreteModel::new(model, settings)?))
    }

    /// The lower Cholesky factor of P, repairing P if it fails (see the
    /// module docs).
    fn factor(&mut self) -> dense::M4 {
        let n = self.n;
        if let Some(l) = dense::cholesky(n, &self.p) {
            return l;
        }
        self.repairs += 1;
        let mut q = self.p;
        for i in 0..n {
            q[i][i] += REPAIR_JITTER * (q[i][i].abs() + self.p0[i][i]);
        }
        if let Some(l) = dense::cholesky(n, &q) {
            self.p = q;
            return l;
        }
        self.p = self.p0;
        self.l0
    }

    /// The 2n + 1 sigma points of (x, L).
    fn sigma_points(&self, l: &dense::M4) -> [[f64; 4]; MAX_POINTS] {
        let n = self.n;
        let mut pts = [self.x; MAX_POINTS];
        let lt = dense::transpose(n, l);
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

    /// One sample: update with (u, y), report the posterior, predict.
    pub fn step(&mut self, u: f64, y: f64) -> Estimate {
        let n = self.n;
        let m = 2 * n + 1;
        let u_ok = u.is_finite();
        if u_ok {
            self.u_last = u;
        }
        let u = self.u_last;
        let t = if self.uses_time { self.time } else { 0.0 };

        // measurement update
        let mut updated = false;
        if u_ok && y.is_finite() {
            let l = self.factor();
            let pts = self.sigma_points(&l);
            let mut ys = [0.0; MAX_POINTS];
            let mut dy_du = 0.0;
            for k in 0..m {
                let e = self.tapes.measure(&pts[k], u, t);
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
            let r = self.measurement_var + self.input_var * (dy_du * dy_du);
            let s = s + r;
            let mut pxy = [0.0; 4];
            for k in 0..m {
                let dy = self.weight_cov(k) * (ys[k] - y_mean);
                for i in 0..n {
                    pxy[i] += (pts[k][i] - self.x[i]) * dy;
                }
            }
            let innovation = y - y_mean;
            if innovation.is_finite() && s.is_finite() && s > 0.0 {
                let mut k = [0.0; 4];
                for i in 0..n {
                    k[i] = pxy[i] / s;
                }
                dense::axpy(n, &mut self.x, innovation, &k);
                dense::rank1_update(n, &mut self.p, -s, &k);
                updated = true;
            }
        }
        if !updated {
            self.skipped += 1;
        }

        // projection, the estimate
        self.x[0] = project(self.x[0], self.z_min, self.z_max);
        self.x[1] = project(self.x[1], self.z_min, self.z_max);
        let [z, z_prev, phi, hc] = self.x;
        let mode = mode_of(z, self.z_min, self.z_max, self.mode_band);

        // prediction
        let l = self.factor();
        let pts = self.sigma_points(&l);
        let mut next = [[0.0; 4]; MAX_POINTS];
        let mut accel = 0.0;
        for k in 0..m {
            let pr = self.tapes.predict(&pts[k], u, t);
            next[k] = pr.next;
            if k == 0 {
                accel = pr.acceleration;
            }
        }
        // the centre point is the posterior mean
        let resting = resting_stop(mode, accel, next[0][0], self.z_min, self.z_max);
        if let Some(stop) = resting {
            for pt in next.iter_mut().take(m) {
                pt[0] = stop;
            }
        }
        let estimate = Estimate {
            z,
            v: (z - z_prev) / self.ts,
            a: if mode == Mode::Free { accel } else { 0.0 },
            phi,
            hc: self.has_field.then_some(hc),
            mode,
        };
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
        for i in 0..n {
            p[i][i] += self.process[i];
        }
        let gain = self.tapes.input_gain(&self.x, u, t);
        dense::rank1_update(n, &mut p, self.input_var, &gain);
        if dense::all_finite(n, &mean) && dense::all_finite_matrix(n, &p) {
            self.x = mean;
            self.p = p;
        } else {
            self.x = self.x0;
            self.p = self.p0;
            self.repairs += 1;
        }
        self.time += self.ts;
        estimate
    }

    /// The prior mean x_{k+1|k} (first `dim` entries).
    pub fn state(&self) -> [f64; 4] {
        self.x
    }

    /// The prior covariance (leading `dim`×`dim` block).
    pub fn covariance(&self) -> [[f64; 4]; 4] {
        self.p
    }

    pub fn dim(&self) -> usize {
        self.n
    }

    /// Samples whose measurement update was skipped (non-finite data).
    pub fn skipped(&self) -> usize {
        self.skipped
    }

    /// Repaired factorisations and restarts after a non-finite prediction.
    pub fn repairs(&self) -> usize {
        self.repairs
    }
}
