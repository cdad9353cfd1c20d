//! SEMERA: stochastic electromagnetic estimation of the resistance r, the
//! apparent inductance l and the flux linkage λ of a reluctance actuator from
//! sampled coil voltage and current alone (semera-electromagnetic-estimation,
//! §II, Algorithm 1). The f64 reference of the emitted `Semera`
//! (`codegen/src/semera.rs`): both run the same operations in the same order.
//!
//! The filter (Algorithm 1, one [`Semera::step`] per sample, every Δ):
//!
//! - state x_k = [r_k, l_k, l_{k−1}] (10), observation z_k = u_k (9) with the
//!   noisy, state-independent-looking but stochastic observation row
//!   H_k = [ι_k, ι_k/Δ, −ι_{k−1}/Δ] (11);
//! - process model (16) with F of (21) (constant r, linear l; the prediction
//!   (19) is garbled in the text, it reads l̂_{k+1/k} = 2·l̂_{k/k} − l̂_{k−1/k},
//!   ERRATA), G of (23), Q = diag(σ_ṙ², σ_l̈²) (24), so
//!   G·Q·Gᵀ = diag((σ_ṙ·Δ)², (σ_l̈·Δ²)², 0);
//! - prior x̄₀ = [r̄₀, l̄₀, l̄₀] (25), P₀ of (26) with σ²_r0 in its first
//!   diagonal element (the text prints σ_r0, ERRATA);
//! - the gain (43) K̂ = Σ Hᵀ (H Σ Hᵀ + σ_v²)⁻¹: the observation noise (12)–(15)
//!   depends on the state and on the current noise through H itself, so the
//!   paper derives the gain from z_k = C_k x_k + v_v (only the voltage noise,
//!   σ_v²) and evaluates it at H_k in place of the unknown C_k. The
//!   state-dependent variance R_k of (15) therefore does not enter the step
//!   (it is [`Semera::observation_noise_variance`], a diagnostic);
//! - Σ_{k/k} = (I − K̂ H) Σ (line 10). With g = Σ Hᵀ this is
//!   B = Σ − K̂ gᵀ (symmetric in exact arithmetic: its upper triangle is
//!   used), and it also equals the Joseph form
//!   (I − K̂ H) Σ (I − K̂ H)ᵀ + σ_v² K̂ K̂ᵀ = B − d K̂ᵀ with d = B Hᵀ − σ_v² K̂,
//!   where d vanishes in exact arithmetic but corrects B's rounding to first
//!   order. The step evaluates the l block (rows and columns 2–3) as B − d K̂ᵀ
//!   and the r row as B. Reason: B alone loses Σ's positive definiteness in
//!   f32 (and the emitted f32 step is this one). Σ's l block is nearly
//!   singular (l_k ≈ l_{k−1}), its entries grow by σ_l̈ through the rest
//!   periods and the update cancels them to ~1e-9 of their size; Σ(1,1) then
//!   goes negative within the first decay of the current and r̂ random-walks
//!   away (by up to 30 Ω over 300 noisy cycles of the semera valve in f32).
//!   Correcting the l block, where the cancellation happens, is enough: the
//!   f32 r̂ then stays within 3e-4 Ω of f64 on those 300 cycles (1e-4
//!   relative on a relay-like record with Table V's parameters), as does the
//!   full Joseph form, at 8 more multiplications instead of 15;
//! - the confidence-interval detector: the a posteriori r and l are the
//!   estimates only if |ι_k| and |ι_{k−1}| both lie outside [−n_σ σ_i, n_σ σ_i]
//!   (and the sample was used, below);
//!   otherwise the expert rule r̂_k = r̂_{k−1}, l̂_k = l̄₀ (the device at rest;
//!   lines 13–15 of Algorithm 1, lost in the text, are read from §II-C);
//! - λ̂_k = l̂_k·ι_k (line 16), φ̂ = λ̂/N and R̂ = N²/l̂ (§II-C, N known).
//!
//! Choices the paper leaves open, made here (and in the emitted code):
//!
//! - Algorithm 1 registers ι₀ before its loop. [`Semera::new`] starts at rest
//!   with ι₀ = 0, so the first call of `step` is k = 1 (under the expert rule,
//!   since |ι₀| is inside the interval).
//! - A sample whose update would not be finite (a NaN or infinite v or i, or
//!   the sample after a non-finite current, whose H uses it) is a missing
//!   measurement: the filter only predicts, and the estimate of that sample
//!   follows the expert rule (`valid` is false); its λ̂ is then l̄₀·ι
//!   (not finite for a non-finite current). The state stays finite.
//!
//! No allocation per step; no division except 1/s (s ≥ σ_v² > 0) and N²/l̂.

