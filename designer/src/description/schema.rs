//! Every key of the description, once: its dotted path, the model variant it
//! belongs to, its kind, domain, unit, model symbol, whether it is required
//! and what it means.
//!
//! This table is the single source of the description's keys. It feeds the
//! parser (the keys a section allows, each number's domain and unit, each
//! default; what a domain admits and its "expected …" text are written here,
//! once), `fit`'s parameter domains (`identify::params`), the unit comments
//! of the TOML editor (`edit.rs`), the model's symbols (`model::Params::key`),
//! the docs of the emitted parameter consts, and the generated reference
//! `docs/reference/description.md` (kept fresh by a test, as `generated/` is).

use std::fmt::Write as _;

/// What a number must satisfy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// Any finite number.
    Any,
    /// > 0
    Positive,
    /// < 0
    Negative,
    /// ≥ 0
    NonNegative,
    /// In [0, 1].
    Unit,
    /// In [0, 1).
    UnitOpen,
    /// In (0, 1].
    UnitLeftOpen,
    /// Strictly above the value of another key (its dotted path).
    Above(&'static str),
}

impl Domain {
    /// Whether `x` lies in the domain. `Above` is checked against the other
    /// key's value by the parser; here it asks only for a finite number.
    pub fn contains(self, x: f64) -> bool {
        self.admits(x, None)
    }

    /// Whether `x` lies in the domain, an `Above` domain's other key having
    /// the value `lower` (the parser's check; without it, any finite number).
    pub fn admits(self, x: f64, lower: Option<f64>) -> bool {
        x.is_finite()
            && match self {
                Domain::Any => true,
                Domain::Positive => x > 0.0,
                Domain::Negative => x < 0.0,
                Domain::NonNegative => x >= 0.0,
                Domain::Unit => (0.0..=1.0).contains(&x),
                Domain::UnitOpen => (0.0..1.0).contains(&x),
                Domain::UnitLeftOpen => x > 0.0 && x <= 1.0,
                Domain::Above(_) => match lower {
                    Some(lower) => x > lower,
                    None => true,
                },
            }
    }

    /// The bound alone ("> 0", "in [0, 1)"), none for `Any`: the rule
    /// column of the reference page.
    pub fn bound(self) -> Option<String> {
        match self {
            Domain::Any => None,
            Domain::Positive => Some("> 0".into()),
            Domain::Negative => Some("< 0".into()),
            Domain::NonNegative => Some("≥ 0".into()),
            Domain::Unit => Some("in [0, 1]".into()),
            Domain::UnitOpen => Some("in [0, 1)".into()),
            Domain::UnitLeftOpen => Some("in (0, 1]".into()),
            Domain::Above(other) => Some(format!("> `{other}`")),
        }
    }

    /// The "expected …" text of messages ("a number > 0").
    pub fn text(self) -> String {
        self.expected(None)
    }

    /// The "expected …" text, an `Above` domain's other key having the value
    /// `lower`: the parser names that key within its section and gives the
    /// value ("a number > z_min (= 0.001)"); without it, the key's path.
    pub fn expected(self, lower: Option<f64>) -> String {
        match self {
            Domain::Any => "a number".into(),
            Domain::Positive => "a number > 0".into(),
            Domain::Negative => "a number < 0".into(),
            Domain::NonNegative => "a number >= 0".into(),
            Domain::Unit => "a number in [0, 1]".into(),
            Domain::UnitOpen => "a number in [0, 1)".into(),
            Domain::UnitLeftOpen => "a number in (0, 1]".into(),
            Domain::Above(other) => match lower {
                Some(lower) => {
                    let name = other.rsplit_once('.').map_or(other, |(_, k)| k);
                    format!("a number > {name} (= {lower})")
                }
                None => format!("a number > {other}"),
            },
        }
    }
}

/// The TOML type of a key's value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Number,
    /// An array of numbers, each in the key's domain.
    Numbers,
    /// One string among these.
    Choice(&'static [&'static str]),
    /// A non-empty array of distinct strings among these.
    Names(&'static [&'static str]),
    Bool,
    /// An identifier string.
    Text,
    /// A sub-table.
    Section,
}

