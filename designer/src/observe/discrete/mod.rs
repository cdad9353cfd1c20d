//! The discretised model of jiles-atherton-actuator-model [JA §6.1] ([JA 84–87]),
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
//! | [JA 85] velocity | v = (z − z_prev)/T_s |
//! | [JA 84a] position | z⁺ = sat_{z_min}^{z_max}(2z − z_prev + T_s²·f_v(z, v, φ)) |
//! | [JA 84b] previous position | z_prev⁺ = sat_{z_min}^{z_max}(z) (= z for every state [JA 84a] produces) |
//! | [JA 84c] flux | φ⁺ = φ + T_s·f_φ(z, φ, H_c, u) (or the exponential step of [`FluxStep`]) |
//! | [JA 84d] core field | H_c⁺ = H_c + T_s·f_Hc(z, φ, H_c, u) (or the exponential step) |
//! | coil resistance (optional) | R⁺ = R (random walk: w_R of σ = σ_Ṙ·T_s, as semera's q_r) |
//! | [JA 86] mode | 1 if z ≤ z_min + band, 3 if z ≥ z_max − band, else 2 |
//! | [JA 87] acceleration | a = f_v(z, v, φ) in mode 2, else 0 |
//! | measurement | y = h(z, φ, H_c, u): the coil current (voltage drive), the coil voltage (current drive) |
//!
//! f_v, f_φ, f_Hc and h are the model's expressions (`Model::f`,
//! `Model::current`/`Model::voltage`) with v replaced by [JA 85]. The model is
//! defined on [z_min, z_max] (and |φ| < φ_sat for the saturating core): the
//! filters evaluate it at z clamped to [z_min, z_max] (and φ clamped to
//! ±(1 − 10⁻³)·φ_sat), so that sigma points and corrections that leave the
//! domain give finite values (the McLyman logarithm is undefined below
//! z_min, R_core is infinite at φ_sat); [JA 84a] and [JA 85] use z itself. [JA 84b]
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
//! through [JA 84c–84d]; its noise is mapped into the process noise to first
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
//! (zero-order hold, the flux step of [`FluxStep`]), updates it with y_k (h at the same
//! held u: the eddy term k_e·u of the current) and reports the posterior,
//! which the controller uses at once. (Updating first and predicting with the
//! same u would use each input one sample late: in closed loop, where u
//! changes every sample, that lags the flux by T_s·N·Δu/(N² + R·k_e), 0.1 µWb
//! for 10 V on the perfect-tracking valve, and biased the position estimate
//! by 10–40 µm at the end of a stroke.)
//!
//! **Mode band.** [JA 86] compares z with the limits; after a measurement update
//! the estimate of a resting armature sits within a few σ of w_z of its stop
//! (the correction moves it, the saturation of [JA 84a] puts it back). The
//! estimate counts as resting when it is within [`MODE_BAND_SIGMAS`]·q_z of a
//! limit. The posterior z and z_prev are projected onto [z_min, z_max].
//!
//! **At a stop.** When the estimate is on a stop (mode 1 or 3) or reaches it
//! within the sample (its own prediction [JA 84a] saturates there) and the free
//! acceleration f_v at the estimate points into that stop, the automaton's
//! lift-off guard does not fire and the armature stays (or, arriving, sticks
//! as [JA 84a] has it): the prediction sets z⁺ = the stop for the estimate and
//! for every sigma point, with a zero row of ∂F/∂x for z (the EKF: what the
//! saturation [JA 84a] of the estimate gives anyway); z_prev⁺ stays [JA 84b], so
//! that v of [JA 85] is the arrival's average velocity for one more sample,
//! then 0. Without it the UKF's sigma points below the stop (spread by the
//! measurement noise) are pushed back by f_v only slowly, the clamped ones
//! not at all, and the mean of the truncated spread hovers ≈ γ·σ_z off the
//! stop in mode 2 with a spurious velocity towards it. Only q_z then remains
//! of the position's uncertainty. (The exponential flux step evaluates the
//! flux at positions between z and the unpinned z⁺ of [JA 84a]; the pin
//! comes after, so a sigma point's φ⁺ is the one of a motion up to the
//! stop plus the nm its prediction went beyond it.)
//!
//! | file | concept |
//! | --- | --- |
//! | `mod.rs` | the model [JA 84–87] in the symbolic core, its Jacobians, the runtime filters' settings |
//! | `flux_step.rs` | the exponential step of the electrical states ([`FluxStep`]; the Euler step [JA 84c–84d] is in `mod.rs`) and the coil's total rate |
//! | `settings.rs` | `[observer.kalman]`: [`KalmanSettings`], [`ResistanceSettings`], [`KalmanError`] |
//! | `tapes.rs` | the model on tapes, and [`TapeModel`]: the runtime's model traits for the reference filters |
//! | `estimate.rs` | the designer's [`Estimate`] |