use crate::description::{Description, SemeraSettings};

/// Everything [`Semera::new`] needs: `[observer]` σ_v, σ_i, Δ, the coil's N
/// and `[observer.semera]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SemeraConfig {
    /// Δ [s].
    pub sample_period: f64,
    /// σ_v [V].
    pub voltage_noise: f64,
    /// σ_i [A].
    pub current_noise: f64,
    /// N, the coil's turns (for φ = λ/N and R = N²/l).
    pub turns: f64,
    /// Table II / V.
    pub filter: SemeraSettings,
}

impl SemeraConfig {
    /// The configuration of a description with `[observer.semera]`.
    pub fn from_description(d: &Description) -> Option<SemeraConfig> {
        let o = d.observer.as_ref()?;
        Some(SemeraConfig {
            sample_period: o.sample_period,
            voltage_noise: o.voltage_noise,
            current_noise: o.current_noise,
            turns: d.coil.turns,
            filter: o.semera?,
        })
    }
}

/// The estimate of one sample (SEMERA and the integral estimator alike).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// r̂ [Ω].
    pub r: f64,
    /// l̂ [H] (l̄₀ under the expert rule).
    pub l: f64,
    /// λ̂ [Wb].
    pub lambda: f64,
    /// φ̂ = λ̂/N [Wb].
    pub phi: f64,
    /// R̂ = N²/l̂ [H⁻¹].
    pub reluctance: f64,
    /// The confidence-interval detector: |ι_k| and |ι_{k−1}| are both above
    /// n_σ·σ_i (and, for SEMERA, the sample was used): the estimator's r, l
    /// are used; false under the expert rule.
    pub valid: bool,
}

/// Precomputed constants of the step (the emitted code's consts).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Constants {
    /// 1/Δ
    inv_dt: f64,
    /// σ_v²
    sigma_v2: f64,
    /// (σ_ṙ·Δ)²: G Q Gᵀ (1, 1)
    q_r: f64,
    /// (σ_l̈·Δ²)²: G Q Gᵀ (2, 2)
    q_l: f64,
    /// n_σ·σ_i
    ci: f64,
    /// l̄₀
    l0: f64,
    /// 1/N
    inv_turns: f64,
    /// N²
    turns_sq: f64,
    /// σ_i² (for R_k of (15) only)
    sigma_i2: f64,
}

/// The SEMERA estimator (Algorithm 1), f64 reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Semera {
    c: Constants,
    /// x̂_{k+1/k} = [r, l, l_prev] (a priori for the next sample).
    x: [f64; 3],
    /// Σ_{k+1/k}, symmetric: [Σ11, Σ12, Σ13, Σ22, Σ23, Σ33].
    p: [f64; 6],
    /// ι_{k−1}.
    i_prev: f64,
    /// r̂_{k−1} (the expert rule keeps it).
    r_hat: f64,
}

impl Semera {
    /// Algorithm 1, lines 1–3: x̂_{1/0} = x̄₀ (25), Σ_{1/0} = P₀ (26), ι₀ = 0.
    pub fn new(config: &SemeraConfig) -> Semera {
        let f = &config.filter;
        let dt = config.sample_period;
        let c = Constants {
            inv_dt: 1.0 / dt,
            sigma_v2: config.voltage_noise * config.voltage_noise,
            q_r: (f.resistance_rate_std * dt) * (f.resistance_rate_std * dt),
            q_l: (f.inductance_accel_std * dt * dt) * (f.inductance_accel_std * dt * dt),
            ci: f.ci_sigmas * config.current_noise,
            l0: f.initial_inductance,
            inv_turns: 1.0 / config.turns,
            turns_sq: config.turns * config.turns,
            sigma_i2: config.current_noise * config.current_noise,
        };
        let var_r0 = f.initial_resistance_std * f.initial_resistance_std;
        let var_l0 = f.initial_inductance_std * f.initial_inductance_std;
        Semera {
            c,
            x: [
                f.initial_resistance,
                f.initial_inductance,
                f.initial_inductance,
            ],
            p: [var_r0, 0.0, 0.0, var_l0, var_l0, var_l0],
            i_prev: 0.0,
            r_hat: f.initial_resistance,
        }
    }