/// Whether a key must be given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Presence {
    Required,
    /// Optional, with this default.
    Default(f64),
    /// Optional; the text says what holds without it.
    Optional(&'static str),
    /// Required or refused depending on other keys; the text says when.
    When(&'static str),
}

/// One key of the description.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Key {
    /// Dotted path: `coil.resistance`, `observer.kalman.process_z`, `name`.
    pub path: &'static str,
    /// The section's `model` values (`[controller]`'s `law` values) this key
    /// belongs to (empty: every one).
    pub variants: &'static [&'static str],
    pub kind: Kind,
    pub domain: Domain,
    /// SI unit ("-" for dimensionless, "" for non-numbers).
    pub unit: &'static str,
    /// The symbol of the parameter in the symbolic model (and the emitted
    /// const), where the key is one.
    pub symbol: Option<&'static str>,
    pub presence: Presence,
    /// A physical parameter `fit` may vary.
    pub fittable: bool,
    pub meaning: &'static str,
}

impl Key {
    /// The section part of the path ("" at the top level).
    pub fn section(&self) -> &'static str {
        self.path.rsplit_once('.').map_or("", |(s, _)| s)
    }

    /// The last part of the path.
    pub fn name(&self) -> &'static str {
        self.path.rsplit_once('.').map_or(self.path, |(_, k)| k)
    }

    /// Whether the key exists with the section's `model` = `variant`.
    pub fn in_variant(&self, variant: Option<&str>) -> bool {
        self.variants.is_empty() || variant.is_some_and(|v| self.variants.contains(&v))
    }
}

/// The `[controller]` keys of each law.
const FL: &[&str] = &["feedback-linearization"];
const SM: &[&str] = &["sliding-mode"];
const MSM: &[&str] = &["model-sliding-mode"];
const BS: &[&str] = &["backstepping"];
/// Laws that hold a constant `position`.
const HOLDS: &[&str] = &["model-sliding-mode", "backstepping"];

