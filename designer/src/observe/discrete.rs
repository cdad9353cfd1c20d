//! The discretised model of jiles-atherton-actuator-model §6.1 (eqs. 84–87),
//! built by the symbolic core from the model's own expressions, with the
//! measurement and the Jacobians the EKF needs.
//!
//! State x = [z, z_prev, φ] (+ H_c with the Jiles–Atherton core) (+ R with
//! [`ResistanceSettings`]), where z_prev is the position one sample earlier;
//! input u (the coil voltage, or the current with `drive = "current"`);
//! sample period T_s.
//!
//! | quantity | expression |
//! | --- | --- |
//! | (85) velocity | v = (z − z_prev)/T_s |
//! | (84a) position | z⁺ = sat_{z_min}^{z_max}(2z − z_prev + T_s²·f_v(z, v, φ)) |
//! | (84b) previous position | z_prev⁺ = sat_{z_min}^{z_max}(z) (= z for every state (84a) produces) |
//! | (84c) flux | φ⁺ = φ + T_s·f_φ(z, φ, H_c, u) |
//! | (84d) core field | H_c⁺ = H_c + T_s·f_Hc(z, φ, H_c, u) |
//! | coil resistance (optional) | R⁺ = R (random walk: w_R of σ = σ_Ṙ·T_s, as semera's q_r) |
//! | (86) mode | 1 if z ≤ z_min + band, 3 if z ≥ z_max − band, else 2 |
//! | (87) acceleration | a = f_v(z, v, φ) in mode 2, else 0 |
//! | measurement | y = h(z, φ, H_c, u): the coil current (voltage drive), the coil voltage (current drive) |
//!
//! f_v, f_φ, f_Hc and h are the model's expressions (`Model::f`,
//! `Model::current`/`Model::voltage`) with v replaced by (85). The model is
//! defined on [z_min, z_max] (and |φ| < φ_sat for the saturating core): the
//! filters evaluate it at z clamped to [z_min, z_max] (and φ clamped to
//! ±(1 − 10⁻³)·φ_sat), so that sigma points and corrections that leave the
//! domain give finite values (the McLyman logarithm is undefined below
//! z_min, R_core is infinite at φ_sat); (84a) and (85) use z itself. (84b)
//! saturates too: a sigma point beyond a stop (the UKF spreads them by
//! ±γ·σ_z around an estimate that rests on it) would otherwise carry the
//! spurious velocity (z_next − z)/T_s of its saturation into the next step,
//! a bias the mean inherits.
//!
//! **Resistance state.** With [`ResistanceSettings`] the model's parameter R
//! becomes a state (the symbol stays, it is no longer bound to the
//! description's value), so f_φ, h and their Jacobians carry it. Under
//! voltage drive an error in R biases the flux rate (u − R·i)/N, hence the
//! flux and, through h, the position estimate; while the armature rests on a
//! stop z is pinned, the steady current makes R observable (R ≈ u/i), and
//! the filter tracks it. R's initial value is the description's.
//!
//! **Noise.** w_z, w_φ, w_Hc (, w_R) are independent with the standard deviations of
//! [`KalmanSettings`] (per step). The measured input u (σ_u: the voltage
//! noise, or the current noise with current drive) enters the transition
//! through (84c)–(84d); its noise is mapped into the process noise to first
//! order: Q = diag(q_z², 0, q_φ², q_Hc²) + σ_u²·g·gᵀ with g = ∂F/∂u at the
//! estimate. The measured u also enters the measurement (the eddy term
//! k_e·u of the current): R = σ_y² + σ_u²·(∂h/∂u)². The update at k and the
//! prediction from k to k + 1 use the same sample u_k, so that prediction's
//! noise is correlated with that update's (E[w·e] = σ_u²·g·∂h/∂u); the
//! filters neglect it (with voltage drive σ_u·∂h/∂u = σ_v·k_e/(N² + R·k_e),
//! 1.5 % of σ_i for the perfect-tracking valve).
//!
//! **Timing.** A filter step at sample k takes (u, y_k): u is the input held
//! over the last sample ((t_{k−1}, t_k], what the controller applied after the
//! previous step) and y_k the output sampled at t_k, before the next input is
//! applied. It predicts the prior x_{k|k−1} from the last posterior with u
//! (zero-order hold, forward Euler (84c)), updates it with y_k (h at the same
//! held u: the eddy term k_e·u of the current) and reports the posterior,
//! which the controller uses at once. (Updating first and predicting with the
//! same u would use each input one sample late: in closed loop, where u
//! changes every sample, that lags the flux by T_s·N·Δu/(N² + R·k_e), 0.1 µWb
//! for 10 V on the perfect-tracking valve, and biased the position estimate
//! by 10–40 µm at the end of a stroke.)
//!
//! **Mode band.** (86) compares z with the limits; after a measurement update
//! the estimate of a resting armature sits within a few σ of w_z of its stop
//! (the correction moves it, the saturation of (84a) puts it back). The
//! estimate counts as resting when it is within [`MODE_BAND_SIGMAS`]·q_z of a
//! limit. The posterior z and z_prev are projected onto [z_min, z_max].
//!
//! **At a stop.** When the estimate is on a stop (mode 1 or 3) or reaches it
//! within the sample (its own prediction (84a) saturates there) and the free
//! acceleration f_v at the estimate points into that stop, the automaton's
//! lift-off guard does not fire and the armature stays (or, arriving, sticks
//! as (84a) has it): the prediction sets z⁺ = the stop for the estimate and
//! for every sigma point, with a zero row of ∂F/∂x for z (the EKF: what the
//! saturation (84a) of the estimate gives anyway); z_prev⁺ stays (84b), so
//! that v of (85) is the arrival's average velocity for one more sample,
//! then 0. Without it the UKF's sigma points below the stop (spread by the
//! measurement noise) are pushed back by f_v only slowly, the clamped ones
//! not at all, and the mean of the truncated spread hovers ≈ γ·σ_z off the
//! stop in mode 2 with a spurious velocity towards it. Only q_z then remains
//! of the position's uncertainty.