mod estimate;
mod flux_step;
mod settings;
mod tapes;

use std::collections::HashMap;

use reldesign_runtime::linalg;
use reldesign_runtime::observe::Settings;

use crate::description::{Core, Drive};
use crate::model::{Model, Params};
use crate::sym::{Graph, Id, Tape};

pub use crate::description::FluxStep;
pub use estimate::Estimate;
pub use settings::{KalmanError, KalmanSettings, ResistanceSettings};
pub use tapes::{DiscreteTapes, MeasurementEval, Prediction, TapeModel};

/// The estimate counts as resting on a stop within this many q_z of it.
pub const MODE_BAND_SIGMAS: f64 = 3.0;

/// The saturating core is evaluated at |φ| ≤ (1 − this)·φ_sat.
pub const FLUX_DOMAIN_MARGIN: f64 = 1e-3;

/// The largest state the filters hold: [z, z_prev, φ, H_c, R].
pub const MAX_DIM: usize = 5;

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

/// The discretised model [JA 84–87] as expressions in a graph of its own
/// (the model's graph plus the new symbols), parameters symbolic.
#[derive(Clone)]
pub struct DiscreteModel {
    pub graph: Graph,
    pub settings: KalmanSettings,
    /// The model's parameters plus T_s, z_min, z_max (and φ_lim with the
    /// saturating core), in that order.
    pub params: Params,
    /// The model's own parameters (R among them even when it is a state: its
    /// value starts the estimate).
    pub model_params: Params,
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
    /// [JA 84]: x_{k+1} = F(x_k, u_k), one expression per state.
    pub transition: Vec<Id>,
    /// [JA 85] v = (z − z_prev)/T_s.
    pub velocity: Id,
    /// f_v(z, v, φ) with v of [JA 85]: the acceleration of [JA 87] in mode 2.
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
    /// [JA 86]: the estimate rests on a stop within this distance of it.
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
        if settings.flux_step == FluxStep::Euler {
            check_electrical_step(model, settings.sample_period)?;
        }
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

        // [JA 85] v = (z − z_prev)/T_s
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

        // [JA 84a] z⁺ = sat(2z − z_prev + T_s²·f_v)
        let two_z = g.scale(2.0, z);
        let ts2 = g.powi(ts, 2);
        let step = g.mul(ts2, f_v);
        let neg_prev = g.neg(z_prev);
        let raw = g.sum(&[two_z, neg_prev, step]);
        let z_next = clamp(&mut g, raw, z_lo, z_hi);
        let (phi_next, hc_next) = match settings.flux_step {
            FluxStep::Euler => {
                // [JA 84c] φ⁺ = φ + T_s·f_φ
                let dphi = g.mul(ts, f_phi);
                let phi_next = g.add(phi, dphi);
                // [JA 84d] H_c⁺ = H_c + T_s·f_Hc
                let hc_next = hc.map(|hc| {
                    let dh = g.mul(ts, subst[3]);
                    g.add(hc, dh)
                });
                (phi_next, hc_next)
            }
            FluxStep::Exponential { substeps } => {
                flux_step::exponential(&mut g, model, &map, (z_dom, z_next), ts, substeps)
            }
        };
        // [JA 84b] z_prev⁺ = z, as sat(z): the same for every state [JA 84a] gives,
        // and no spurious velocity [JA 85] from sigma points beyond a stop
        let mut states = vec![z, z_prev, phi];
        let mut kinds = vec![
            StateKind::Position,
            StateKind::PreviousPosition,
            StateKind::Flux,
        ];
        let mut transition = vec![z_next, z_dom, phi_next];
        if let (Some(hc), Some(hc_next)) = (hc, hc_next) {
            states.push(hc);
            kinds.push(StateKind::CoreField);
            transition.push(hc_next);
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
            model_params: model.params.clone(),
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
        self.compile_adaptive(exprs, &[])
    }

