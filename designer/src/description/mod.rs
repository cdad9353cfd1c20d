//! The actuator description (`valve.toml`): typed, validated values.
//!
//! The file format is the contract of `shared/spec/actuator.md`. Parsing
//! (`parse.rs`) turns text into a [`Description`] or a [`DescriptionError`]
//! that names the file, the key, the line/column and what was expected.
//! Everything downstream (model, simulator, designers) reads only these types.

mod error;
mod gains;
pub mod params;
mod parse;
pub mod schema;

pub use error::DescriptionError;
pub use gains::{settling_time_within, triple_pole_settling_product};
pub use parse::{parse_file, parse_str};

/// A whole, validated actuator description. All quantities SI.
#[derive(Debug, Clone, PartialEq)]
pub struct Description {
    /// Identifier used for generated module/type names.
    pub name: String,
    pub coil: Coil,
    pub gap: Gap,
    pub core: Core,
    pub mechanics: Mechanics,
    pub supply: Supply,
    /// `[trajectory]`: the soft-landing references to design (optional).
    pub trajectory: Option<Trajectory>,
    /// `[controller]`: the control law to design and emit (optional).
    pub controller: Option<Controller>,
    /// `[observer]`: the estimators to design and emit (optional).
    pub observer: Option<Observer>,
    /// Where the description came from (file name as given, full text).
    pub source: Source,
    /// What the parser accepts but advises against, each as
    /// `file:line:column: key: message` (the CLI prints them).
    pub warnings: Vec<String>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    pub file_name: String,
    pub text: String,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Coil {
    /// N, number of turns (> 0).
    pub turns: f64,
    /// R [Ω] (> 0).
    pub resistance: f64,
    /// k_e [A/V] (≥ 0): eddy current i_ec = −k_e·dφ/dt.
    pub eddy: f64,
    /// dR/dt [Ω/s], self-heating; 0 when absent.
    pub resistance_drift: f64,
}

/// Air-gap reluctance model R_gap(z).
#[derive(Debug, Clone, PartialEq)]
pub enum Gap {
    /// R_gap = offset + slope·z.
    Linear { slope: f64, offset: f64 },
    /// McLyman fringing: R_gap = (z/(μ0·A)) / (1 + z/√A · ln(2·l_w/z)).
    McLyman { area: f64, winding_length: f64 },
    /// R_gap = r0 + r0_prime·z / (1 + k1·z·ln(k2/z)).
    McLymanFit {
        r0: f64,
        r0_prime: f64,
        k1: f64,
        k2: f64,
    },
    /// Tabulated, strictly increasing z (≥ 4 points) and r; optional r'.
    Table {
        z: Vec<f64>,
        r: Vec<f64>,
        r_prime: Option<Vec<f64>>,
    },
}

/// Iron-path model.
#[derive(Debug, Clone, PartialEq)]
pub enum Core {
    /// R_core = r0.
    Linear { r0: f64 },
    /// Fröhlich–Kennelly: R_core = r0 / (1 − |φ|/phi_sat).
    Saturating { r0: f64, phi_sat: f64 },
    /// Inverse Jiles–Atherton core (adds the state H_c).
    JilesAtherton(JilesAtherton),
}

#[derive(Debug, Clone, PartialEq)]
pub struct JilesAtherton {
    /// l_c [m]
    pub length: f64,
    /// A_c [m²]
    pub area: f64,
    /// M_sat [A/m]
    pub m_sat: f64,
    /// b [T]
    pub b: f64,
    /// c [-], in [0, 1)
    pub c: f64,
    /// κ [A/m]
    pub kappa: f64,
    /// α [-]
    pub alpha: f64,
    /// ε of [JA 52] (default 1e-3)
    pub epsilon: f64,
    /// What the irreversible magnetisation does while it lags the field's
    /// new direction after a reversal (`core.reversal`).
    pub reversal: Reversal,
}

/// `core.reversal`: the irreversible magnetisation's rate [JA 26] where
/// δ·(M_an − M_irr) < 0 (just after sgn φ̇ changes).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Reversal {
    /// [JA 26] as it stands, with the clamp [JA 52]: the core's field jumps
    /// to the physical region at a rate |Ḣ_c| ≫ |φ̇| (the paper's model).
    #[default]
    Clamp,
    /// dM_irr/dB_e = 0 there: the core moves reversibly through a reversal,
    /// until M_an crosses M_irr (the usual correction of the Jiles–Atherton
    /// model against negative susceptibility).
    Reversible,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Mechanics {
    /// m [kg] (> 0)
    pub mass: f64,
    /// k_s [N/m] (≥ 0)
    pub stiffness: f64,
    /// c [N·s/m] (≥ 0)
    pub damping: f64,
    /// F0 [N], resolved: `preload`, or −k_s·rest_position.
    pub preload: f64,
    pub z_min: f64,
    pub z_max: f64,
    /// γ in [0, 1]
    pub restitution: f64,
    /// v_ε [m/s] (≥ 0)
    pub bounce_threshold: f64,
}

impl Mechanics {
    /// The passive force at rest at `z`, F(z, 0) = k_s·z + F0 [PT 10] [N]
    /// (positive: towards z_min).
    pub fn passive_at_rest(&self, z: f64) -> f64 {
        self.stiffness * z + self.preload
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Drive {
    /// Input u is the coil voltage; output is the coil current.
    Voltage,
    /// Input u is the coil current; output is the coil voltage.
    Current,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Supply {
    pub drive: Drive,
    pub u_min: f64,
    pub u_max: f64,
}

/// A switching operation: which way the armature moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Operation {
    /// z_max → z_min
    Closing,
    /// z_min → z_max
    Opening,
}

/// Shape of the motion z_m(t) on [takeoff, landing].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// 5th-degree polynomial (perfect-tracking-soft-landing [PT 52–53]).
    Polynomial,
    /// Minimum ∫u² dt with |u| ≤ u_bound ([PT 58–66]).
    EnergyOptimal,
}

/// `[trajectory]`: times are measured from the start of each operation.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// One or both operations, each designed separately (no duplicates).
    pub operations: Vec<Operation>,
    /// t₀ [s]: end of the pre-movement stage, start of the motion (> 0).
    pub takeoff: f64,
    /// t_f [s]: end of the motion (> takeoff).
    pub landing: f64,
    pub shape: Shape,
    /// Input bound used to design the trajectory [V or A] (> 0, at most the
    /// supply limits' magnitude), leaving the rest to the feedback.
    pub u_bound: f64,
    /// σ [m]: the spread of each designed stop's position into the stroke
    /// (half-normal of scale σ); 0: the stops are where the mechanics says.
    pub contact_uncertainty: f64,
    /// δ [m]: the move ends this far short of each stop, at rest, and the
    /// reference approaches the stop at `approach_speed` (`trajectory/approach.rs`);
    /// 0: it lands at rest on the stop.
    pub standoff: f64,
    /// v_c [m/s] of the approach (given exactly where `standoff` > 0).
    pub approach_speed: Option<f64>,
}

/// The approach's part of the motion: its ramp time over δ/v_c.
const RAMP_PER_STANDOFF_TIME: f64 = 0.5;

/// δ and v_c of `[trajectory]` (`standoff`, `approach_speed`): the move ends
/// at rest δ short of each stop and the reference approaches it at v_c
/// (`design/trajectory/approach.rs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Approach {
    /// δ [m] (> 0): how far short of the stop the move ends.
    pub standoff: f64,
    /// v_c [m/s] (> 0): the speed at which the stop is approached.
    pub speed: f64,
}