/// Every key, in the order of the reference (one key per line: a table).
#[rustfmt::skip]
pub const KEYS: &[Key] = &[
    text("name", "identifier used for the generated module and type names ([A-Za-z_][A-Za-z0-9_-]*)"),
    section("coil", Presence::Required, "the coil"),
    section("gap", Presence::Required, "the air-gap reluctance R_gap(z)"),
    section("core", Presence::Required, "the iron path's MMF"),
    section("mechanics", Presence::Required, "the armature and its stops"),
    section("supply", Presence::Required, "the drive"),
    section("trajectory", Presence::Optional("no reference is designed"), "the soft-landing references to design"),
    section("controller", Presence::Optional("no controller is emitted"), "the control law to design and emit (needs [trajectory])"),
    section("observer", Presence::Optional("no observer is emitted"), "the estimators to design and emit"),
    // [coil]
    param("coil.turns", "N", Domain::Positive, "turns", "number of turns"),
    param("coil.resistance", "R", Domain::Positive, "Ω", "coil resistance"),
    param("coil.eddy", "k_e", Domain::NonNegative, "A/V", "eddy-current constant: i_ec = −k_e·dφ/dt (0 = none)"),
    Key { presence: Presence::Default(0.0), ..param("coil.resistance_drift", "R_drift", Domain::Any, "Ω/s", "dR/dt, the resistance's drift (self-heating)") },
    // [gap]
    choice("gap.model", &["linear", "mclyman", "mclyman-fit", "table"], "the gap model"),
    Key { variants: &["linear"], ..param("gap.slope", "k_gap", Domain::Positive, "H⁻¹/m", "R_gap = offset + slope·z") },
    Key { variants: &["linear"], presence: Presence::Default(0.0), ..param("gap.offset", "R_gap0", Domain::NonNegative, "H⁻¹", "R_gap at z = 0") },
    Key { variants: &["mclyman"], ..param("gap.area", "A_gap", Domain::Positive, "m²", "pole-face area A of the McLyman fringing gap: R_gap = (z/(μ0·A)) / (1 + z/√A·ln(2·l_w/z))") },
    Key { variants: &["mclyman"], ..param("gap.winding_length", "l_w", Domain::Positive, "m", "winding length l_w of the McLyman fringing factor") },
    Key { variants: &["mclyman-fit"], ..param("gap.r0", "R_g0", Domain::NonNegative, "H⁻¹", "R_gap = r0 + r0_prime·z / (1 + k1·z·ln(k2/z)): the reluctance at z = 0") },
    Key { variants: &["mclyman-fit"], ..param("gap.r0_prime", "R_g0_prime", Domain::Positive, "H⁻¹/m", "the fitted gap's slope without fringing") },
    Key { variants: &["mclyman-fit"], ..param("gap.k1", "k1", Domain::NonNegative, "1/m", "the fitted gap's fringing gain") },
    Key { variants: &["mclyman-fit"], ..param("gap.k2", "k2", Domain::Positive, "m", "the fitted gap's fringing length") },
    numbers("gap.z", &["table"], Domain::Any, "m", Presence::Required, "table positions, strictly increasing, at least 4, covering [z_min, z_max]"),
    numbers("gap.r", &["table"], Domain::NonNegative, "H⁻¹", Presence::Required, "R_gap at each z, strictly increasing (the force pulls towards z_min)"),
    numbers("gap.r_prime", &["table"], Domain::Positive, "H⁻¹/m", Presence::Optional("a not-a-knot spline, or PCHIP where that is not monotone"), "R_gap′ at each z (then the C¹ Hermite interpolant)"),
    // [core]
    choice("core.model", &["linear", "saturating", "jiles-atherton"], "the core model"),
    Key { variants: &["linear", "saturating"], ..param("core.r0", "R_core0", Domain::Positive, "H⁻¹", "core reluctance at φ = 0") },
    Key { variants: &["saturating"], ..param("core.phi_sat", "phi_sat", Domain::Positive, "Wb", "saturation flux: R_core = r0 / (1 − |φ|/phi_sat) (Fröhlich–Kennelly)") },
    Key { variants: &["jiles-atherton"], ..param("core.length", "l_c", Domain::Positive, "m", "magnetic path length l_c of the Jiles–Atherton core: MMF_core = H_c·l_c") },
    Key { variants: &["jiles-atherton"], ..param("core.area", "A_c", Domain::Positive, "m²", "core cross-section A_c") },
    Key { variants: &["jiles-atherton"], ..param("core.m_sat", "M_sat", Domain::Positive, "A/m", "saturation magnetisation") },
    Key { variants: &["jiles-atherton"], ..param("core.b", "b_ja", Domain::Positive, "T", "anhysteretic shape parameter b of the Langevin function") },
    Key { variants: &["jiles-atherton"], ..param("core.c", "c_ja", Domain::UnitOpen, "-", "reversibility c") },
    Key { variants: &["jiles-atherton"], ..param("core.kappa", "kappa_ja", Domain::Positive, "A/m", "pinning κ (the hysteresis loop's width)") },
    Key { variants: &["jiles-atherton"], ..param("core.alpha", "alpha_ja", Domain::NonNegative, "-", "inter-domain coupling α") },
    Key { variants: &["jiles-atherton"], kind: Kind::Choice(&["clamp", "reversible"]), ..number("core.reversal", Domain::Any, "", Presence::Optional("clamp"), "dM_irr/dB_e (26) just after a flux reversal, while δ·(M_an − M_irr) < 0: clamp, the paper's (26) with the clamp (52), where H_c jumps fast to the physical region; reversible, 0 there (the core moves reversibly until M_an crosses M_irr), smooth enough for a filter sampling at tens of µs") },
    Key { variants: &["jiles-atherton"], presence: Presence::Default(1e-3), fittable: false, ..param("core.epsilon", "eps_ja", Domain::Positive, "-", "ε of the clamp (52): dB_c/dB_e ≥ ε") },
    // [mechanics]
    param("mechanics.mass", "m", Domain::Positive, "kg", "moving mass"),
    param("mechanics.stiffness", "k_s", Domain::NonNegative, "N/m", "spring stiffness: passive force F(z, v) = k_s·z + c·v + F0"),
    param("mechanics.damping", "c", Domain::NonNegative, "N·s/m", "viscous damping c"),
    Key { presence: Presence::When("exactly one of preload and rest_position"), ..param("mechanics.preload", "F0", Domain::Any, "N", "F0 of the passive force") },
    Key { presence: Presence::When("exactly one of preload and rest_position"), fittable: false, symbol: None, ..param("mechanics.rest_position", "", Domain::Any, "m", "alternative to preload: F0 = −k_s·rest_position") },
    Key { fittable: false, ..param("mechanics.z_min", "z_min", Domain::NonNegative, "m", "the closed stop (z is the gap length; the force pulls towards z_min)") },
    Key { fittable: false, ..param("mechanics.z_max", "z_max", Domain::Above("mechanics.z_min"), "m", "the open stop") },
    param("mechanics.restitution", "gamma", Domain::Unit, "-", "γ: an impact faster than bounce_threshold bounces, v⁺ = −γ·v"),
    param("mechanics.bounce_threshold", "v_eps", Domain::NonNegative, "m/s", "v_ε: at or below it an impact sticks (v⁺ = 0)"),
    // [supply]
    choice("supply.drive", &["voltage", "current"], "the input u: the coil voltage, or the coil current (needs coil.eddy > 0)"),
    number("supply.u_min", Domain::Any, "V", Presence::Required, "the lowest input (A with drive = \"current\")"),
    number("supply.u_max", Domain::Above("supply.u_min"), "V", Presence::Required, "the highest input (A with drive = \"current\")"),
    // [trajectory]
    names("trajectory.operations", &["closing", "opening"], Presence::Required, "the operations to design, in order: closing (z_max → z_min), opening (z_min → z_max)"),
    number("trajectory.takeoff", Domain::Positive, "s", Presence::Required, "t₀: end of the pre-movement stage, start of the motion"),
    number("trajectory.landing", Domain::Above("trajectory.takeoff"), "s", Presence::Required, "t_f: end of the motion"),
    choice("trajectory.shape", &["energy-optimal", "polynomial"], "the motion: min ∫u² dt (Pontryagin), or the degree-5 polynomial"),
    number("trajectory.u_bound", Domain::Positive, "V", Presence::Required, "the design uses inputs in [max(u_min, −u_bound), u_bound]; max(0, u_min) < u_bound ≤ u_max; the rest is the feedback's (A with drive = \"current\")"),
    Key { presence: Presence::Default(0.0), ..number("trajectory.contact_uncertainty", Domain::NonNegative, "m", Presence::Required, "σ: the spread of each designed stop's position into the stroke (a half-normal distribution of scale σ from z_min, closing, and from z_max, opening); > 0 designs the probability-based energy-optimal reference (min ∫u² dt plus the expected squared contact speed over that distribution), 0 today's; energy-optimal only, at most a tenth of the stroke") },
    Key { presence: Presence::Default(0.0), ..number("trajectory.standoff", Domain::NonNegative, "m", Presence::Required, "δ: the move ends at rest this far short of each stop, and the reference then approaches the stop at approach_speed, reaching it at t_f (the approach takes 5·δ/(4·approach_speed) of the motion); any stop, or any lead of the armature on its reference, within δ is met at no more than approach_speed; 0 lands at rest on the stop; at most a tenth of the stroke") },
    number("trajectory.approach_speed", Domain::Positive, "m/s", Presence::When("exactly where standoff > 0"), "v_c: the speed of the approach to the stop (and, unless controller.creep_speed is set, of the creep after t_f); the approach must leave at least half of the motion t_f − t₀ to the move"),
    // [controller]
    choice("controller.law", &["feedback-linearization", "sliding-mode", "model-sliding-mode", "backstepping"], "the control law: feedback linearization [PT 50], the model-free sliding mode [SM 34–35] with the expert rules [SM 43], the model-based sliding mode [JA 89] with the mode rules [JA 94], or backstepping through the force [SB 19] with a certified region [SB Theorem 3]"),
    Key { variants: FL, ..number("controller.settling_time", Domain::Positive, "s", Presence::When("exactly one of settling_time and poles"), "5 % settling time of the error dynamics with a triple real pole") },
    numbers("controller.poles", FL, Domain::Negative, "1/s", Presence::When("exactly one of settling_time and poles"), "the three real closed-loop poles of the error dynamics"),
    Key { variants: SM, ..number("controller.lambda1", Domain::Positive, "1/s", Presence::Required, "λ₁ of the sliding surface s = (λ₁ + d/dt)(λ₂ + d/dt)(z − z_r) [SM 17]") },
    Key { variants: SM, ..number("controller.lambda2", Domain::Positive, "1/s", Presence::Required, "λ₂ of the sliding surface [SM 17]") },
    Key { variants: SM, ..number("controller.eta", Domain::Positive, "m/s³", Presence::Required, "η of the reaching condition s·ṡ ≤ −η·|s| [SM 20]: enters the robustness bound [SM 49], not the emitted law") },
    Key { variants: SM, kind: Kind::Bool, ..number("controller.nonnegative_current", Domain::Any, "", Presence::Optional("false: the step reads φ (measured or estimated) for its sign"), "the current is kept ≥ 0 [SM §5]: the step reads the coil current instead of φ, takes sgn φ = +1 and never drives the current below 0") },
    Key { variants: MSM, ..number("controller.p", Domain::Positive, "1/s", Presence::Required, "p of the sliding surface s = (p + d/dt)²(z − z_ref) [JA 88]") },
    Key { variants: MSM, ..number("controller.k", Domain::Positive, "1/s", Presence::Required, "K of the reaching law ṡ = −K·s [JA 93]: with p, the error dynamics (d/dt + p)²(d/dt + K)") },
    Key { variants: HOLDS, ..number("controller.position", Domain::Any, "m", Presence::When("model-sliding-mode: exactly one of position and a [trajectory] section; backstepping: exactly one of position and square"), "z_ref: hold the armature at this constant position in [z_min, z_max] [JA §6.3], [SB §III]") },
    numbers("controller.gains", BS, Domain::Positive, "1/s", Presence::Required, "α₁, α₂, α₃ of the backstepping law: z₂ = v + α₁·(z − y_r) [SB 9], ż₂ = −z₁ − α₂·z₂ [SB 14], (F − F_d) decays at α₃ [SB 18]"),
    Key { variants: BS, kind: Kind::Choice(&["none", "intuitive", "hybrid"]), ..number("controller.switching", Domain::Any, "", Presence::Optional("hybrid"), "where F_d < 0: none (the local law [SB 19] everywhere), intuitive (u = 0 until the region D is reached [SB 28]), hybrid (the law while F_d > 0, u = 0 from F_d ≤ 0 until D [SB 31–33]); intuitive and hybrid need the spring's rest inside D") },
    Key { variants: BS, ..number("controller.decay", Domain::Positive, "1/s", Presence::Optional("a fifth of the largest a quadratic V allows"), "α of the region's LMI AᵀP + PA ⪯ −α·P [SB Theorem 3]") },
    numbers("controller.square", BS, Domain::NonNegative, "m, m, s", Presence::When("exactly one of position and square"), "[z_low, z_high, period]: a square reference, z_low for the first half of each period, then z_high [SB §V]"),
    number("controller.sample_period", Domain::Positive, "s", Presence::Required, "T_s: the emitted step runs once per sample; at most (landing − takeoff)/10"),
    names("controller.float", &["f32", "f64"], Presence::Optional("both"), "the float types to emit code for"),
    Key { kind: Kind::Choice(&["ekf", "ukf"]), ..number("controller.estimator", Domain::Any, "", Presence::Optional("the closed loops of `loop` and `sweep` feed the controller the plant's state"), "the observer of [observer] that drives the controller in `reldesign loop` and `sweep` from the measured voltage and current (it must be listed in observer.estimators)") },
    Key { variants: &["feedback-linearization", "model-sliding-mode"], kind: Kind::Bool, ..number("controller.compensate_resistance", Domain::Any, "", Presence::Optional("false"), "in the closed loops of `loop` and `sweep`, the law's voltage is corrected to the coil resistance R̂ the estimator estimates: u + (R̂ − R)·i with the measured current i (voltage drive; needs controller.estimator and observer.kalman.estimate_resistance = true); firmware applies reldesign_runtime::resistance::compensate_resistance the same way") },
    Key { variants: &["feedback-linearization"], kind: Kind::Bool, ..number("controller.self_calibration", Domain::Any, "", Presence::Optional("false"), "run-to-run self-calibration from the coil current (listed in the design report): with a UKF estimator, after each run the emitted code updates every physics parameter so that the filter's one-step current predictions are right (the law and the filter read them at run time); without an estimator, after each operation the emitted code updates the parameters the planned operations' current identifies, from the operation's replayed current (the law reads them at run time); a model of three states (no Jiles–Atherton core)") },
    Key { variants: &["feedback-linearization", "sliding-mode", "model-sliding-mode"], ..number("controller.landed_band", Domain::Positive, "m", Presence::Optional("10⁻⁹ of the stroke"), "within this distance of its end stop the armature counts as in contact (the expert rules [SM 43], and z_min of sgn* [SM 35]): size it to the position measurement or estimate the controller reads") },
    Key { variants: &["feedback-linearization", "sliding-mode", "model-sliding-mode"], ..number("controller.creep_speed", Domain::Positive, "m/s", Presence::Optional("2.5e-3 of the stroke per motion time"), "after t_f the reference creeps beyond the stop at this speed, so that a loop held short still lands") },
    // [observer]
    names("observer.estimators", &["semera", "integral", "ekf", "ukf"], Presence::Required, "the estimators to design and emit"),
    number("observer.sample_period", Domain::Positive, "s", Presence::Required, "Δ: one estimator step per sample"),
    names("observer.float", &["f32", "f64"], Presence::Optional("both"), "the float types to emit code for"),
    number("observer.voltage_noise", Domain::Positive, "V", Presence::Required, "σ_v of the measured coil voltage"),
    number("observer.current_noise", Domain::Positive, "A", Presence::Required, "σ_i of the measured coil current"),
    section("observer.semera", Presence::When("required iff estimators lists \"semera\""), "SEMERA (semera Algorithm 1, Table II/V)"),
    section("observer.integral", Presence::When("required iff estimators lists \"integral\""), "the integral estimator (semera Algorithm 2)"),
    section("observer.kalman", Presence::When("required iff estimators lists \"ekf\" or \"ukf\""), "the EKF and UKF on the discretised model (JA 84–87)"),
    // [observer.semera]
    number("observer.semera.initial_resistance", Domain::Positive, "Ω", Presence::Required, "r̄0"),
    number("observer.semera.initial_resistance_std", Domain::Positive, "Ω", Presence::Required, "σ_r0"),
    number("observer.semera.initial_inductance", Domain::Positive, "H", Presence::Required, "l̄0: at rest, and the expert rule's l̂"),
    number("observer.semera.initial_inductance_std", Domain::Positive, "H", Presence::Required, "σ_l0"),
    number("observer.semera.resistance_rate_std", Domain::NonNegative, "Ω/s", Presence::Required, "σ_ṙ"),
    number("observer.semera.inductance_accel_std", Domain::NonNegative, "H/s²", Presence::Required, "σ_l̈"),
    number("observer.semera.ci_sigmas", Domain::Positive, "-", Presence::Required, "n_σ of the confidence-interval detector (3.29: 99.9 %)"),
    // [observer.integral]
    number("observer.integral.initial_resistance", Domain::Positive, "Ω", Presence::Required, "r̄0, used until the first update (47)"),
    number("observer.integral.initial_inductance", Domain::Positive, "H", Presence::Required, "l̄0: the expert rule's l̂"),
    number("observer.integral.initial_flux_linkage", Domain::Any, "Wb", Presence::Default(0.0), "λ0"),
    number("observer.integral.ci_sigmas", Domain::Positive, "-", Presence::Required, "n_σ"),
    number("observer.integral.energize_threshold", Domain::Positive, "V", Presence::Optional("supply.u_max/2 with drive = \"voltage\" and u_max > 0; required otherwise"), "the coil voltage above which an energizing operation starts"),
    // [observer.kalman]
    number("observer.kalman.process_z", Domain::Positive, "m", Presence::Required, "σ of w_z per step (84a)"),
    number("observer.kalman.process_phi", Domain::Positive, "Wb", Presence::Required, "σ of w_φ per step (84c)"),
    number("observer.kalman.process_hc", Domain::Positive, "A/m", Presence::When("required with a jiles-atherton core, refused otherwise"), "σ of w_Hc per step"),
    number("observer.kalman.initial_z_std", Domain::Positive, "m", Presence::Required, "initial σ of z (the filter starts at rest at z_max, φ = 0, H_c = 0)"),
    number("observer.kalman.initial_phi_std", Domain::Positive, "Wb", Presence::Required, "initial σ of φ"),
    number("observer.kalman.initial_hc_std", Domain::Positive, "A/m", Presence::When("required with a jiles-atherton core, refused otherwise"), "initial σ of H_c"),
    number("observer.kalman.ukf_alpha", Domain::UnitLeftOpen, "-", Presence::Default(1.0), "the UKF's sigma-point spread α"),
    number("observer.kalman.ukf_beta", Domain::NonNegative, "-", Presence::Default(2.0), "the UKF's prior-knowledge weight β"),
    number("observer.kalman.ukf_kappa", Domain::Any, "-", Presence::Default(0.0), "the UKF's secondary scaling κ"),
    Key { kind: Kind::Bool, domain: Domain::Any, unit: "", ..number("observer.kalman.estimate_resistance", Domain::Any, "", Presence::Optional("false"), "R becomes a random-walk state: [z, z_prev, φ, R], [z, z_prev, φ, H_c, R] with a jiles-atherton core") },
    Key { kind: Kind::Choice(&["euler", "exponential"]), ..number("observer.kalman.flux_step", Domain::Any, "", Presence::Optional("euler"), "how φ (and H_c) advance over a sample: euler, the paper's φ⁺ = φ + T_s·f_φ (84c–84d), stable while T_s < 2τ; exponential, exponential Euler on the coil's total rate at the armature's mid-step position, exact for a linear coil and stable at any T_s") },
    number("observer.kalman.flux_substeps", Domain::Positive, "-", Presence::When("only with flux_step = \"exponential\"; default 1"), "exponential substeps per sample (an integer in 1..=64)"),
    number("observer.kalman.resistance_rate_std", Domain::Positive, "Ω/s", Presence::When("required with estimate_resistance = true, refused otherwise"), "σ_Ṙ: w_R has σ = σ_Ṙ·T_s per step"),
    number("observer.kalman.initial_resistance_std", Domain::Positive, "Ω", Presence::When("required with estimate_resistance = true, refused otherwise"), "initial σ of R around coil.resistance"),
];