    /// Compiles `exprs` to a tape of (x, u, t, θ): the parameters `free`
    /// (θ, in order) left as inputs, every other one bound. φ_lim follows a
    /// free φ_sat (φ_lim = (1 − margin)·φ_sat) as the emitted adaptive model's.
    ///
    /// # Panics
    /// Where a free symbol is not a parameter of the model.
    pub fn compile_adaptive(&self, exprs: &[Id], free: &[Id]) -> Tape {
        let mut g = self.graph.clone();
        let mut map = self.params.bindings(&mut g);
        for id in free {
            assert!(map.remove(id).is_some(), "θ holds a parameter");
        }
        map.extend(self.flux_limit_following(&mut g, free));
        let bound = g.substitute_all(exprs, &map);
        let mut inputs = self.tape_inputs();
        inputs.extend_from_slice(free);
        Tape::compile(&g, &inputs, &bound)
            .expect("the discretised model only uses x, u, t and parameters")
    }

    /// φ_lim → (1 − margin)·φ_sat in `g` where φ_sat is among the adapted
    /// parameters `free`: the filter's flux domain follows θ (the designer's
    /// adaptive tapes and the emitted adaptive model alike); `None` otherwise.
    pub fn flux_limit_following(&self, g: &mut Graph, free: &[Id]) -> Option<(Id, Id)> {
        let lim = self.params.symbol(PHI_LIM)?;
        let sat = self.params.symbol("phi_sat").filter(|s| free.contains(s))?;
        let margin = g.constant(1.0 - FLUX_DOMAIN_MARGIN);
        Some((lim, g.mul(margin, sat)))
    }

    /// The symbol of each named parameter (`None` for a name that is not one,
    /// e.g. R where the filter estimates it).
    pub fn param_symbols(&self, names: &[&str]) -> Option<Vec<Id>> {
        names.iter().map(|n| self.params.symbol(n)).collect()
    }

    /// The tapes both filters evaluate.
    pub fn tapes(&self) -> DiscreteTapes {
        DiscreteTapes::new(self)
    }

    /// The settings of the runtime's filters, N the number of states
    /// ([`DiscreteModel::dim`]; panics on another N):
    ///
    /// - x₀: at rest at z_max (z = z_prev = z_max), φ = 0, H_c = 0, R = the
    ///   description's;
    /// - P₀: the armature is known to start at rest, so z and z_prev share
    ///   the initial uncertainty σ_z0 (fully correlated: v = 0), each with the
    ///   per-step variance q_z² added so that P₀ is positive definite:
    ///   [[σ_z0² + q_z², σ_z0²], [σ_z0², σ_z0² + q_z²]]; then σ_φ0², σ_Hc0²
    ///   (σ_R0²) on the diagonal;
    /// - Q without the input's part: diag(q_z², 0, q_φ², q_Hc², (σ_Ṙ·T_s)²).
    pub fn filter_settings<const N: usize>(&self) -> Settings<f64, N> {
        assert_eq!(N, self.dim(), "the model has {} states", self.dim());
        let s = &self.settings;
        let (z2, q2) = (s.initial_z_std * s.initial_z_std, s.process_z * s.process_z);
        let mut x0 = [0.0; N];
        let mut p0 = [[0.0; N]; N];
        let mut q = [0.0; N];
        for (i, kind) in self.kinds.iter().enumerate() {
            let (initial, process) = match kind {
                StateKind::Position | StateKind::PreviousPosition => {
                    x0[i] = self.z_max;
                    p0[i][..2].copy_from_slice(&[z2, z2]);
                    p0[i][i] = z2 + q2;
                    let process = if *kind == StateKind::Position {
                        s.process_z
                    } else {
                        0.0
                    };
                    (None, process)
                }
                StateKind::Flux => (Some(s.initial_phi_std), s.process_phi),
                StateKind::CoreField => (s.initial_hc_std, s.process_hc.unwrap_or(0.0)),
                StateKind::Resistance => {
                    x0[i] = self.nominal_resistance;
                    let (sd0, rate) = self
                        .resistance
                        .map_or((0.0, 0.0), |r| (r.initial_std, r.rate_std));
                    (Some(sd0), rate * s.sample_period)
                }
            };
            if let Some(sd) = initial {
                p0[i][i] = sd * sd;
            }
            q[i] = process * process;
        }
        Settings {
            sample_period: s.sample_period,
            z_min: self.z_min,
            z_max: self.z_max,
            mode_band: self.mode_band,
            input_variance: self.input_noise * self.input_noise,
            measurement_variance: self.measurement_noise * self.measurement_noise,
            process_variance: q,
            initial_state: x0,
            initial_covariance: p0,
            field: self.kinds.iter().position(|&k| k == StateKind::CoreField),
            resistance: self.resistance_index(),
            unscented: s.unscented(N),
            // σ_z0²·[[1, 1], [1, 1]] + q_z²·I and positive variances
            initial_factor: linalg::cholesky(&p0).expect("P₀ is positive definite by construction"),
        }
    }