    /// One sample k: the measured voltage u_k = `v` [V] and current ι_k = `i`
    /// [A] (Algorithm 1, lines 5–16).
    pub fn step(&mut self, v: f64, i: f64) -> Estimate {
        let c = &self.c;
        // line 7: H_k (11)
        let h1 = i;
        let h2 = i * c.inv_dt;
        let h3 = -(self.i_prev * c.inv_dt);
        // line 8: K̂ (43) = g/s, g = Σ Hᵀ, s = H Σ Hᵀ + σ_v²
        let [p11, p12, p13, p22, p23, p33] = self.p;
        let g1 = p11 * h1 + p12 * h2 + p13 * h3;
        let g2 = p12 * h1 + p22 * h2 + p23 * h3;
        let g3 = p13 * h1 + p23 * h2 + p33 * h3;
        let s = h1 * g1 + h2 * g2 + h3 * g3 + c.sigma_v2;
        let w = 1.0 / s;
        // line 9: innovation z_k − H_k x̂_{k/k−1}
        let [mut r, mut l, mut lp] = self.x;
        let nu = v - (h1 * r + h2 * l + h3 * lp);
        let (mut q11, mut q12, mut q13, mut q22, mut q23, mut q33) = (p11, p12, p13, p22, p23, p33);
        let m = nu * w;
        let used = m.is_finite();
        if used {
            let k1 = g1 * w;
            let k2 = g2 * w;
            let k3 = g3 * w;
            r += g1 * m;
            l += g2 * m;
            lp += g3 * m;
            // line 10: Σ_{k/k} = (I − K̂ H) Σ = B = Σ − K̂ gᵀ, the l block as the
            // Joseph form B − d K̂ᵀ, d = B Hᵀ − σ_v² K̂ (= 0 up to rounding; module docs)
            let (b11, b12, b13) = (p11 - k1 * g1, p12 - k1 * g2, p13 - k1 * g3);
            let (b22, b23, b33) = (p22 - k2 * g2, p23 - k2 * g3, p33 - k3 * g3);
            let d2 = b12 * h1 + b22 * h2 + b23 * h3 - c.sigma_v2 * k2;
            let d3 = b13 * h1 + b23 * h2 + b33 * h3 - c.sigma_v2 * k3;
            q11 = b11;
            q12 = b12;
            q13 = b13;
            q22 = b22 - d2 * k2;
            q23 = b23 - d2 * k3;
            q33 = b33 - d3 * k3;
        }
        // lines 11–12: x̂_{k+1/k} = F x̂_{k/k}, Σ_{k+1/k} = F Σ Fᵀ + G Q Gᵀ (21), (23), (24)
        self.x = [r, 2.0 * l - lp, l];
        self.p = [
            q11 + c.q_r,
            2.0 * q12 - q13,
            q12,
            4.0 * (q22 - q23) + q33 + c.q_l,
            2.0 * q22 - q23,
            q22,
        ];
        // lines 13–15: CI detector and expert rule
        let valid = used && i.abs() > c.ci && self.i_prev.abs() > c.ci;
        let (r_hat, l_hat) = if valid { (r, l) } else { (self.r_hat, c.l0) };
        self.r_hat = r_hat;
        self.i_prev = i;
        // line 16 and §II-C: λ = l·ι, φ = λ/N, R = N²/l
        let lambda = l_hat * i;
        Estimate {
            r: r_hat,
            l: l_hat,
            lambda,
            phi: lambda * c.inv_turns,
            reluctance: c.turns_sq / l_hat,
            valid,
        }
    }

    /// x̂_{k+1/k} = [r, l, l_prev]: the a priori state for the next sample.
    pub fn state(&self) -> [f64; 3] {
        self.x
    }

    /// Σ_{k+1/k} as a full 3×3 matrix.
    pub fn covariance(&self) -> [[f64; 3]; 3] {
        let [a, b, c, d, e, f] = self.p;
        [[a, b, c], [b, d, e], [c, e, f]]
    }

    /// R_k of (15) at the a priori state for the next sample: the variance of
    /// the observation noise (12), σ_v² + σ_i²·((r + l/Δ)² + (l_prev/Δ)²).
    /// Not used by the step (the gain (43) takes σ_v² alone, see the module
    /// docs); a diagnostic of how much the current noise weighs.
    pub fn observation_noise_variance(&self) -> f64 {
        let [r, l, lp] = self.x;
        let a = r + l * self.c.inv_dt;
        let b = lp * self.c.inv_dt;
        self.c.sigma_v2 + self.c.sigma_i2 * (a * a + b * b)
    }
}