use std::collections::HashMap;

use crate::description::{Core, Drive};
use crate::model::{Model, Params};
use crate::sim::Mode;
use crate::sym::{Graph, Id, Tape};

/// The estimate counts as resting on a stop within this many q_z of it.
pub const MODE_BAND_SIGMAS: f64 = 3.0;

/// The saturating core is evaluated at |φ| ≤ (1 − this)·φ_sat.
pub const FLUX_DOMAIN_MARGIN: f64 = 1e-3;

/// The largest state the filters hold: [z, z_prev, φ, H_c] or [z, z_prev, φ, R].
pub const MAX_DIM: usize = 4;

/// What each state of the discretised model is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateKind {
    /// z [m]
    Position,
    /// z_prev [m], the position one sample earlier
    PreviousPosition,
    /// φ [Wb]
    Flux,
    /// H_c [A/m] (Jiles–Atherton core)
    CoreField,
    /// R [Ω], the coil resistance (with [`ResistanceSettings`])
    Resistance,
}

/// Coil-resistance estimation (`estimate_resistance = true` in
/// `[observer.kalman]`): R as a random-walk state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResistanceSettings {
    /// σ_Ṙ [Ω/s] (> 0): the random walk's rate; w_R has σ = σ_Ṙ·T_s per step.
    pub rate_std: f64,
    /// Initial σ of R [Ω] (> 0) around the description's value.
    pub initial_std: f64,
}

impl ResistanceSettings {
    /// The settings of `[observer.kalman]`, `None` unless it estimates R.
    pub fn from_observer(o: &crate::description::Observer) -> Option<ResistanceSettings> {
        let r = o.kalman.as_ref()?.resistance?;
        Some(ResistanceSettings {
            rate_std: r.rate_std,
            initial_std: r.initial_std,
        })
    }
}

/// The Kalman filters' settings (`[observer.kalman]` with σ_v, σ_i and T_s
/// of `[observer]`). Standard deviations are per sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanSettings {
    /// T_s [s] (> 0).
    pub sample_period: f64,
    /// σ_v [V] (> 0): noise of the measured coil voltage.
    pub voltage_noise: f64,
    /// σ_i [A] (> 0): noise of the measured coil current.
    pub current_noise: f64,
    /// σ of w_z [m] per step (> 0).
    pub process_z: f64,
    /// σ of w_φ [Wb] per step (> 0).
    pub process_phi: f64,
    /// σ of w_Hc [A/m] per step (> 0); exactly with the Jiles–Atherton core.
    pub process_hc: Option<f64>,
    /// Initial σ of z and z_prev [m] (> 0).
    pub initial_z_std: f64,
    /// Initial σ of φ [Wb] (> 0).
    pub initial_phi_std: f64,
    /// Initial σ of H_c [A/m] (> 0); exactly with the Jiles–Atherton core.
    pub initial_hc_std: Option<f64>,
    /// UKF spread α (> 0).
    pub ukf_alpha: f64,
    /// UKF β (≥ 0; 2 is optimal for Gaussian priors).
    pub ukf_beta: f64,
    /// UKF κ (n + κ > 0).
    pub ukf_kappa: f64,
}