    /// chol P₀ (of [`DiscreteModel::filter_settings`]), row by row.
    pub fn initial_factor(&self) -> Vec<Vec<f64>> {
        fn rows<const N: usize>(m: [[f64; N]; N]) -> Vec<Vec<f64>> {
            m.iter().map(|r| r.to_vec()).collect()
        }
        match self.dim() {
            3 => rows(self.filter_settings::<3>().initial_factor),
            4 => rows(self.filter_settings::<4>().initial_factor),
            _ => rows(self.filter_settings::<5>().initial_factor),
        }
    }
}

/// [JA 84c] is forward Euler on the flux: stable while T_s/τ ≤ 2, with
/// 1/τ = −dφ̇/dφ the rate of the magnetic circuit. On a Jiles–Atherton core
/// the core's MMF l_c·H_c moves with φ through the field's own step
/// [JA 84d], so 1/τ = −(∂f_φ/∂φ + ∂f_φ/∂H_c·dH_c/dφ), dH_c/dφ = (∂f_Hc/∂u)/
/// (∂f_φ/∂u) on the rising branch. Checked at rest at both stops at φ = 0
/// (demagnetised): the operating point every loop starts from. (In
/// saturation τ is far shorter; the filters' measurement update keeps the
/// step there in practice, see `tests/tests/ja_ukf_long_run.rs`.)
fn check_electrical_step(model: &Model, sample_period: f64) -> Result<(), KalmanError> {
    let mut m = model.clone();
    let rate = flux_step::total_rate(&mut m.graph, model);
    let tape = m.compile(&[rate]);
    let mech = &m.description.mechanics;
    let mut out = [0.0];
    for z in [mech.z_min, mech.z_max] {
        let mut inputs = vec![0.0; m.dim() + 2];
        inputs[0] = z;
        // a small positive input: φ̇ > 0, the rising branch of sign(φ̇)
        if let Some(input) = inputs.get_mut(m.dim()) {
            *input = 1e-6;
        }
        tape.eval(&inputs, &mut tape.scratch(), &mut out);
        let tau = -1.0 / out[0];
        if tau > 0.0 && sample_period > 2.0 * tau {
            return Err(KalmanError::SampleTooLong {
                sample_period,
                tau,
                z,
            });
        }
    }
    Ok(())
}

/// The model's symbol R checked for use as a state: valid settings and a
/// parameter called R.
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
    // n = 4 (5 with H_c) with R: the unscented transform needs n + κ > 0
    let n = if model.has_field_state() { 5.0 } else { 4.0 };
    if n + settings.ukf_kappa <= 0.0 {
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

/// min(max(x, lo), hi).
fn clamp(g: &mut Graph, x: Id, lo: Id, hi: Id) -> Id {
    let m = g.max(x, lo);
    g.min(m, hi)
}