impl Approach {
    /// The ramp's duration τ_r [s].
    pub fn ramp(&self) -> f64 {
        RAMP_PER_STANDOFF_TIME * self.standoff / self.speed
    }

    /// t_f − t_s [s]: the ramp and the constant-speed run, 5·δ/(4·v_c).
    pub fn duration(&self) -> f64 {
        self.standoff / self.speed + 0.5 * self.ramp()
    }

    /// The approach's knots for a landing at `tf`: t_s, where the move ends
    /// and the ramp starts, and the ramp's end.
    pub fn knots(&self, tf: f64) -> [f64; 2] {
        let start = tf - self.duration();
        [start, start + self.ramp()]
    }

    /// The move's end z_s and time t_s for an operation from `z0` to the stop
    /// `zf` landing at `tf`.
    pub fn move_end(&self, z0: f64, zf: f64, tf: f64) -> (f64, f64) {
        let direction = (zf - z0).signum();
        let [start, _] = self.knots(tf);
        (zf - direction * self.standoff, start)
    }
}

impl Trajectory {
    /// The motion [t₀, t_f] must span at least this many sample periods for
    /// a sampled controller to track it.
    pub const MIN_SAMPLES_PER_MOTION: f64 = 10.0;

    /// The longest sample period the motion allows:
    /// (t_f − t₀)/[`Trajectory::MIN_SAMPLES_PER_MOTION`].
    pub fn longest_sample_period(&self) -> f64 {
        (self.landing - self.takeoff) / Self::MIN_SAMPLES_PER_MOTION
    }