/// Why a discretised model or filter could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KalmanError {
    #[error("observer.kalman: {name} = {value:e}: expected {expected}")]
    BadSetting {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error("observer.kalman: {0} is required with the Jiles–Atherton core (state H_c)")]
    MissingFieldSetting(&'static str),
    #[error("observer.kalman: {0} applies only to the Jiles–Atherton core (the model has no H_c)")]
    UnusedFieldSetting(&'static str),
    #[error("the symbol `{0}` the discretised model needs is already taken by the model")]
    NameTaken(String),
    #[error("observer.kalman: estimate_resistance with the Jiles–Atherton core needs 5 states [z, z_prev, φ, H_c, R]; the filters hold at most {MAX_DIM}")]
    TooManyStates,
    #[error("observer.kalman: {name} = {value:e}: expected a finite number > 0")]
    BadResistanceSetting { name: &'static str, value: f64 },
    #[error("estimate_resistance: the model has no coil resistance parameter `R`")]
    NoResistance,
}

impl KalmanSettings {
    /// The settings of the description's `[observer]` and
    /// `[observer.kalman]`; `None` without a kalman section.
    pub fn from_observer(o: &crate::description::Observer) -> Option<KalmanSettings> {
        let k = o.kalman.as_ref()?;
        Some(KalmanSettings {
            sample_period: o.sample_period,
            voltage_noise: o.voltage_noise,
            current_noise: o.current_noise,
            process_z: k.process_z,
            process_phi: k.process_phi,
            process_hc: k.process_hc,
            initial_z_std: k.initial_z_std,
            initial_phi_std: k.initial_phi_std,
            initial_hc_std: k.initial_hc_std,
            ukf_alpha: k.ukf_alpha,
            ukf_beta: k.ukf_beta,
            ukf_kappa: k.ukf_kappa,
        })
    }

    /// Checks every value (with or without the H_c state).
    pub fn validate(&self, has_field_state: bool) -> Result<(), KalmanError> {
        let check = |name: &'static str, value: f64, ok: bool, expected: &'static str| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(KalmanError::BadSetting {
                    name,
                    value,
                    expected,
                })
            }
        };
        let positive = |name, v: f64| check(name, v, v > 0.0, "a finite number > 0");
        positive("sample_period", self.sample_period)?;
        positive("voltage_noise", self.voltage_noise)?;
        positive("current_noise", self.current_noise)?;
        positive("process_z", self.process_z)?;
        positive("process_phi", self.process_phi)?;
        positive("initial_z_std", self.initial_z_std)?;
        positive("initial_phi_std", self.initial_phi_std)?;
        positive("ukf_alpha", self.ukf_alpha)?;
        check(
            "ukf_beta",
            self.ukf_beta,
            self.ukf_beta >= 0.0,
            "a finite number >= 0",
        )?;
        let n = if has_field_state { 4.0 } else { 3.0 };
        check(
            "ukf_kappa",
            self.ukf_kappa,
            n + self.ukf_kappa > 0.0,
            "n + kappa > 0 (n = number of states)",
        )?;
        for (name, v) in [
            ("process_hc", self.process_hc),
            ("initial_hc_std", self.initial_hc_std),
        ] {
            match (has_field_state, v) {
                (true, Some(v)) => positive(name, v)?,
                (true, None) => return Err(KalmanError::MissingFieldSetting(name)),
                (false, Some(_)) => return Err(KalmanError::UnusedFieldSetting(name)),
                (false, None) => {}
            }
        }
        Ok(())
    }

    /// The unscented transform's constants for n states.
    pub fn unscented(&self, n: usize) -> UnscentedWeights {
        let n = n as f64;
        let a2 = self.ukf_alpha * self.ukf_alpha;
        let lambda = a2 * (n + self.ukf_kappa) - n;
        let spread = n + lambda;
        let mean0 = lambda / spread;
        UnscentedWeights {
            gamma: spread.sqrt(),
            mean0,
            cov0: mean0 + (1.0 - a2 + self.ukf_beta),
            other: 0.5 / spread,
        }
    }
}

/// Weights of the unscented transform (Julier's scaled form): sigma points
/// x̄ ± γ·(columns of chol P), γ = √(n + λ), λ = α²(n + κ) − n.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnscentedWeights {
    pub gamma: f64,
    /// W₀ᵐ = λ/(n + λ)
    pub mean0: f64,
    /// W₀ᶜ = W₀ᵐ + 1 − α² + β
    pub cov0: f64,
    /// Wᵢ = 1/(2(n + λ)), i ≥ 1 (mean and covariance)
    pub other: f64,
}

