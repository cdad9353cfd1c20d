//! What the EKF and the UKF share: the discretised model's constants, the
//! posterior (x, P) with its initial value, the held input, and the steps
//! around the two filters' own algebra — input handling, projection onto
//! [z_min, z_max] with the estimate (85)–(87), Q added to the predicted
//! covariance, and the restart from (x₀, P₀) after a non-finite prediction.

// index loops over the leading n ≤ 4 entries mirror the algebra
#![allow(clippy::needless_range_loop)]

use crate::sim::Mode;

use super::discrete::{dense, mode_of, project, DiscreteModel, DiscreteTapes, Estimate};

/// The state and bookkeeping of a Kalman filter on the discretised model.
#[derive(Clone, Debug)]
pub(crate) struct FilterCore {
    pub tapes: DiscreteTapes,
    pub n: usize,
    pub ts: f64,
    pub z_min: f64,
    pub z_max: f64,
    pub mode_band: f64,
    pub input_var: f64,
    pub measurement_var: f64,
    pub process: [f64; 4],
    pub x0: [f64; 4],
    pub p0: [[f64; 4]; 4],
    pub has_field: bool,
    /// Index of R in the state, if estimated.
    pub r_index: Option<usize>,
    pub uses_time: bool,
    /// Mean: the posterior x_{k|k} between steps, the prior x_{k|k−1}
    /// between a step's prediction and its update.
    pub x: [f64; 4],
    /// Its covariance.
    pub p: [[f64; 4]; 4],
    pub u_last: f64,
    pub time: f64,
    pub skipped: usize,
    pub repairs: usize,
}

/// The input of one step: whether the measured u was finite and the u used
/// (the last finite one).
pub(crate) struct StepInput {
    pub u_ok: bool,
    pub u: f64,
}

/// The posterior after projection: its components and mode (86).
pub(crate) struct Posterior {
    pub z: f64,
    pub z_prev: f64,
    pub phi: f64,
    /// x[3]: H_c with the Jiles–Atherton core.
    pub hc: f64,
    /// R, if estimated.
    pub r: Option<f64>,
    pub mode: Mode,
}

impl FilterCore {
    /// At the initial state (at rest at z_max, φ = 0, H_c = 0).
    pub fn new(discrete: &DiscreteModel) -> FilterCore {
        let x0 = discrete.initial_state();
        let p0 = discrete.initial_covariance();
        FilterCore {
            tapes: discrete.tapes(),
            n: discrete.dim(),
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
            r_index: discrete.resistance_index(),
            uses_time: discrete.uses_time,
            x: x0,
            p: p0,
            u_last: 0.0,
            // the first step predicts from x₀ at −T_s to the first sample at 0
            time: -discrete.settings.sample_period,
            skipped: 0,
            repairs: 0,
        }
    }

    /// A finite u is remembered; a non-finite one is replaced by the last
    /// finite u.
    pub fn input(&mut self, u: f64) -> StepInput {
        let u_ok = u.is_finite();
        if u_ok {
            self.u_last = u;
        }
        StepInput {
            u_ok,
            u: self.u_last,
        }
    }

    /// The time argument of the tapes: the time of the current mean (the
    /// last posterior's before [`FilterCore::accept`], this sample's after).
    pub fn tape_time(&self) -> f64 {
        if self.uses_time {
            self.time
        } else {
            0.0
        }
    }

    /// The mode (86) of the current mean.
    pub fn mode(&self) -> Mode {
        mode_of(self.x[0], self.z_min, self.z_max, self.mode_band)
    }

    /// R = σ_y² + σ_u²·(∂h/∂u)²: the measurement variance with the input's.
    pub fn output_variance(&self, dy_du: f64) -> f64 {
        self.measurement_var + self.input_var * (dy_du * dy_du)
    }

    /// x ← x + innovation·K with K = gain/s, returning K; `None` (nothing
    /// changed) unless the innovation and s are finite and s > 0.
    pub fn correct(&mut self, innovation: f64, s: f64, gain: &[f64; 4]) -> Option<[f64; 4]> {
        if !(innovation.is_finite() && s.is_finite() && s > 0.0) {
            return None;
        }
        let mut k = [0.0; 4];
        for i in 0..self.n {
            k[i] = gain[i] / s;
        }
        dense::axpy(self.n, &mut self.x, innovation, &k);
        Some(k)
    }

    /// Counts a skipped update; projects z, z_prev onto [z_min, z_max]; the
    /// posterior with its mode (86).
    pub fn project(&mut self, updated: bool) -> Posterior {
        if !updated {
            self.skipped += 1;
        }
        self.x[0] = project(self.x[0], self.z_min, self.z_max);
        self.x[1] = project(self.x[1], self.z_min, self.z_max);
        let [z, z_prev, phi, hc] = self.x;
        Posterior {
            z,
            z_prev,
            phi,
            hc,
            r: self.r_index.map(|i| self.x[i]),
            mode: mode_of(z, self.z_min, self.z_max, self.mode_band),
        }
    }

    /// The estimate: v (85), a (87) = f_v at the posterior in mode 2 (only
    /// evaluated there), else 0.
    pub fn estimate(&mut self, post: &Posterior, u: f64) -> Estimate {
        let a = if post.mode == Mode::Free {
            let t = self.tape_time();
            self.tapes.acceleration(&self.x, u, t)
        } else {
            0.0
        };
        Estimate {
            z: post.z,
            v: (post.z - post.z_prev) / self.ts,
            a,
            phi: post.phi,
            hc: self.has_field.then_some(post.hc),
            r: post.r,
            mode: post.mode,
        }
    }

    /// P + Q: the diagonal process noise and σ_u²·g·gᵀ of the input.
    pub fn add_process_noise(&self, p: &mut [[f64; 4]; 4], input_gain: &[f64; 4]) {
        for i in 0..self.n {
            p[i][i] += self.process[i];
        }
        dense::rank1_update(self.n, p, self.input_var, input_gain);
    }

    /// The predicted prior if finite, else a restart from (x₀, P₀) (counted);
    /// then the clock advances by one sample.
    pub fn accept(&mut self, next: [f64; 4], p: [[f64; 4]; 4]) {
        let n = self.n;
        if dense::all_finite(n, &next) && dense::all_finite_matrix(n, &p) {
            self.x = next;
            self.p = p;
        } else {
            self.x = self.x0;
            self.p = self.p0;
            self.repairs += 1;
        }
        self.time += self.ts;
    }
}