const fn number(
    path: &'static str,
    domain: Domain,
    unit: &'static str,
    presence: Presence,
    meaning: &'static str,
) -> Key {
    Key {
        path,
        variants: &[],
        kind: Kind::Number,
        domain,
        unit,
        symbol: None,
        presence,
        fittable: false,
        meaning,
    }
}

const fn param(
    path: &'static str,
    symbol: &'static str,
    domain: Domain,
    unit: &'static str,
    meaning: &'static str,
) -> Key {
    Key {
        symbol: Some(symbol),
        fittable: true,
        ..number(path, domain, unit, Presence::Required, meaning)
    }
}

const fn numbers(
    path: &'static str,
    variants: &'static [&'static str],
    domain: Domain,
    unit: &'static str,
    presence: Presence,
    meaning: &'static str,
) -> Key {
    Key {
        variants,
        kind: Kind::Numbers,
        ..number(path, domain, unit, presence, meaning)
    }
}

const fn choice(path: &'static str, values: &'static [&'static str], meaning: &'static str) -> Key {
    Key {
        kind: Kind::Choice(values),
        unit: "",
        ..number(path, Domain::Any, "", Presence::Required, meaning)
    }
}

const fn names(
    path: &'static str,
    values: &'static [&'static str],
    presence: Presence,
    meaning: &'static str,
) -> Key {
    Key {
        kind: Kind::Names(values),
        unit: "",
        ..number(path, Domain::Any, "", presence, meaning)
    }
}