/// The discretised model (84)–(87) as expressions in a graph of its own
/// (the model's graph plus the new symbols), parameters symbolic.
#[derive(Clone)]
pub struct DiscreteModel {
    pub graph: Graph,
    pub settings: KalmanSettings,
    /// The model's parameters plus T_s, z_min, z_max (and φ_lim with the
    /// saturating core), in that order.
    pub params: Params,
    /// x = [z, z_prev, φ] (+ H_c) (+ R).
    pub states: Vec<Id>,
    /// What each state is.
    pub kinds: Vec<StateKind>,
    /// R as a state, if estimated.
    pub resistance: Option<ResistanceSettings>,
    /// The description's coil resistance [Ω] (R's initial estimate).
    pub nominal_resistance: f64,
    /// u
    pub input: Id,
    /// t (only through the resistance drift).
    pub time: Id,
    /// Whether any expression depends on t.
    pub uses_time: bool,
    pub drive: Drive,
    /// (84): x_{k+1} = F(x_k, u_k), one expression per state.
    pub transition: Vec<Id>,
    /// (85) v = (z − z_prev)/T_s.
    pub velocity: Id,
    /// f_v(z, v, φ) with v of (85): the acceleration of (87) in mode 2.
    pub acceleration: Id,
    /// y = h(x, u): the measured coil quantity.
    pub measurement: Id,
    /// ∂F/∂x (rows).
    pub transition_jacobian: Vec<Vec<Id>>,
    /// g = ∂F/∂u.
    pub input_gain: Vec<Id>,
    /// ∂h/∂x.
    pub measurement_jacobian: Vec<Id>,
    /// ∂h/∂u.
    pub measurement_input_gain: Id,
    pub z_min: f64,
    pub z_max: f64,
    /// (86): the estimate rests on a stop within this distance of it.
    pub mode_band: f64,
    /// σ of the input's noise (voltage noise, or current noise with current drive).
    pub input_noise: f64,
    /// σ of the measurement's noise (current noise, or voltage noise with current drive).
    pub measurement_noise: f64,
}

/// Symbols the discretised model adds to the model's graph.
pub const Z_PREV: &str = "z_prev";
pub const T_S: &str = "T_s";
pub const Z_MIN: &str = "z_min";
pub const Z_MAX: &str = "z_max";
pub const PHI_LIM: &str = "phi_lim";

impl DiscreteModel {
    /// Discretises `model` with `settings` (validated here), R a parameter.
    pub fn new(model: &Model, settings: &KalmanSettings) -> Result<DiscreteModel, KalmanError> {
        DiscreteModel::with_resistance(model, settings, None)
    }

    /// The settings of the description's `[observer]`, `None` without a
    /// `[observer.kalman]` section.
    pub fn from_observer(
        model: &Model,
        o: &crate::description::Observer,
    ) -> Option<Result<DiscreteModel, KalmanError>> {
        let settings = KalmanSettings::from_observer(o)?;
        let r = ResistanceSettings::from_observer(o);
        Some(DiscreteModel::with_resistance(model, &settings, r))
    }

    /// Discretises `model` with `settings`, and R as a state when
    /// `resistance` is given (validated here).
    pub fn with_resistance(
        model: &Model,
        settings: &KalmanSettings,
        resistance: Option<ResistanceSettings>,
    ) -> Result<DiscreteModel, KalmanError> {
        settings.validate(model.has_field_state())?;
        let r_symbol = match resistance {
            Some(r) => Some(resistance_symbol(model, settings, &r)?),
            None => None,
        };
        let mut g = model.graph.clone();
        let mut params = model.params.clone();
        if let Some(r) = r_symbol {
            params = without(&mut g, &model.params, r);
        }
        let fresh = |g: &mut Graph, name: &str| {
            if g.find_symbol(name).is_some() {
                Err(KalmanError::NameTaken(name.to_owned()))
            } else {
                Ok(g.symbol(name))
            }
        };
        let mech = &model.description.mechanics;
        let z_prev = fresh(&mut g, Z_PREV)?;
        for name in [T_S, Z_MIN, Z_MAX, PHI_LIM] {
            fresh(&mut g, name)?;
        }
        let ts = params.add(&mut g, T_S, settings.sample_period);
        let z_lo = params.add(&mut g, Z_MIN, mech.z_min);
        let z_hi = params.add(&mut g, Z_MAX, mech.z_max);
        let phi_lim = match model.description.core {
            Core::Saturating { phi_sat, .. } => {
                Some(params.add(&mut g, PHI_LIM, (1.0 - FLUX_DOMAIN_MARGIN) * phi_sat))
            }
            _ => None,
        };

        let (z, v, phi) = (model.states[0], model.states[1], model.states[2]);
        let hc = model.states.get(3).copied();
        let u = model.input;

        // (85) v = (z − z_prev)/T_s
        let dz = g.sub(z, z_prev);
        let velocity = g.div(dz, ts);
        // the model's domain: z ∈ [z_min, z_max] (|φ| ≤ φ_lim)
        let z_dom = clamp(&mut g, z, z_lo, z_hi);
        let mut map: HashMap<Id, Id> = HashMap::new();
        map.insert(z, z_dom);
        map.insert(v, velocity);
        if let Some(lim) = phi_lim {
            let lo = g.neg(lim);
            let phi_dom = clamp(&mut g, phi, lo, lim);
            map.insert(phi, phi_dom);
        }
        let measured = match model.description.supply.drive {
            Drive::Voltage => model.current,
            Drive::Current => model.voltage,
        };
        let mut roots = model.f.clone();
        roots.push(measured);
        let subst = g.substitute_all(&roots, &map);
        let (f_v, f_phi, measurement) = (subst[1], subst[2], subst[model.dim()]);

        // (84a) z⁺ = sat(2z − z_prev + T_s²·f_v)
        let two_z = g.scale(2.0, z);
        let ts2 = g.powi(ts, 2);
        let step = g.mul(ts2, f_v);
        let neg_prev = g.neg(z_prev);
        let raw = g.sum(&[two_z, neg_prev, step]);
        let z_next = clamp(&mut g, raw, z_lo, z_hi);
        // (84c) φ⁺ = φ + T_s·f_φ
        let dphi = g.mul(ts, f_phi);
        let phi_next = g.add(phi, dphi);
        // (84b) z_prev⁺ = z, as sat(z): the same for every state (84a) gives,
        // and no spurious velocity (85) from sigma points beyond a stop
        let mut states = vec![z, z_prev, phi];
        let mut kinds = vec![
            StateKind::Position,
            StateKind::PreviousPosition,
            StateKind::Flux,
        ];
        let mut transition = vec![z_next, z_dom, phi_next];
        if let Some(hc) = hc {
            // (84d) H_c⁺ = H_c + T_s·f_Hc
            let dh = g.mul(ts, subst[3]);
            states.push(hc);
            kinds.push(StateKind::CoreField);
            transition.push(g.add(hc, dh));
        }
        if let Some(r) = r_symbol {
            // R⁺ = R: a random walk (its noise is in Q)
            states.push(r);
            kinds.push(StateKind::Resistance);
            transition.push(r);
        }

        let transition_jacobian = g.jacobian(&transition, &states);
        let input_gain: Vec<Id> = transition.iter().map(|&f| g.diff(f, u)).collect();
        let measurement_jacobian = g.gradient(measurement, &states);
        let measurement_input_gain = g.diff(measurement, u);

        let mut all = transition.clone();
        all.extend([velocity, f_v, measurement, measurement_input_gain]);
        all.extend(transition_jacobian.iter().flatten());
        all.extend(&input_gain);
        all.extend(&measurement_jacobian);
        let uses_time = all.iter().any(|&e| g.depends_on(e, model.time));

        let drive = model.description.supply.drive;
        let (input_noise, measurement_noise) = match drive {
            Drive::Voltage => (settings.voltage_noise, settings.current_noise),
            Drive::Current => (settings.current_noise, settings.voltage_noise),
        };
        Ok(DiscreteModel {
            graph: g,
            settings: *settings,
            params,
            states,
            kinds,
            resistance,
            nominal_resistance: model.description.coil.resistance,
            input: u,
            time: model.time,
            uses_time,
            drive,
            transition,
            velocity,
            acceleration: f_v,
            measurement,
            transition_jacobian,
            input_gain,
            measurement_jacobian,
            measurement_input_gain,
            z_min: mech.z_min,
            z_max: mech.z_max,
            mode_band: MODE_BAND_SIGMAS * settings.process_z,
            input_noise,
            measurement_noise,
        })
    }