    /// The approach, where the reference stops short of the stops.
    pub fn approach(&self) -> Option<Approach> {
        match (self.standoff, self.approach_speed) {
            (standoff, Some(speed)) if standoff > 0.0 => Some(Approach { standoff, speed }),
            _ => None,
        }
    }
}

/// How the gains K of the tracking law [PT 48] are given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gains {
    /// 5 % settling time [s] of the error dynamics with a triple real pole.
    SettlingTime(f64),
    /// The three closed-loop poles [1/s] (real parts < 0; real poles).
    Poles([f64; 3]),
}

/// Floating-point type of the emitted code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FloatType {
    F32,
    F64,
}

/// `[controller]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// The law and its own keys.
    pub law: Law,
    /// T_s [s] (> 0): the controller runs every sample period.
    pub sample_period: f64,
    /// Emitted variants, sorted, no duplicates (default: both).
    pub floats: Vec<FloatType>,
    /// Speed [m/s] (> 0) at which the reference creeps on beyond the end stop
    /// after t_f, so that an armature held short of it (a plant that differs
    /// from the model, a biased estimate) still lands, at about this speed.
    /// `None`: 2.5·10⁻³ of the stroke per motion time (`codegen`).
    pub creep_speed: Option<f64>,
    /// [m] (> 0): within this distance of its end stop the armature counts as
    /// in contact. `None`: 10⁻⁹ of the stroke (`design::law::decisions`).
    pub landed_band: Option<f64>,
    /// The observer of `[observer]` that drives the controller in the closed
    /// loops of `reldesign loop` and `sweep` (`Ekf` or `Ukf`); `None`: the
    /// controller reads the plant's state.
    pub estimator: Option<Estimator>,
    /// `compensate_resistance = true`: in the closed loops the law's voltage
    /// is corrected to the estimator's coil resistance, u + (R̂ − R)·i
    /// (`reldesign_runtime::resistance`); needs an estimator that estimates R.
    pub compensate_resistance: bool,
    /// `self_calibration = true`: the emitted code adapts the model's
    /// identifiable parameters from run to run, from the coil current
    /// (`designer::calibrate`, `reldesign_runtime::calibrate`).
    pub self_calibration: bool,
}

/// `controller.law` with the keys of that law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Law {
    /// u = α + β·(K·(ξ_r − T(x)) + z_r⁽³⁾), perfect-tracking-soft-landing [PT 50],
    /// with the gains K of [PT 48].
    FeedbackLinearization(Gains),
    /// u = u_max·sgn(φ)·sgn*(s), model-free-sliding-mode-soft-landing [SM 34–35],
    /// with the expert rules [SM 43].
    SlidingMode(SlidingSurface),
    /// u₂ of jiles-atherton-actuator-model [JA 89] on the surface [JA 88],
    /// with the mode rules and saturation to [0, u_max] of [JA 94].
    ModelSlidingMode(ModelSurface),
    /// Backstepping through the magnetic force, switched-force-backstepping
    /// [SB 19], with a certified region [SB Theorem 3] and the switching
    /// strategies [SB 28], [SB 31–33].
    Backstepping(BacksteppingKeys),
}

impl Law {
    /// The `controller.law` value.
    pub fn name(&self) -> &'static str {
        match self {
            Law::FeedbackLinearization(_) => "feedback-linearization",
            Law::SlidingMode(_) => "sliding-mode",
            Law::ModelSlidingMode(_) => "model-sliding-mode",
            Law::Backstepping(_) => "backstepping",
        }
    }
}

