//! The extended Kalman filter on the discretised model (84)–(87), with the
//! Jacobians the symbolic core derives (`DiscreteModel::transition_jacobian`,
//! `measurement_jacobian`): the f64 reference of the emitted EKF
//! (`codegen::emit_ekf`), step for step the same algorithm.
//!
//! One [`Ekf::step`] at sample k, with the input u held over the last
//! sample and the output y_k measured now (the coil current under voltage
//! drive; see `discrete.rs`, "Timing"):
//!
//! 1. prediction from the last posterior with u (the last finite input if u
//!    is not finite): x ← F(x, u), P ← F_x·P·F_xᵀ + Q, Q = diag(q_z², 0,
//!    q_φ², q_Hc²) + σ_u²·g·gᵀ, g = ∂F/∂u (see `discrete.rs`); at a stop
//!    (the posterior in mode 1 or 3, or (84a) saturating there, and f_v into
//!    the stop) z = the stop and its row of F_x is zero. If the result is not
//!    finite the filter restarts from its initial state and covariance
//!    (counted in [`Ekf::repairs`]);
//! 2. update of the prior with y_k: h, H = ∂h/∂x, ∂h/∂u at (x, u);
//!    R = σ_y² + σ_u²·(∂h/∂u)²; S = H·P·Hᵀ + R; K = P·Hᵀ/S;
//!    x ← x + K·(y_k − h); P ← (I − K·H)·P·(I − K·H)ᵀ + R·K·Kᵀ (Joseph form:
//!    symmetric, positive semi-definite for any rounding of K). Skipped (and
//!    counted) when u or y_k is not finite or S or the innovation is not: a
//!    NaN measurement leaves the prior as it is;
//! 3. projection of z, z_prev onto [z_min, z_max]; the estimate: v (85),
//!    mode (86), a (87) = f_v at the posterior.
//!
//! Nothing allocates after [`Ekf::new`].

use crate::model::Model;

use super::discrete::{dense, resting_stop, DiscreteModel, Estimate, KalmanError, KalmanSettings};
use super::filter::FilterCore;

/// The f64 reference EKF.
#[derive(Clone, Debug)]
pub struct Ekf {
    core: FilterCore,
}

impl Ekf {
    /// A filter at its initial state (at rest at z_max, φ = 0, H_c = 0).
    pub fn new(discrete: &DiscreteModel) -> Ekf {
        Ekf {
            core: FilterCore::new(discrete),
        }
    }

    /// Discretises `model` and builds the filter.
    pub fn from_model(model: &Model, settings: &KalmanSettings) -> Result<Ekf, KalmanError> {
        Ok(Ekf::new(&DiscreteModel::new(model, settings)?))
    }

    /// One sample: predict with u (held over the last sample), update with
    /// y (measured now), report the posterior.
    pub fn step(&mut self, u: f64, y: f64) -> Estimate {
        let c = &mut self.core;
        let n = c.n;
        let input = c.input(u);
        let u = input.u;

        // prediction from the last posterior with u held over the sample
        let t = c.tape_time();
        let mut pred = c.tapes.predict(&c.x, u, t);
        let (mut f, gain) = c.tapes.jacobian(&c.x, u, t);
        if let Some(stop) =
            resting_stop(c.mode(), pred.acceleration, pred.next[0], c.z_min, c.z_max)
        {
            pred.next[0] = stop;
            f[0] = [0.0; 4];
        }
        let mut p = dense::sandwich(n, &f, &c.p);
        c.add_process_noise(&mut p, &gain);
        c.accept(pred.next, p);

        // measurement update (skipped when anything is not finite)
        let t = c.tape_time();
        let mut updated = false;
        if input.u_ok && y.is_finite() {
            let m = c.tapes.measure(&c.x, u, t);
            let r = c.output_variance(m.dy_du);
            let ph = dense::mat_vec(n, &c.p, &m.dy_dx);
            let s = dense::dot(n, &m.dy_dx, &ph) + r;
            if let Some(k) = c.correct(y - m.y, s, &ph) {
                c.p = dense::joseph_update(n, &c.p, &k, &m.dy_dx, r);
                updated = true;
            }
        }

        // projection onto [z_min, z_max], the estimate
        let post = c.project(updated);
        c.estimate(&post, u)
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

    /// Restarts after a non-finite prediction.
    pub fn repairs(&self) -> usize {
        self.core.repairs
    }
}