    /// Number of states (3, plus H_c, plus R).
    pub fn dim(&self) -> usize {
        self.states.len()
    }

    pub fn has_field_state(&self) -> bool {
        self.kinds.contains(&StateKind::CoreField)
    }

    /// Index of the state R, if estimated.
    pub fn resistance_index(&self) -> Option<usize> {
        self.kinds.iter().position(|&k| k == StateKind::Resistance)
    }

    /// Tape inputs: the states, u, then t.
    pub fn tape_inputs(&self) -> Vec<Id> {
        let mut inputs = self.states.clone();
        inputs.push(self.input);
        inputs.push(self.time);
        inputs
    }

    /// (symbol name, symbol, value) of every parameter, for emitters.
    pub fn param_list(&self) -> Vec<(&str, Id, f64)> {
        self.params.iter().collect()
    }

    /// Compiles `exprs` (parameters bound) to a tape of (x, u, t).
    pub fn compile(&self, exprs: &[Id]) -> Tape {
        let mut g = self.graph.clone();
        let map = self.params.bindings(&mut g);
        let bound = g.substitute_all(exprs, &map);
        Tape::compile(&g, &self.tape_inputs(), &bound)
            .expect("the discretised model only uses x, u, t and parameters")
    }

    /// The tapes both filters evaluate.
    pub fn tapes(&self) -> DiscreteTapes {
        let n = self.dim();
        let mut prediction = self.transition.clone();
        prediction.push(self.acceleration);
        let mut jacobian: Vec<Id> = self.transition_jacobian.iter().flatten().copied().collect();
        jacobian.extend(&self.input_gain);
        let mut measurement = vec![self.measurement, self.measurement_input_gain];
        measurement.extend(&self.measurement_jacobian);
        let (prediction, jacobian, measurement, input_gain, acceleration) = (
            self.compile(&prediction),
            self.compile(&jacobian),
            self.compile(&measurement),
            self.compile(&self.input_gain),
            self.compile(&[self.acceleration]),
        );
        DiscreteTapes {
            n,
            scratch: [
                prediction.scratch(),
                jacobian.scratch(),
                measurement.scratch(),
                input_gain.scratch(),
                acceleration.scratch(),
            ],
            prediction,
            jacobian,
            measurement,
            input_gain,
            acceleration,
            inputs: [0.0; 6],
        }
    }