/// The sliding-mode law's keys (model-free-sliding-mode-soft-landing [SM §3]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlidingSurface {
    /// λ₁ [1/s] (> 0) of s = (λ₁ + d/dt)(λ₂ + d/dt)z̃ [SM 17].
    pub lambda1: f64,
    /// λ₂ [1/s] (> 0).
    pub lambda2: f64,
    /// η [m/s³] (> 0): the reaching condition s·ṡ ≤ −η·|s| [SM 20]; it enters
    /// the robustness bound [SM 49], not the emitted law.
    pub eta: f64,
    /// The current is kept ≥ 0 ([SM §5]): the emitted step reads the coil
    /// current instead of φ's sign, takes sgn φ = +1 and never drives the
    /// current below 0.
    pub nonnegative_current: bool,
}

/// The model-based sliding-mode law's keys (jiles-atherton-actuator-model
/// [JA §6.2]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelSurface {
    /// p [1/s] (> 0) of s = (p + d/dt)²(z − z_ref) [JA 88].
    pub p: f64,
    /// K [1/s] (> 0) of the reaching law ṡ = −K·s [JA 93].
    pub k: f64,
    /// z_ref [m]: a constant reference (a position hold); `None`: the
    /// references of `[trajectory]`.
    pub position: Option<f64>,
}

/// The backstepping law's keys (switched-force-backstepping [SB §III–IV]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BacksteppingKeys {
    /// α₁, α₂, α₃ [1/s] (> 0): z₂ = v + α₁·z₁ [SB 9], ż₂ = −z₁ − α₂·z₂
    /// [SB 14], Ḟ − Ḟ_d = −α₃·(F − F_d) [SB 18].
    pub gains: [f64; 3],
    pub switching: Switching,
    /// α [1/s] of AᵀP + PA ⪯ −α·P [SB Theorem 3]; `None`: the default
    /// (`design::law::backstepping::design`).
    pub decay: Option<f64>,
    pub reference: SetPoint,
}

/// What the backstepping law does where F_d < 0 (the magnet cannot push).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Switching {
    /// The local law everywhere [SB 19] (its output saturated).
    None,
    /// u = 0 until the state enters the region D, then the law [SB 28].
    Intuitive,
    /// The law while F_d > 0, u = 0 from F_d ≤ 0 until D, then the law
    /// [SB 31–33].
    Hybrid,
}

impl Switching {
    /// The `controller.switching` value.
    pub fn name(self) -> &'static str {
        match self {
            Switching::None => "none",
            Switching::Intuitive => "intuitive",
            Switching::Hybrid => "hybrid",
        }
    }
}

/// The backstepping law's reference y_r.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SetPoint {
    /// A constant position [m].
    Position(f64),
    /// `low` for the first half of each `period` [s], then `high` [m].
    Square { low: f64, high: f64, period: f64 },
}

impl SetPoint {
    /// The constant references, in the order they are first held.
    pub fn positions(&self) -> Vec<f64> {
        match *self {
            SetPoint::Position(z) => vec![z],
            SetPoint::Square { low, high, .. } => vec![low, high],
        }
    }
}

/// An estimator of `[observer].estimators`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Estimator {
    /// SEMERA, model-free Kalman estimation of r, l, λ ([SE Alg. 1]).
    Semera,
    /// The integral estimator with resistance update ([SE Alg. 2], [SE 47]).
    Integral,
    /// Extended Kalman filter on the actuator model.
    Ekf,
    /// Unscented Kalman filter on the actuator model.
    Ukf,
}

/// `[observer]`: what to estimate from the coil voltage and current, sampled
/// every `sample_period`.
#[derive(Debug, Clone, PartialEq)]
pub struct Observer {
    /// In the order given, non-empty, no duplicates.
    pub estimators: Vec<Estimator>,
    /// Δ [s] (> 0): the estimators run once per sample.
    pub sample_period: f64,
    /// Emitted variants, sorted, no duplicates (default: both).
    pub floats: Vec<FloatType>,
    /// σ_v [V] (> 0): standard deviation of the voltage measurement noise.
    pub voltage_noise: f64,
    /// σ_i [A] (> 0): standard deviation of the current measurement noise.
    pub current_noise: f64,
    /// `[observer.semera]`: present iff `estimators` has `Semera`.
    pub semera: Option<SemeraSettings>,
    /// `[observer.integral]`: present iff `estimators` has `Integral`.
    pub integral: Option<IntegralSettings>,
    /// `[observer.kalman]`: present iff `estimators` has `Ekf` or `Ukf`.
    pub kalman: Option<KalmanSection>,
}