const fn text(path: &'static str, meaning: &'static str) -> Key {
    Key {
        kind: Kind::Text,
        unit: "",
        ..number(path, Domain::Any, "", Presence::Required, meaning)
    }
}

const fn section(path: &'static str, presence: Presence, meaning: &'static str) -> Key {
    Key {
        kind: Kind::Section,
        unit: "",
        ..number(path, Domain::Any, "", presence, meaning)
    }
}

/// The key at `path`. Panics on a path not in [`KEYS`]: callers pass
/// literals, and a test reads every one of them.
pub fn key(path: &str) -> &'static Key {
    lookup(path).unwrap_or_else(|| panic!("`{path}` is not a key of the description schema"))
}

/// The key at `path`, if there is one.
pub fn lookup(path: &str) -> Option<&'static Key> {
    KEYS.iter().find(|k| k.path == path)
}

/// The key whose model symbol is `symbol`.
pub fn by_symbol(symbol: &str) -> Option<&'static Key> {
    KEYS.iter().find(|k| k.symbol == Some(symbol))
}

/// The keys allowed directly in `section` ("" for the top level) when its
/// `model` is `variant`, in schema order.
pub fn keys_of(section: &str, variant: Option<&str>) -> Vec<&'static str> {
    KEYS.iter()
        .filter(|k| k.section() == section && k.in_variant(variant))
        .map(Key::name)
        .collect()
}