    /// x₀: at rest at z_max (z = z_prev = z_max), φ = 0, H_c = 0, R = the
    /// description's.
    pub fn initial_state(&self) -> [f64; 4] {
        let mut x = [self.z_max, self.z_max, 0.0, 0.0];
        if let Some(i) = self.resistance_index() {
            x[i] = self.nominal_resistance;
        }
        x
    }

    /// P₀: the armature is known to start at rest, so z and z_prev share
    /// the initial uncertainty σ_z0 (fully correlated: v = 0), each with the
    /// per-step variance q_z² added so that P₀ is positive definite:
    /// [[σ_z0² + q_z², σ_z0²], [σ_z0², σ_z0² + q_z²]]; then σ_φ0², σ_Hc0² on
    /// the diagonal (and σ_R0² for R).
    pub fn initial_covariance(&self) -> [[f64; 4]; 4] {
        let s = &self.settings;
        let z2 = s.initial_z_std * s.initial_z_std;
        let q2 = s.process_z * s.process_z;
        let mut p = [[0.0; 4]; 4];
        p[0] = [z2 + q2, z2, 0.0, 0.0];
        p[1] = [z2, z2 + q2, 0.0, 0.0];
        for (i, kind) in self.kinds.iter().enumerate() {
            let sd = match kind {
                StateKind::Flux => s.initial_phi_std,
                StateKind::CoreField => s.initial_hc_std.unwrap_or(0.0),
                StateKind::Resistance => self.resistance.map_or(0.0, |r| r.initial_std),
                StateKind::Position | StateKind::PreviousPosition => continue,
            };
            p[i][i] = sd * sd;
        }
        p
    }

    /// The lower Cholesky factor of P₀ (P₀ is positive definite by
    /// construction: σ_z0²·[[1, 1], [1, 1]] + q_z²·I and positive variances).
    pub fn initial_factor(&self) -> [[f64; 4]; 4] {
        dense::cholesky(self.dim(), &self.initial_covariance())
            .expect("P₀ is positive definite by construction")
    }

    /// diag(q_z², 0, q_φ², q_Hc², (σ_Ṙ·T_s)²): the part of Q that does not
    /// come from u.
    pub fn process_variance(&self) -> [f64; 4] {
        let s = &self.settings;
        let mut q = [0.0; 4];
        for (i, kind) in self.kinds.iter().enumerate() {
            let sd = match kind {
                StateKind::Position => s.process_z,
                StateKind::PreviousPosition => 0.0,
                StateKind::Flux => s.process_phi,
                StateKind::CoreField => s.process_hc.unwrap_or(0.0),
                StateKind::Resistance => self
                    .resistance
                    .map_or(0.0, |r| r.rate_std * s.sample_period),
            };
            q[i] = sd * sd;
        }
        q
    }

    /// (86) with the band: the discrete mode of the estimate z.
    pub fn mode(&self, z: f64) -> Mode {
        mode_of(z, self.z_min, self.z_max, self.mode_band)
    }
}

/// The model's symbol R checked for use as a state: valid settings, room in
/// [`MAX_DIM`], and a parameter called R.
fn resistance_symbol(
    model: &Model,
    settings: &KalmanSettings,
    r: &ResistanceSettings,
) -> Result<Id, KalmanError> {
    for (name, value) in [
        ("resistance_rate_std", r.rate_std),
        ("initial_resistance_std", r.initial_std),
    ] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(KalmanError::BadResistanceSetting { name, value });
        }
    }
    if model.has_field_state() {
        return Err(KalmanError::TooManyStates);
    }
    // n = 4 with R: the unscented transform needs n + κ > 0
    if 4.0 + settings.ukf_kappa <= 0.0 {
        return Err(KalmanError::BadSetting {
            name: "ukf_kappa",
            value: settings.ukf_kappa,
            expected: "n + kappa > 0 (n = number of states)",
        });
    }
    model.params.symbol("R").ok_or(KalmanError::NoResistance)
}

/// `params` without the symbol `skip` (which becomes a state).
fn without(g: &mut Graph, params: &Params, skip: Id) -> Params {
    let mut out = Params::default();
    for (name, id, value) in params.iter() {
        if id != skip {
            out.add(g, name, value);
        }
    }
    out
}

/// z projected onto [lo, hi] (NaN stays NaN).
pub(crate) fn project(z: f64, lo: f64, hi: f64) -> f64 {
    if z < lo {
        lo
    } else if z > hi {
        hi
    } else {
        z
    }
}