/// `[observer.semera]`: the filter parameters of [SE Table II] (valve) /
/// [SE Table V] (relay), besides σ_v, σ_i and Δ of `[observer]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SemeraSettings {
    /// r̄₀ [Ω] (> 0): expected initial resistance, [SE 25].
    pub initial_resistance: f64,
    /// σ_r0 [Ω] (> 0): its standard deviation, [SE 26].
    pub initial_resistance_std: f64,
    /// l̄₀ [H] (> 0): expected inductance at rest, [SE 25]; also the expert rule's value.
    pub initial_inductance: f64,
    /// σ_l0 [H] (> 0): its standard deviation, [SE 26].
    pub initial_inductance_std: f64,
    /// σ_ṙ [Ω/s] (≥ 0): standard deviation of dr/dt, [SE 24].
    pub resistance_rate_std: f64,
    /// σ_l̈ [H/s²] (≥ 0): standard deviation of d²l/dt², [SE 24].
    pub inductance_accel_std: f64,
    /// n_σ (> 0): half-width of the current's noise confidence interval in σ_i.
    pub ci_sigmas: f64,
}

/// `[observer.integral]`: what [SE Alg. 2] needs besides σ_i and Δ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegralSettings {
    /// r̄₀ [Ω] (> 0): resistance used until the first update [SE 47].
    pub initial_resistance: f64,
    /// l̄₀ [H] (> 0): the inductance of the expert rule.
    pub initial_inductance: f64,
    /// λ₀ [Wb]: flux linkage at each reset (0 without permanent magnets; default 0).
    pub initial_flux_linkage: f64,
    /// n_σ (> 0): half-width of the current's noise confidence interval in σ_i.
    pub ci_sigmas: f64,
    /// [V] (> 0): an energizing operation starts where the measured voltage
    /// rises above this (default: half of `supply.u_max` with voltage drive).
    pub energize_threshold: f64,
}

/// `[observer.kalman]`: the model-based filters (EKF, UKF) on x = [z, φ(, H_c)].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanSection {
    /// Standard deviation of w_z per step [m] (> 0).
    pub process_z: f64,
    /// Standard deviation of w_φ per step [Wb] (> 0).
    pub process_phi: f64,
    /// Standard deviation of w_Hc per step [A/m] (> 0); only with a Jiles–Atherton core.
    pub process_hc: Option<f64>,
    /// Initial standard deviation of z [m] (> 0); the filter starts at rest at z_max.
    pub initial_z_std: f64,
    /// Initial standard deviation of φ [Wb] (> 0); the filter starts at φ = 0.
    pub initial_phi_std: f64,
    /// Initial standard deviation of H_c [A/m] (> 0); only with a Jiles–Atherton core.
    pub initial_hc_std: Option<f64>,
    /// UKF spread α in (0, 1] (default 1).
    pub ukf_alpha: f64,
    /// UKF β ≥ 0 (default 2).
    pub ukf_beta: f64,
    /// UKF κ (default 0).
    pub ukf_kappa: f64,
    /// `estimate_resistance = true`: the coil resistance as a random-walk state.
    pub resistance: Option<ResistanceEstimate>,
    /// `flux_step` (with `flux_substeps`).
    pub flux_step: FluxStep,
}

/// `observer.kalman.flux_step`: how the flux (and H_c) advance over one
/// sample (`observe::discrete::flux_step`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum FluxStep {
    /// [JA 84c]–[JA 84d]: forward Euler at the sample's position.
    #[default]
    Euler,
    /// Exponential Euler on the coil's total rate, `substeps` (in
    /// 1..=[`MAX_FLUX_SUBSTEPS`]) per sample at the moving position.
    Exponential { substeps: u32 },
}

/// The most substeps an exponential flux step takes per sample.
pub const MAX_FLUX_SUBSTEPS: u32 = 64;

/// `estimate_resistance = true` in `[observer.kalman]` with its two keys.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResistanceEstimate {
    /// `resistance_rate_std` σ_Ṙ [Ω/s] (> 0): w_R has σ = σ_Ṙ·T_s per sample.
    pub rate_std: f64,
    /// `initial_resistance_std` [Ω] (> 0), around `coil.resistance`.
    pub initial_std: f64,
}
