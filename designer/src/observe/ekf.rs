//! The extended Kalman filter on the discretised model (84)–(87), with the
//! Jacobians the symbolic core derives (`DiscreteModel::transition_jacobian`,
//! `measurement_jacobian`): the f64 reference of the emitted EKF
//! (`codegen::emit_ekf`), step for step the same algorithm.
//!
//! One [`Ekf::step`] at sample k, with the measured input u_k and output y_k
//! (the coil current under voltage drive):
//!
//! 1. update of the prior x_{k|k−1}, P with y_k: h, H = ∂h/∂x, ∂h/∂u at
//!    (x, u_k); R = σ_y² + σ_u²·(∂h/∂u)²; S = H·P·Hᵀ + R; K = P·Hᵀ/S;
//!    x ← x + K·(y_k − h); P ← (I − K·H)·P·(I − K·H)ᵀ + R·K·Kᵀ (Joseph form:
//!    symmetric, positive semi-definite for any rounding of K). Skipped (and
//!    counted) when u_k or y_k is not finite or S or the innovation is not: a
//!    NaN measurement leaves the state as it was;
//! 2. projection of z, z_prev onto [z_min, z_max]; the estimate: v (85),
//!    mode (86), a (87);
//! 3. prediction with u_k (the last finite input if u_k is not finite):
//!    x ← F(x, u_k), P ← F_x·P·F_xᵀ + Q, Q = diag(q_z², 0, q_φ², q_Hc²) +
//!    σ_u²·g·gᵀ, g = ∂F/∂u (see `discrete.rs`); at a stop (mode 1 or 3,
//!    or (84a) saturating there, and f_v into the stop) z = the stop and its
//!    row of F_x is zero. If the result is not finite
//!    the filter restarts from its initial state and covariance (counted in
//!    [`Ekf::repairs`]).
//!
//! Nothing allocates after [`Ekf::new`].

// index loops over the leading n ≤ 4 entries mirror the algebra
#![allow(clippy::needless_range_loop)]

use crate::model::Model;
use crate::sim::Mode;

use super::discrete::{
    dense, mode_of, project, resting_stop, DiscreteModel, DiscreteTapes, Estimate, KalmanError,
    KalmanSettings,
};

/// The f64 reference EKF.
#[derive(Clone, Debug)]
pub struct Ekf {
    tapes: DiscreteTapes,
    n: usize,
    ts: f64,
    z_min: f64,
    z_max: f64,
    mode_band: f64,
    input_var: f64,
    measurement_var: f64,
    process: [f64; 4],
    x0: [f64; 4],
    p0: [[f64; 4]; 4],
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

impl Ekf {
    /// A filter at its initial state (at rest at z_max, φ = 0, H_c = 0).
    pub fn new(discrete: &DiscreteModel) -> Ekf {
        let n = discrete.dim();
        let x0 = discrete.initial_state();
        let p0 = discrete.initial_covariance();
        Ekf {
            tapes: discrete.tapes(),
            n,
            ts: discrete.settings.sample_period,
            z_min: discrete.z_min,
            z_max: discrete.z_max,
            mode_band: discrete.mode_band,
            input_var: discrete.input_noise * discrete.input_noise,
            measurement_var: discrete.measurement_noise * discrete.measurement_noise,
            process: discrete.process_variance(),
            x0,
            p0,
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
    pub fn from_model(model: &Model, settings: &KalmanSettings) -> Result<Ekf, KalmanError> {
        Ok(Ekf::new(&DiscreteModel::new(model, settings)?))
    }

    /// One sample: update with (u, y), report the posterior, predict.
    pub fn step(&mut self, u: f64, y: f64) -> Estimate {
        let n = self.n;
        let u_ok = u.is_finite();
        if u_ok {
            self.u_last = u;
        }
        let u = self.u_last;
        let t = if self.uses_time { self.time } else { 0.0 };

        // measurement update (skipped when anything is not finite)
        let mut updated = false;
        if u_ok && y.is_finite() {
            let m = self.tapes.measure(&self.x, u, t);
            let r = self.measurement_var + self.input_var * (m.dy_du * m.dy_du);
            let ph = dense::mat_vec(n, &self.p, &m.dy_dx);
            let s = dense::dot(n, &m.dy_dx, &ph) + r;
            let innovation = y - m.y;
            if innovation.is_finite() && s.is_finite() && s > 0.0 {
                let mut k = [0.0; 4];
                for i in 0..n {
                    k[i] = ph[i] / s;
                }
                dense::axpy(n, &mut self.x, innovation, &k);
                self.p = dense::joseph_update(n, &self.p, &k, &m.dy_dx, r);
                updated = true;
            }
        }
        if !updated {
            self.skipped += 1;
        }

        // projection onto [z_min, z_max], the estimate
        self.x[0] = project(self.x[0], self.z_min, self.z_max);
        self.x[1] = project(self.x[1], self.z_min, self.z_max);
        let [z, z_prev, phi, hc] = self.x;
        let mode = mode_of(z, self.z_min, self.z_max, self.mode_band);

        // prediction with u held over the sample
        let mut pred = self.tapes.predict(&self.x, u, t);
        let (mut f, gain) = self.tapes.jacobian(&self.x, u, t);
        let resting = resting_stop(
            mode,
            pred.acceleration,
            pred.next[0],
            self.z_min,
            self.z_max,
        );
        if let Some(stop) = resting {
            pred.next[0] = stop;
            f[0] = [0.0; 4];
        }
        let estimate = Estimate {
            z,
            v: (z - z_prev) / self.ts,
            a: if mode == Mode::Free {
                pred.acceleration
            } else {
                0.0
            },
            phi,
            hc: self.has_field.then_some(hc),
            mode,
        };
        let mut p = dense::sandwich(n, &f, &self.p);
        for i in 0..n {
            p[i][i] += self.process[i];
        }
        dense::rank1_update(n, &mut p, self.input_var, &gain);
        if dense::all_finite(n, &pred.next) && dense::all_finite_matrix(n, &p) {
            self.x = pred.next;
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

    /// Restarts after a non-finite prediction.
    pub fn repairs(&self) -> usize {
        self.repairs
    }
}