/// The stop the estimate stays on over the next sample, if any: the free
/// acceleration f_v at the estimate points into a stop (the automaton's
/// lift-off guard does not fire) and the estimate is on it by its mode (86),
/// or reaches it within the sample (its own prediction (84a) `z_next`
/// saturates there). A NaN acceleration stays nowhere.
pub(crate) fn resting_stop(mode: Mode, accel: f64, z_next: f64, lo: f64, hi: f64) -> Option<f64> {
    if accel <= 0.0 && (mode == Mode::StuckMin || z_next == lo) {
        Some(lo)
    } else if accel >= 0.0 && (mode == Mode::StuckMax || z_next == hi) {
        Some(hi)
    } else {
        None
    }
}

/// (86) with the band (a NaN z counts as moving).
pub(crate) fn mode_of(z: f64, lo: f64, hi: f64, band: f64) -> Mode {
    if z <= lo + band {
        Mode::StuckMin
    } else if z >= hi - band {
        Mode::StuckMax
    } else {
        Mode::Free
    }
}

/// min(max(x, lo), hi).
fn clamp(g: &mut Graph, x: Id, lo: Id, hi: Id) -> Id {
    let m = g.max(x, lo);
    g.min(m, hi)
}

/// The discretised model compiled for f64 evaluation (parameters bound),
/// with scratch buffers: evaluations do not allocate.
#[derive(Clone, Debug)]
pub struct DiscreteTapes {
    n: usize,
    /// F(x, u) (n), then f_v (the acceleration).
    prediction: Tape,
    /// ∂F/∂x row by row (n²), then ∂F/∂u (n).
    jacobian: Tape,
    /// h, ∂h/∂u, then ∂h/∂x (n).
    measurement: Tape,
    /// ∂F/∂u (n).
    input_gain: Tape,
    /// f_v (87).
    acceleration: Tape,
    scratch: [Vec<f64>; 5],
    inputs: [f64; 6],
}

/// F(x, u) and the acceleration f_v at x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// x_{k+1} (first n entries used).
    pub next: [f64; 4],
    /// f_v(z, v, φ) at x_k.
    pub acceleration: f64,
}

/// h(x, u) and its derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasurementEval {
    pub y: f64,
    /// ∂h/∂u
    pub dy_du: f64,
    /// ∂h/∂x (first n used)
    pub dy_dx: [f64; 4],
}

impl DiscreteTapes {
    pub fn dim(&self) -> usize {
        self.n
    }

    fn set_inputs(&mut self, x: &[f64; 4], u: f64, t: f64) -> usize {
        let n = self.n;
        self.inputs[..n].copy_from_slice(&x[..n]);
        self.inputs[n] = u;
        self.inputs[n + 1] = t;
        n + 2
    }

    /// (84), and f_v at x.
    pub fn predict(&mut self, x: &[f64; 4], u: f64, t: f64) -> Prediction {
        let m = self.set_inputs(x, u, t);
        let mut out = [0.0; 5];
        let n = self.n;
        self.prediction
            .eval(&self.inputs[..m], &mut self.scratch[0], &mut out[..n + 1]);
        let mut next = [0.0; 4];
        next[..n].copy_from_slice(&out[..n]);
        Prediction {
            next,
            acceleration: out[n],
        }
    }

    /// ∂F/∂x and g = ∂F/∂u at (x, u).
    pub fn jacobian(&mut self, x: &[f64; 4], u: f64, t: f64) -> ([[f64; 4]; 4], [f64; 4]) {
        let m = self.set_inputs(x, u, t);
        let n = self.n;
        let mut out = [0.0; 20];
        self.jacobian.eval(
            &self.inputs[..m],
            &mut self.scratch[1],
            &mut out[..n * n + n],
        );
        let mut f = [[0.0; 4]; 4];
        for (i, row) in f.iter_mut().enumerate().take(n) {
            row[..n].copy_from_slice(&out[i * n..(i + 1) * n]);
        }
        let mut gain = [0.0; 4];
        gain[..n].copy_from_slice(&out[n * n..n * n + n]);
        (f, gain)
    }

    /// g = ∂F/∂u at (x, u).
    pub fn input_gain(&mut self, x: &[f64; 4], u: f64, t: f64) -> [f64; 4] {
        let m = self.set_inputs(x, u, t);
        let n = self.n;
        let mut gain = [0.0; 4];
        self.input_gain
            .eval(&self.inputs[..m], &mut self.scratch[3], &mut gain[..n]);
        gain
    }

    /// f_v(z, v, φ) of (87) at x (v of (85)).
    pub fn acceleration(&mut self, x: &[f64; 4], u: f64, t: f64) -> f64 {
        let m = self.set_inputs(x, u, t);
        let mut out = [0.0; 1];
        self.acceleration
            .eval(&self.inputs[..m], &mut self.scratch[4], &mut out);
        out[0]
    }