/// The values of a `Choice` or `Names` key.
pub fn values(path: &str) -> &'static [&'static str] {
    match key(path).kind {
        Kind::Choice(v) | Kind::Names(v) => v,
        _ => &[],
    }
}

/// The reference page `docs/reference/description.md`, generated.
pub fn reference_markdown() -> String {
    let mut out = String::from(
        "<!-- @generated from designer/src/description/schema.rs by the test \
         `designer/tests/schema.rs`; run `UPDATE_DOCS=1 cargo test -p reldesign-designer --test schema` \
         to refresh. -->\n\n# The description's keys\n\n\
         Every key `reldesign` reads, by section. All quantities are SI; unknown keys are an \
         error. A key marked with a `model` exists only with that value of its section's \
         `model`. The contract these keys follow is `../shared/spec/actuator.md`; the \
         conventions behind them are in [conventions](conventions.md).\n",
    );
    let sections = KEYS.iter().filter(|k| k.kind == Kind::Section);
    for s in std::iter::once("").chain(sections.map(|k| k.path)) {
        let title = if s.is_empty() {
            "top level".to_string()
        } else {
            format!("`[{s}]`")
        };
        let _ = write!(out, "\n## {title}\n\n| key | type | unit | symbol | rule | meaning |\n| --- | --- | --- | --- | --- | --- |\n");
        for k in KEYS.iter().filter(|k| k.section() == s) {
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} | {} |",
                key_cell(k),
                kind_text(k.kind),
                unit_cell(k),
                symbol_cell(k),
                rule_text(k),
                k.meaning.replace('|', "\\|")
            );
        }
    }
    out
}