    /// h, ∂h/∂u, ∂h/∂x at (x, u).
    pub fn measure(&mut self, x: &[f64; 4], u: f64, t: f64) -> MeasurementEval {
        let m = self.set_inputs(x, u, t);
        let n = self.n;
        let mut out = [0.0; 6];
        self.measurement
            .eval(&self.inputs[..m], &mut self.scratch[2], &mut out[..n + 2]);
        let mut dy_dx = [0.0; 4];
        dy_dx[..n].copy_from_slice(&out[2..n + 2]);
        MeasurementEval {
            y: out[0],
            dy_du: out[1],
            dy_dx,
        }
    }
}

/// What the filters output at each sample: the posterior estimate, which is
/// what the controllers consume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// z [m]
    pub z: f64,
    /// v [m/s] of (85)
    pub v: f64,
    /// a [m/s²] of (87)
    pub a: f64,
    /// φ [Wb]
    pub phi: f64,
    /// H_c [A/m] (Jiles–Atherton core only)
    pub hc: Option<f64>,
    /// R [Ω] (when estimated)
    pub r: Option<f64>,
    /// (86), with the band of [`DiscreteModel::mode_band`]
    pub mode: Mode,
}

/// Small dense algebra on the leading n×n block of 4×4 arrays, in the same
/// summation order as `reldesign_runtime::linalg` (left to right), so that
/// the reference filters and the generated ones round alike.
#[allow(clippy::needless_range_loop)]
pub(crate) mod dense {
    pub type M4 = [[f64; 4]; 4];

    pub fn dot(n: usize, a: &[f64; 4], b: &[f64; 4]) -> f64 {
        let mut s = 0.0;
        for k in 0..n {
            s += a[k] * b[k];
        }
        s
    }

    pub fn mat_vec(n: usize, a: &M4, x: &[f64; 4]) -> [f64; 4] {
        let mut y = [0.0; 4];
        for i in 0..n {
            y[i] = dot(n, &a[i], x);
        }
        y
    }

    pub fn transpose(n: usize, a: &M4) -> M4 {
        let mut t = [[0.0; 4]; 4];
        for i in 0..n {
            for j in 0..n {
                t[j][i] = a[i][j];
            }
        }
        t
    }

    /// A·Bᵀ
    pub fn mul_transpose(n: usize, a: &M4, b: &M4) -> M4 {
        let mut c = [[0.0; 4]; 4];
        for i in 0..n {
            for j in 0..n {
                c[i][j] = dot(n, &a[i], &b[j]);
            }
        }
        c
    }

    pub fn mat_mul(n: usize, a: &M4, b: &M4) -> M4 {
        mul_transpose(n, a, &transpose(n, b))
    }

    pub fn symmetrize(n: usize, a: &mut M4) {
        let t = transpose(n, a);
        for i in 0..n {
            for j in 0..n {
                a[i][j] = (a[i][j] + t[i][j]) * 0.5;
            }
        }
    }

    /// F·P·Fᵀ, symmetrised.
    pub fn sandwich(n: usize, f: &M4, p: &M4) -> M4 {
        let mut s = mul_transpose(n, &mat_mul(n, f, p), f);
        symmetrize(n, &mut s);
        s
    }

    /// P + α·(xᵢ·xⱼ)
    pub fn rank1_update(n: usize, p: &mut M4, alpha: f64, x: &[f64; 4]) {
        for i in 0..n {
            for j in 0..n {
                p[i][j] += alpha * (x[i] * x[j]);
            }
        }
    }

    pub fn axpy(n: usize, y: &mut [f64; 4], alpha: f64, x: &[f64; 4]) {
        for i in 0..n {
            y[i] += alpha * x[i];
        }
    }

    /// (I − k·hᵀ)·P·(I − k·hᵀ)ᵀ + r·k·kᵀ
    pub fn joseph_update(n: usize, p: &M4, k: &[f64; 4], h: &[f64; 4], r: f64) -> M4 {
        let mut a = [[0.0; 4]; 4];
        for i in 0..n {
            for j in 0..n {
                let id = if i == j { 1.0 } else { 0.0 };
                a[i][j] = id - k[i] * h[j];
            }
        }
        let mut out = sandwich(n, &a, p);
        rank1_update(n, &mut out, r, k);
        out
    }

    /// Lower Cholesky factor, `None` if a pivot is not positive and finite.
    pub fn cholesky(n: usize, a: &M4) -> Option<M4> {
        let mut l = [[0.0; 4]; 4];
        for i in 0..n {
            for j in 0..=i {
                let mut s = 0.0;
                for k in 0..j {
                    s += l[i][k] * l[j][k];
                }
                let s = a[i][j] - s;
                if j == i {
                    if s <= 0.0 || !s.is_finite() {
                        return None;
                    }
                    l[i][i] = s.sqrt();
                } else {
                    l[i][j] = s / l[j][j];
                }
            }
        }
        Some(l)
    }

    pub fn all_finite(n: usize, x: &[f64; 4]) -> bool {
        x[..n].iter().all(|v| v.is_finite())
    }

    pub fn all_finite_matrix(n: usize, a: &M4) -> bool {
        a[..n].iter().all(|r| all_finite(n, r))
    }
}