fn key_cell(k: &Key) -> String {
    let variants = k
        .variants
        .iter()
        .map(|v| format!("`{v}`"))
        .collect::<Vec<_>>();
    match variants.is_empty() {
        true => format!("`{}`", k.name()),
        false => format!("`{}` (model {})", k.name(), variants.join(", ")),
    }
}

fn kind_text(kind: Kind) -> String {
    let list = |v: &[&str]| {
        v.iter()
            .map(|s| format!("`\"{s}\"`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match kind {
        Kind::Number => "number".into(),
        Kind::Numbers => "array of numbers".into(),
        Kind::Choice(v) => format!("one of {}", list(v)),
        Kind::Names(v) => format!("array of {}", list(v)),
        Kind::Bool => "boolean".into(),
        Kind::Text => "string".into(),
        Kind::Section => "table".into(),
    }
}

fn unit_cell(k: &Key) -> &'static str {
    if k.unit.is_empty() {
        ""
    } else {
        k.unit
    }
}

fn symbol_cell(k: &Key) -> String {
    k.symbol.map_or_else(String::new, |s| format!("`{s}`"))
}

fn rule_text(k: &Key) -> String {
    let presence = match k.presence {
        Presence::Required => "required".to_string(),
        Presence::Default(d) => format!("optional, default {d}"),
        Presence::Optional(what) => format!("optional (without it: {what})"),
        Presence::When(when) => when.to_string(),
    };
    match (k.kind, k.domain.bound()) {
        (Kind::Number, Some(b)) => format!("{presence}; {b}"),
        (Kind::Numbers, Some(b)) => format!("{presence}; each {b}"),
        _ => presence,
    }
}
