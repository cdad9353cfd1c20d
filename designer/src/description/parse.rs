//! Text → [`Description`]: the TOML document is parsed with spans kept
//! ([`toml::de::DeTable`]) and walked by hand, so that every rejection names
//! the file, the full dotted key, its line/column and what was expected.
//!
//! The checks below read like the table of `shared/spec/actuator.md`: each
//! section lists its keys with the bound and the unit a value must have.

use std::ops::Range;
use std::path::Path;

use toml::de::{DeString, DeTable, DeValue};
use toml::Spanned;

use super::schema;
use super::{
    Coil, Controller, Core, Description, DescriptionError, Drive, Estimator, FloatType, Gains, Gap,
    IntegralSettings, JilesAtherton, KalmanSection, Law, Mechanics, Observer, Operation,
    ResistanceEstimate, SemeraSettings, Shape, SlidingSurface, Source, Supply, Trajectory,
};

type Res<T> = Result<T, DescriptionError>;

/// The motion [takeoff, landing] must last at least this many sample periods.
const MIN_SAMPLES_PER_MOTION: f64 = 10.0;
/// Grid size of the fringing-denominator check on (0, z_max].
const DENOMINATOR_GRID: usize = 1000;

/// Reads and validates the description in `path`. An unreadable file is a
/// [`DescriptionError`] naming the file.
pub fn parse_file(path: &Path) -> Result<Description, DescriptionError> {
    let file_name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| DescriptionError::io(&file_name, &e))?;
    parse_str(&text, &file_name)
}

/// Parses and validates a description; `file_name` is only used in messages
/// and in [`Description::source`].
pub fn parse_str(text: &str, file_name: &str) -> Result<Description, DescriptionError> {
    let doc = DeTable::parse(text).map_err(|e| DescriptionError::syntax(file_name, text, &e))?;
    let ctx = Ctx {
        file: file_name,
        text,
    };
    let root = Sect {
        ctx: &ctx,
        name: "",
        table: doc.get_ref(),
        span: 0..0,
    };
    root.check_keys(None, "at the top level")?;
    let name = parse_name(&root)?;
    let coil = parse_coil(&root.section("coil")?)?;
    let gap_sect = root.section("gap")?;
    let gap = parse_gap(&gap_sect)?;
    let core_sect = root.section("core")?;
    let core = parse_core(&core_sect)?;
    let mechanics = parse_mechanics(&root.section("mechanics")?)?;
    let supply_sect = root.section("supply")?;
    let supply = parse_supply(&supply_sect)?;
    check_gap_range(&gap_sect, &gap, &mechanics)?;
    check_drive(&supply_sect, &supply, &coil)?;
    let trajectory_sect = root.opt_section("trajectory")?;
    let trajectory = trajectory_sect
        .as_ref()
        .map(|s| parse_trajectory(s, &supply))
        .transpose()?;
    if let (Some(_), Core::JilesAtherton(_)) = (&trajectory, &core) {
        let msg = "a [trajectory] is designed through the feedback-linearizing coordinates \
                   (x = T⁻¹(ξ), perfect-tracking-soft-landing eqs. 41–42), which need an \
                   input-affine model, but the \"jiles-atherton\" core is not: its branch \
                   δ = sign(dφ/dt) depends on the input u; design on a \"saturating\" or \
                   \"linear\" core model of the same actuator";
        return Err(core_sect.err("model", msg, "not input-affine"));
    }
    let controller_sect = root.opt_section("controller")?;
    let controller = controller_sect.as_ref().map(parse_controller).transpose()?;
    if let (Some(s), Some(c)) = (&controller_sect, &controller) {
        check_controller(&root, s, c, trajectory.as_ref(), &core_sect, &core)?;
    }
    let observer = root
        .opt_section("observer")?
        .map(|s| parse_observer(&s, &supply, &core_sect, &core))
        .transpose()?;
    if let (Some(s), Some(c)) = (&controller_sect, &controller) {
        check_estimator(s, c, observer.as_ref())?;
    }
    let source = Source {
        file_name: file_name.to_string(),
        text: text.to_string(),
    };
    Ok(Description {
        name,
        coil,
        gap,
        core,
        mechanics,
        supply,
        trajectory,
        controller,
        observer,
        source,
    })
}

// ---------------------------------------------------------------- sections

fn parse_name(root: &Sect) -> Res<String> {
    const WHAT: &str = "an identifier usable as a Rust module name ([A-Za-z_][A-Za-z0-9_-]*)";
    let Some((_, value)) = root.entry("name") else {
        return Err(root.missing("name", WHAT));
    };
    let Some(name) = value.get_ref().as_str() else {
        let msg = format!("expected a string, {WHAT}, found {}", root.ctx.found(value));
        return Err(root.err("name", msg, "expected a string"));
    };
    if let Some(why) = identifier_problem(name) {
        let msg = format!("expected {WHAT}, found {name:?} ({why})");
        return Err(root.err("name", msg, "not a valid identifier"));
    }
    Ok(name.to_string())
}

/// Why `name` cannot be used as a module/type name, if it cannot.
fn identifier_problem(name: &str) -> Option<&'static str> {
    let mut chars = name.chars();
    let Some(first) = chars.next() else {
        return Some("it is empty");
    };
    if !(first.is_ascii_alphabetic() || first == '_') {
        return Some("it must start with a letter or '_'");
    }
    if !chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Some("only letters, digits, '_' and '-' are allowed");
    }
    let ident = name.replace('-', "_");
    if ident.chars().all(|c| c == '_') {
        return Some("it needs a letter or digit");
    }
    if RUST_KEYWORDS.contains(&ident.as_str()) {
        return Some("it is a Rust keyword");
    }
    None
}

const RUST_KEYWORDS: [&str; 51] = [
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try",
];

fn parse_coil(s: &Sect) -> Res<Coil> {
    s.check_keys(None, "in [coil]")?;
    Ok(Coil {
        turns: s.req("turns")?,
        resistance: s.req("resistance")?,
        eddy: s.req("eddy")?,
        resistance_drift: s.or_default("resistance_drift")?,
    })
}

fn parse_gap(s: &Sect) -> Res<Gap> {
    let model = s.choice("model", "gap model")?;
    let context = format!("in [gap] with model \"{model}\"");
    let gap = match model {
        "linear" => {
            s.check_keys(Some(model), &context)?;
            Gap::Linear {
                slope: s.req("slope")?,
                offset: s.or_default("offset")?,
            }
        }
        "mclyman" => {
            s.check_keys(Some(model), &context)?;
            Gap::McLyman {
                area: s.req("area")?,
                winding_length: s.req("winding_length")?,
            }
        }
        "mclyman-fit" => {
            s.check_keys(Some(model), &context)?;
            Gap::McLymanFit {
                r0: s.req("r0")?,
                r0_prime: s.req("r0_prime")?,
                k1: s.req("k1")?,
                k2: s.req("k2")?,
            }
        }
        _ => {
            s.check_keys(Some(model), &context)?;
            parse_table(s)?
        }
    };
    Ok(gap)
}

fn parse_table(s: &Sect) -> Res<Gap> {
    let z = s.req_array("z")?;
    let r = s.req_array("r")?;
    let r_prime = s.opt_numbers("r_prime")?;
    if z.len() < 4 {
        let msg = format!("expected at least 4 points, found {}", z.len());
        return Err(s.err("z", msg, "too few points"));
    }
    s.same_length("r", &r, z.len())?;
    if let Some(rp) = &r_prime {
        s.same_length("r_prime", rp, z.len())?;
    }
    s.strictly_increasing("z", &z, "")?;
    let why = " (R_gap' > 0: the magnetic force must pull towards z_min)";
    s.strictly_increasing("r", &r, why)?;
    Ok(Gap::Table { z, r, r_prime })
}

fn parse_core(s: &Sect) -> Res<Core> {
    let model = s.choice("model", "core model")?;
    let context = format!("in [core] with model \"{model}\"");
    let core = match model {
        "linear" => {
            s.check_keys(Some(model), &context)?;
            Core::Linear { r0: s.req("r0")? }
        }
        "saturating" => {
            s.check_keys(Some(model), &context)?;
            Core::Saturating {
                r0: s.req("r0")?,
                phi_sat: s.req("phi_sat")?,
            }
        }
        _ => {
            s.check_keys(Some(model), &context)?;
            Core::JilesAtherton(JilesAtherton {
                length: s.req("length")?,
                area: s.req("area")?,
                m_sat: s.req("m_sat")?,
                b: s.req("b")?,
                c: s.req("c")?,
                kappa: s.req("kappa")?,
                alpha: s.req("alpha")?,
                epsilon: s.or_default("epsilon")?,
            })
        }
    };
    Ok(core)
}

fn parse_mechanics(s: &Sect) -> Res<Mechanics> {
    s.check_keys(None, "in [mechanics]")?;
    let mass = s.req("mass")?;
    let stiffness = s.req("stiffness")?;
    let damping = s.req("damping")?;
    let preload = resolve_preload(s, stiffness)?;
    let z_min = s.req("z_min")?;
    let z_max = s.req_above("z_max", z_min)?;
    Ok(Mechanics {
        mass,
        stiffness,
        damping,
        preload,
        z_min,
        z_max,
        restitution: s.req("restitution")?,
        bounce_threshold: s.req("bounce_threshold")?,
    })
}

/// F0: `preload`, or −k_s·`rest_position`; exactly one of them.
fn resolve_preload(s: &Sect, stiffness: f64) -> Res<f64> {
    let preload = s.opt("preload")?;
    let rest = s.opt("rest_position")?;
    match (preload, rest) {
        (Some(f0), None) => Ok(f0),
        (None, Some(z_s)) => Ok(-stiffness * z_s),
        (Some(_), Some(_)) => Err(s.err(
            "rest_position",
            "give either mechanics.preload or mechanics.rest_position, not both \
             (F0 = preload, or F0 = −stiffness·rest_position)",
            "conflicts with `preload`",
        )),
        (None, None) => Err(s.missing(
            "preload",
            "exactly one of mechanics.preload [N] or mechanics.rest_position [m] \
             (F0 = preload, or F0 = −stiffness·rest_position)",
        )),
    }
}

fn parse_supply(s: &Sect) -> Res<Supply> {
    s.check_keys(None, "in [supply]")?;
    let drive = match s.choice("drive", "drive")? {
        "voltage" => Drive::Voltage,
        _ => Drive::Current,
    };
    let unit = if drive == Drive::Voltage { "V" } else { "A" };
    let u_min = s.req_in("u_min", unit)?;
    let u_max = s.req_above_in("u_max", u_min, unit)?;
    Ok(Supply {
        drive,
        u_min,
        u_max,
    })
}

fn parse_trajectory(s: &Sect, supply: &Supply) -> Res<Trajectory> {
    s.check_keys(None, "in [trajectory]")?;
    let operations = s
        .names("operations", "operation", "at least one operation")?
        .ok_or_else(|| {
            s.missing(
                "operations",
                "a non-empty array of \"closing\", \"opening\"",
            )
        })?
        .into_iter()
        .map(|op| match op {
            "closing" => Operation::Closing,
            _ => Operation::Opening,
        })
        .collect();
    let takeoff = s.req("takeoff")?;
    let landing = s.req_above("landing", takeoff)?;
    let shape = match s.choice("shape", "trajectory shape")? {
        "energy-optimal" => Shape::EnergyOptimal,
        _ => Shape::Polynomial,
    };
    let unit = if supply.drive == Drive::Voltage {
        "V"
    } else {
        "A"
    };
    let u_bound = s.req_in("u_bound", unit)?;
    check_u_bound(s, u_bound, supply, unit)?;
    Ok(Trajectory {
        operations,
        takeoff,
        landing,
        shape,
        u_bound,
    })
}

fn parse_controller(s: &Sect) -> Res<Controller> {
    if s.entry("law").is_none() {
        // an unknown key is the likelier mistake (`kind = …` for `law = …`)
        s.check_keys_any_variant("in [controller]")?;
    }
    let name = s.choice("law", "control law")?;
    s.check_keys(Some(name), &format!("in [controller] with law \"{name}\""))?;
    let law = match name {
        "feedback-linearization" => Law::FeedbackLinearization(parse_gains(s)?),
        _ => Law::SlidingMode(SlidingSurface {
            lambda1: s.req("lambda1")?,
            lambda2: s.req("lambda2")?,
            eta: s.req("eta")?,
            nonnegative_current: s.opt_bool("nonnegative_current")?.unwrap_or(false),
        }),
    };
    let sample_period = s.req("sample_period")?;
    let floats = parse_floats(s)?;
    let creep_speed = s.opt("creep_speed")?;
    let estimator = s.opt_choice("estimator", "estimator")?.map(|e| match e {
        "ekf" => Estimator::Ekf,
        _ => Estimator::Ukf,
    });
    Ok(Controller {
        law,
        sample_period,
        floats,
        creep_speed,
        estimator,
    })
}

/// `controller.estimator` names an observer that `[observer]` designs.
fn check_estimator(s: &Sect, c: &Controller, observer: Option<&Observer>) -> Res<()> {
    let Some(wanted) = c.estimator else {
        return Ok(());
    };
    let name = if wanted == Estimator::Ekf {
        "ekf"
    } else {
        "ukf"
    };
    match observer {
        Some(o) if o.estimators.contains(&wanted) => Ok(()),
        Some(_) => {
            let msg = format!(
                "controller.estimator = \"{name}\" needs \"{name}\" in observer.estimators: the \
                 loop runs the observer that [observer] designs"
            );
            Err(s.err("estimator", msg, "not in observer.estimators"))
        }
        None => {
            let msg = format!(
                "controller.estimator = \"{name}\" needs an [observer] section listing \
                 \"{name}\" in estimators (with [observer.kalman])"
            );
            Err(s.err("estimator", msg, "no [observer]"))
        }
    }
}

/// `float`: optional, default both; sorted, no duplicates.
fn parse_floats(s: &Sect) -> Res<Vec<FloatType>> {
    let mut floats: Vec<FloatType> = s
        .names("float", "float type", "at least one float type")?
        .unwrap_or(schema::values("controller.float").to_vec())
        .into_iter()
        .map(|f| match f {
            "f32" => FloatType::F32,
            _ => FloatType::F64,
        })
        .collect();
    floats.sort();
    Ok(floats)
}

/// `[observer]` and its sub-sections `[observer.semera]`, `[observer.integral]`,
/// `[observer.kalman]`: each sub-section is required exactly when one of its
/// estimators is listed (and refused otherwise).
fn parse_observer(s: &Sect, supply: &Supply, core_sect: &Sect, core: &Core) -> Res<Observer> {
    s.check_keys(None, "in [observer]")?;
    let estimators: Vec<Estimator> = s
        .names("estimators", "estimator", "at least one estimator")?
        .ok_or_else(|| {
            s.missing(
                "estimators",
                "a non-empty array of \"semera\", \"integral\", \"ekf\", \"ukf\"",
            )
        })?
        .into_iter()
        .map(|e| match e {
            "semera" => Estimator::Semera,
            "integral" => Estimator::Integral,
            "ekf" => Estimator::Ekf,
            _ => Estimator::Ukf,
        })
        .collect();
    let sample_period = s.req("sample_period")?;
    let floats = parse_floats(s)?;
    let voltage_noise = s.req("voltage_noise")?;
    let current_noise = s.req("current_noise")?;
    let has = |e: Estimator| estimators.contains(&e);
    let semera = s
        .sub_section(
            "semera",
            "observer.semera",
            has(Estimator::Semera),
            "\"semera\"",
        )?
        .map(|t| parse_semera(&t))
        .transpose()?;
    let integral = s
        .sub_section(
            "integral",
            "observer.integral",
            has(Estimator::Integral),
            "\"integral\"",
        )?
        .map(|t| parse_integral(&t, supply))
        .transpose()?;
    let kalman = s
        .sub_section(
            "kalman",
            "observer.kalman",
            has(Estimator::Ekf) || has(Estimator::Ukf),
            "\"ekf\" or \"ukf\"",
        )?
        .map(|t| parse_kalman(&t, core_sect, core))
        .transpose()?;
    Ok(Observer {
        estimators,
        sample_period,
        floats,
        voltage_noise,
        current_noise,
        semera,
        integral,
        kalman,
    })
}

/// `[observer.semera]`: [SE Table II] / [SE Table V].
fn parse_semera(s: &Sect) -> Res<SemeraSettings> {
    s.check_keys(None, "in [observer.semera]")?;
    Ok(SemeraSettings {
        initial_resistance: s.req("initial_resistance")?,
        initial_resistance_std: s.req("initial_resistance_std")?,
        initial_inductance: s.req("initial_inductance")?,
        initial_inductance_std: s.req("initial_inductance_std")?,
        resistance_rate_std: s.req("resistance_rate_std")?,
        inductance_accel_std: s.req("inductance_accel_std")?,
        ci_sigmas: s.req("ci_sigmas")?,
    })
}

/// `[observer.integral]`: what [SE Alg. 2] needs.
fn parse_integral(s: &Sect, supply: &Supply) -> Res<IntegralSettings> {
    s.check_keys(None, "in [observer.integral]")?;
    let initial_resistance = s.req("initial_resistance")?;
    let initial_inductance = s.req("initial_inductance")?;
    let initial_flux_linkage = s.or_default("initial_flux_linkage")?;
    let ci_sigmas = s.req("ci_sigmas")?;
    let default_threshold =
        (supply.drive == Drive::Voltage && supply.u_max > 0.0).then_some(0.5 * supply.u_max);
    let energize_threshold = match default_threshold {
        Some(d) => s.num_or("energize_threshold", Bound::Positive, "V", d)?,
        None => s
            .opt_num("energize_threshold", Bound::Positive, "V")?
            .ok_or_else(|| {
                s.missing(
                    "energize_threshold",
                    "a number > 0 [V]: the coil voltage above which an energizing operation \
                     starts (it has no default unless supply.drive = \"voltage\" with \
                     supply.u_max > 0, where it is u_max/2)",
                )
            })?,
    };
    Ok(IntegralSettings {
        initial_resistance,
        initial_inductance,
        initial_flux_linkage,
        ci_sigmas,
        energize_threshold,
    })
}

/// `[observer.kalman]`: `process_hc` and `initial_hc_std` exist exactly with a
/// Jiles–Atherton core (whose state has H_c).
fn parse_kalman(s: &Sect, core_sect: &Sect, core: &Core) -> Res<KalmanSection> {
    s.check_keys(None, "in [observer.kalman]")?;
    let process_z = s.req("process_z")?;
    let process_phi = s.req("process_phi")?;
    let ja = matches!(core, Core::JilesAtherton(_));
    let hc = |key: &str| -> Res<Option<f64>> {
        if ja {
            let what = "a number > 0 [A/m] (the \"jiles-atherton\" core adds the state H_c)";
            return s
                .opt_num(key, Bound::Positive, "A/m")?
                .map(Some)
                .ok_or_else(|| s.missing(key, what));
        }
        if s.entry(key).is_some() {
            let model = core_sect
                .entry("model")
                .and_then(|(_, v)| v.get_ref().as_str().map(str::to_owned))
                .unwrap_or_default();
            let msg = format!(
                "only allowed with core.model = \"jiles-atherton\" \
                 (the state has no H_c with core.model = \"{model}\"); remove it"
            );
            return Err(s.err(key, msg, "no H_c in this model"));
        }
        Ok(None)
    };
    let process_hc = hc("process_hc")?;
    let initial_z_std = s.req("initial_z_std")?;
    let initial_phi_std = s.req("initial_phi_std")?;
    let initial_hc_std = hc("initial_hc_std")?;
    let resistance = parse_resistance_estimate(s, ja)?;
    Ok(KalmanSection {
        process_z,
        process_phi,
        process_hc,
        initial_z_std,
        initial_phi_std,
        initial_hc_std,
        ukf_alpha: s.or_default("ukf_alpha")?,
        ukf_beta: s.or_default("ukf_beta")?,
        ukf_kappa: s.or_default("ukf_kappa")?,
        resistance,
    })
}

/// `estimate_resistance` (a boolean, default false) of `[observer.kalman]`
/// with `resistance_rate_std` [Ω/s] and `initial_resistance_std` [Ω], both
/// required with it and refused without it. With a Jiles–Atherton core the
/// state [z, z_prev, φ, H_c, R] would exceed the filters' four states.
fn parse_resistance_estimate(s: &Sect, ja: bool) -> Res<Option<ResistanceEstimate>> {
    const KEY: &str = "estimate_resistance";
    let on = s.opt_bool(KEY)?.unwrap_or(false);
    let keys = ["resistance_rate_std", "initial_resistance_std"];
    if !on {
        if let Some(key) = keys.into_iter().find(|k| s.entry(k).is_some()) {
            let msg = "only allowed with estimate_resistance = true (the coil resistance is a \
                       state only then); add estimate_resistance = true or remove it";
            return Err(s.err(key, msg, "R is not estimated"));
        }
        return Ok(None);
    }
    if ja {
        let msg = "not supported with core.model = \"jiles-atherton\": the state \
                   [z, z_prev, φ, H_c, R] would have 5 entries and the filters hold at most 4";
        return Err(s.err(KEY, msg, "too many states"));
    }
    Ok(Some(ResistanceEstimate {
        rate_std: s.req(keys[0])?,
        initial_std: s.req(keys[1])?,
    }))
}

/// K of [PT 48]: exactly one of `settling_time` and `poles`.
fn parse_gains(s: &Sect) -> Res<Gains> {
    let settling = s.opt("settling_time")?;
    let poles = s.opt_numbers("poles")?;
    match (settling, poles) {
        (Some(t), None) => Ok(Gains::SettlingTime(t)),
        (None, Some(p)) => match <[f64; 3]>::try_from(p.as_slice()) {
            Ok(poles) => Ok(Gains::Poles(poles)),
            Err(_) => {
                let msg = format!(
                    "expected exactly 3 real closed-loop poles [1/s] (the error dynamics of \
                     z, v, a is of order 3), found {}",
                    p.len()
                );
                Err(s.err("poles", msg, "needs 3 poles"))
            }
        },
        (Some(_), Some(_)) => Err(s.err(
            "poles",
            "give either controller.settling_time or controller.poles, not both \
             (both define the gains K)",
            "conflicts with `settling_time`",
        )),
        (None, None) => Err(s.missing(
            "settling_time",
            "exactly one of controller.settling_time [s] (5 % settling time of a triple \
             real pole) or controller.poles = [p1, p2, p3] [1/s] (each < 0)",
        )),
    }
}

// ------------------------------------------------------ cross-section checks

/// The trajectory is designed with inputs in [max(u_min, −u_bound), u_bound]:
/// that interval must lie within the supply and contain positive inputs
/// (closing needs them), i.e. max(0, u_min) < u_bound ≤ u_max.
fn check_u_bound(s: &Sect, u_bound: f64, supply: &Supply, unit: &str) -> Res<()> {
    let (u_min, u_max) = (supply.u_min, supply.u_max);
    let lower = u_min.max(0.0);
    if u_bound > lower && u_bound <= u_max {
        return Ok(());
    }
    let found = s
        .entry("u_bound")
        .map_or_else(|| u_bound.to_string(), |(_, v)| s.ctx.found(v));
    let design = "the trajectory is designed with inputs in [max(u_min, -u_bound), u_bound], \
                  which must lie within the supply and include positive inputs (closing needs \
                  them)";
    let msg = if u_max <= 0.0 {
        format!(
            "found {found}, but no u_bound can work: supply.u_max = {u_max} gives no positive \
             input; {design}"
        )
    } else if u_bound > u_max {
        format!(
            "expected a number in ({lower}, supply.u_max = {u_max}] [{unit}], found {found}: \
             it exceeds supply.u_max; {design}, leaving the rest to the feedback"
        )
    } else {
        format!(
            "expected a number in (supply.u_min = {u_min}, {u_max}] [{unit}], found {found}: \
             with u_bound <= supply.u_min no input is left to design with; {design}"
        )
    };
    Err(s.err("u_bound", msg, "outside the supply"))
}

fn check_controller(
    root: &Sect,
    s: &Sect,
    c: &Controller,
    trajectory: Option<&Trajectory>,
    core_sect: &Sect,
    core: &Core,
) -> Res<()> {
    let Some(t) = trajectory else {
        let msg = "section [controller] requires a [trajectory] section: the controller tracks \
                   a reference trajectory, so give [trajectory] (operations, takeoff, landing, \
                   shape, u_bound)";
        return Err(root.err("controller", msg, "needs [trajectory]"));
    };
    if let Core::JilesAtherton(_) = core {
        let msg = format!(
            "the controller law \"{}\" is designed on an input-affine model, but the \
             \"jiles-atherton\" core is not: its branch δ = sign(dφ/dt) depends on the input \
             u; design on a \"saturating\" or \"linear\" core model of the same actuator",
            c.law.name()
        );
        return Err(core_sect.err("model", msg, "not input-affine"));
    }
    let limit = (t.landing - t.takeoff) / MIN_SAMPLES_PER_MOTION;
    if c.sample_period > limit {
        let found = s
            .entry("sample_period")
            .map_or_else(|| c.sample_period.to_string(), |(_, v)| s.ctx.found(v));
        let msg = format!(
            "expected a number <= (trajectory.landing - trajectory.takeoff)/10 = {limit:e} [s], \
             found {found}: the motion must span at least 10 sample periods for the sampled \
             controller to track it"
        );
        return Err(s.err("sample_period", msg, "too long for the motion"));
    }
    Ok(())
}

fn check_gap_range(s: &Sect, gap: &Gap, m: &Mechanics) -> Res<()> {
    match gap {
        Gap::Linear { .. } => Ok(()),
        Gap::McLyman {
            area,
            winding_length,
        } => {
            let sqrt_a = area.sqrt();
            let f = |z: f64| 1.0 + z / sqrt_a * (2.0 * winding_length / z).ln();
            check_denominator(s, "winding_length", "1 + z/√A·ln(2·l_w/z)", m.z_max, f)
        }
        Gap::McLymanFit { k1, k2, .. } => {
            let f = |z: f64| 1.0 + k1 * z * (k2 / z).ln();
            check_denominator(s, "k2", "1 + k1·z·ln(k2/z)", m.z_max, f)
        }
        Gap::Table { z, .. } => check_coverage(s, z, m),
    }
}

/// The fringing denominator must stay > 0 on (0, z_max]. It is concave in z
/// with limit 1 at 0⁺, so a uniform grid that ends at z_max finds any failure.
fn check_denominator(
    s: &Sect,
    key: &str,
    formula: &str,
    z_max: f64,
    f: impl Fn(f64) -> f64,
) -> Res<()> {
    for k in 1..=DENOMINATOR_GRID {
        let z = z_max * k as f64 / DENOMINATOR_GRID as f64;
        let d = f(z);
        if d.is_nan() || d <= 0.0 {
            let msg = format!(
                "the gap denominator {formula} must stay > 0 on (0, z_max = {z_max:e} m], \
                 but it is {d:.4} at z = {z:.4e} m (R_gap would be singular or negative)"
            );
            return Err(s.err(key, msg, "makes the gap denominator <= 0"));
        }
    }
    Ok(())
}

fn check_coverage(s: &Sect, z: &[f64], m: &Mechanics) -> Res<()> {
    let last = z.len() - 1;
    if z[0] > m.z_min {
        let msg = format!(
            "expected a number <= z_min = {} [m] (the table must cover [z_min, z_max]), found {}",
            m.z_min, z[0]
        );
        return Err(s.elem_err("z", 0, msg, "table starts above z_min"));
    }
    if z[last] < m.z_max {
        let msg = format!(
            "expected a number >= z_max = {} [m] (the table must cover [z_min, z_max]), found {}",
            m.z_max, z[last]
        );
        return Err(s.elem_err("z", last, msg, "table ends below z_max"));
    }
    Ok(())
}

fn check_drive(s: &Sect, supply: &Supply, coil: &Coil) -> Res<()> {
    if supply.drive == Drive::Current && coil.eddy <= 0.0 {
        let msg = "drive \"current\" requires coil.eddy > 0: with k_e = 0 the flux is an \
                   algebraic function of the current, not a state, so a current-driven model \
                   has no flux dynamics; use drive = \"voltage\" or give coil.eddy > 0";
        return Err(s.err("drive", msg, "needs coil.eddy > 0"));
    }
    Ok(())
}

// ------------------------------------------------------------ the machinery

/// What a number must satisfy; its text is the "expected …" of messages.
#[derive(Clone, Copy)]
enum Bound {
    Any,
    Positive,
    Negative,
    NonNegative,
    /// In [0, 1].
    Unit,
    /// In [0, 1).
    UnitOpen,
    /// In (0, 1].
    UnitLeftOpen,
    /// Strictly above another key's value.
    Above(&'static str, f64),
}

impl Bound {
    /// The parser's bound for a schema domain; `lower` is the value of the
    /// key an `Above` domain names.
    fn of(domain: schema::Domain, lower: f64) -> Bound {
        match domain {
            schema::Domain::Any => Bound::Any,
            schema::Domain::Positive => Bound::Positive,
            schema::Domain::Negative => Bound::Negative,
            schema::Domain::NonNegative => Bound::NonNegative,
            schema::Domain::Unit => Bound::Unit,
            schema::Domain::UnitOpen => Bound::UnitOpen,
            schema::Domain::UnitLeftOpen => Bound::UnitLeftOpen,
            schema::Domain::Above(other) => {
                Bound::Above(other.rsplit_once('.').map_or(other, |(_, k)| k), lower)
            }
        }
    }

    fn admits(self, x: f64) -> bool {
        match self {
            Bound::Any => true,
            Bound::Positive => x > 0.0,
            Bound::Negative => x < 0.0,
            Bound::NonNegative => x >= 0.0,
            Bound::Unit => (0.0..=1.0).contains(&x),
            Bound::UnitOpen => (0.0..1.0).contains(&x),
            Bound::UnitLeftOpen => x > 0.0 && x <= 1.0,
            Bound::Above(_, lower) => x > lower,
        }
    }

    fn describe(self) -> String {
        match self {
            Bound::Any => "a number".into(),
            Bound::Positive => "a number > 0".into(),
            Bound::Negative => "a number < 0".into(),
            Bound::NonNegative => "a number >= 0".into(),
            Bound::Unit => "a number in [0, 1]".into(),
            Bound::UnitOpen => "a number in [0, 1)".into(),
            Bound::UnitLeftOpen => "a number in (0, 1]".into(),
            Bound::Above(other, lower) => format!("a number > {other} (= {lower})"),
        }
    }
}

fn expected(bound: Bound, unit: &str) -> String {
    format!("expected {} [{unit}]", bound.describe())
}

struct Ctx<'a> {
    file: &'a str,
    text: &'a str,
}

impl Ctx<'_> {
    fn err(
        &self,
        key: String,
        span: Range<usize>,
        msg: impl Into<String>,
        label: &str,
    ) -> DescriptionError {
        DescriptionError::at(self.file, self.text, key, span, msg, label)
    }

    /// How a value reads in a message: numbers as written, others by type.
    fn found(&self, value: &Spanned<DeValue>) -> String {
        match value.get_ref() {
            DeValue::Integer(_) | DeValue::Float(_) => self
                .text
                .get(value.span())
                .unwrap_or("?")
                .trim()
                .to_string(),
            DeValue::String(s) => format!("the string {s:?}"),
            DeValue::Boolean(b) => format!("the boolean {b}"),
            DeValue::Datetime(d) => format!("the datetime {d}"),
            DeValue::Array(_) => "an array".into(),
            DeValue::Table(_) => "a table".into(),
        }
    }

    /// A finite number within `bound` (integers accepted), or an error about
    /// `key` at `span`.
    fn number(
        &self,
        key: String,
        span: Range<usize>,
        value: &Spanned<DeValue>,
        bound: Bound,
        unit: &str,
    ) -> Res<f64> {
        let found = self.found(value);
        let expect = expected(bound, unit);
        let label = format!("expected {}", bound.describe());
        match as_number(value.get_ref()) {
            None => Err(self.err(key, span, format!("{expect}, found {found}"), &label)),
            Some(x) if !x.is_finite() => {
                let msg = format!("{expect}, found {found} (NaN and infinities are not allowed)");
                Err(self.err(key, span, msg, "not a finite number"))
            }
            Some(x) if !bound.admits(x) => {
                Err(self.err(key, span, format!("{expect}, found {found}"), &label))
            }
            Some(x) => Ok(x),
        }
    }
}

fn as_number(value: &DeValue) -> Option<f64> {
    match value {
        DeValue::Integer(i) => match i64::from_str_radix(i.as_str(), i.radix()) {
            Ok(n) => Some(n as f64),
            Err(_) if i.radix() == 10 => i.as_str().parse().ok(),
            Err(_) => u64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|n| n as f64),
        },
        DeValue::Float(f) => f.as_str().parse().ok(),
        _ => None,
    }
}

type Entry<'a> = (&'a Spanned<DeString<'a>>, &'a Spanned<DeValue<'a>>);

/// A table of the document (the root or a section) and where it is.
struct Sect<'a> {
    ctx: &'a Ctx<'a>,
    /// "" for the root.
    name: &'a str,
    table: &'a DeTable<'a>,
    /// The section header (or inline table); 0..0 for the root.
    span: Range<usize>,
}

impl<'a> Sect<'a> {
    fn full_key(&self, key: &str) -> String {
        if self.name.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.name)
        }
    }

    fn entry(&self, key: &str) -> Option<Entry<'a>> {
        self.table.get_key_value(key)
    }

    /// The key and, when on the same line, its value.
    fn key_span(&self, key: &str) -> Range<usize> {
        let Some((k, v)) = self.entry(key) else {
            return self.span.clone();
        };
        let (k, v) = (k.span(), v.span());
        let (start, end) = (k.start.min(v.start), k.end.max(v.end));
        match self.ctx.text.get(start..end) {
            Some(t) if !t.contains('\n') => start..end,
            _ => k,
        }
    }

    fn err(&self, key: &str, msg: impl Into<String>, label: &str) -> DescriptionError {
        self.ctx
            .err(self.full_key(key), self.key_span(key), msg, label)
    }

    fn elem_err(
        &self,
        key: &str,
        index: usize,
        msg: impl Into<String>,
        label: &str,
    ) -> DescriptionError {
        let span = self
            .entry(key)
            .and_then(|(_, v)| v.get_ref().as_array()?.get(index).map(|e| e.span()))
            .unwrap_or_else(|| self.key_span(key));
        self.ctx
            .err(format!("{}[{index}]", self.full_key(key)), span, msg, label)
    }

    fn missing(&self, key: &str, what: &str) -> DescriptionError {
        let place = if self.name.is_empty() {
            "at the top level".to_string()
        } else {
            format!("in section [{}]", self.name)
        };
        let msg = format!("missing required key {place}: expected {what}");
        self.ctx.err(
            self.full_key(key),
            self.span.clone(),
            msg,
            &format!("`{key}` is missing"),
        )
    }

    /// The required sub-table `name` of the root.
    fn section(&self, name: &'a str) -> Res<Sect<'a>> {
        let Some((_, value)) = self.entry(name) else {
            let msg = format!(
                "missing required section [{name}] (required sections: [coil], [gap], [core], \
                 [mechanics], [supply])"
            );
            return Err(self.ctx.err(name.to_string(), 0..0, msg, "section missing"));
        };
        let Some(table) = value.get_ref().as_table() else {
            let msg = format!("expected a table [{name}], found {}", self.ctx.found(value));
            return Err(self.err(name, msg, "expected a table"));
        };
        Ok(Sect {
            ctx: self.ctx,
            name,
            table,
            span: value.span(),
        })
    }

    /// The sub-table `key` of this section, named `full` in messages, which
    /// must be present iff `required` (`needed_by` says which entries of
    /// `estimators` ask for it).
    fn sub_section(
        &self,
        key: &str,
        full: &'static str,
        required: bool,
        needed_by: &str,
    ) -> Res<Option<Sect<'a>>> {
        let Some((_, value)) = self.entry(key) else {
            if !required {
                return Ok(None);
            }
            let msg = format!(
                "missing required section [{full}]: {}.estimators lists {needed_by}, which \
                 needs its parameters (see docs/reference/description.md)",
                self.name
            );
            return Err(self
                .ctx
                .err(full.to_string(), self.span.clone(), msg, "section missing"));
        };
        let Some(table) = value.get_ref().as_table() else {
            let msg = format!("expected a table [{full}], found {}", self.ctx.found(value));
            return Err(self.err(key, msg, "expected a table"));
        };
        if !required {
            let msg = format!(
                "section [{full}] is given but {}.estimators does not list {needed_by}: \
                 add it there or remove the section",
                self.name
            );
            return Err(self.err(key, msg, "not used by any estimator"));
        }
        Ok(Some(Sect {
            ctx: self.ctx,
            name: full,
            table,
            span: value.span(),
        }))
    }

    /// The optional sub-table `name` of the root.
    fn opt_section(&self, name: &'a str) -> Res<Option<Sect<'a>>> {
        if self.entry(name).is_none() {
            return Ok(None);
        }
        self.section(name).map(Some)
    }

    /// An optional, non-empty array of distinct strings among `allowed`, in
    /// the order given.
    fn names(&self, key: &str, what: &str, at_least: &str) -> Res<Option<Vec<&'static str>>> {
        let allowed = schema::values(&self.full_key(key));
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        let list = quoted_list(allowed);
        let Some(items) = value.get_ref().as_array() else {
            let msg = format!(
                "expected an array of strings among {list}, found {}",
                self.ctx.found(value)
            );
            return Err(self.err(key, msg, "expected an array"));
        };
        if items.is_empty() {
            let msg = format!("expected a non-empty array ({at_least}) among {list}, found []");
            return Err(self.err(key, msg, "empty"));
        }
        let full = self.full_key(key);
        let mut out: Vec<&'static str> = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let elem = |msg: String, label: &str| {
                self.ctx
                    .err(format!("{full}[{i}]"), item.span(), msg, label)
            };
            let Some(text) = item.get_ref().as_str() else {
                let msg = format!(
                    "expected a string, one of {list}, found {}",
                    self.ctx.found(item)
                );
                return Err(elem(msg, "expected a string"));
            };
            let Some(name) = allowed.iter().find(|a| **a == text) else {
                let msg = format!("unknown {what} \"{text}\"; expected one of {list}");
                return Err(elem(msg, &format!("unknown {what}")));
            };
            if let Some(first) = out.iter().position(|o| o == name) {
                let msg = format!(
                    "duplicate {what} \"{text}\" (already given as {full}[{first}]); each may \
                     appear once"
                );
                return Err(elem(msg, "duplicate"));
            }
            out.push(name);
        }
        Ok(Some(out))
    }

    /// Rejects keys the schema does not allow in this section (with its
    /// `model` = `variant`), reporting the first in document order.
    /// Unknown keys, against the keys of every variant of the section.
    fn check_keys_any_variant(&self, context: &str) -> Res<()> {
        let allowed: Vec<&str> = schema::KEYS
            .iter()
            .filter(|k| k.section() == self.name)
            .map(schema::Key::name)
            .collect();
        self.reject_unknown(&allowed, context)
    }

    fn check_keys(&self, variant: Option<&str>, context: &str) -> Res<()> {
        self.reject_unknown(&schema::keys_of(self.name, variant), context)
    }

    fn reject_unknown(&self, allowed: &[&str], context: &str) -> Res<()> {
        let unknown = self
            .table
            .iter()
            .filter(|(k, _)| !allowed.contains(&k.get_ref().as_ref()))
            .min_by_key(|(k, _)| k.span().start);
        let Some((key, _)) = unknown else {
            return Ok(());
        };
        let msg = format!(
            "unknown key; allowed keys {context}: {}",
            allowed.join(", ")
        );
        let full = self.full_key(key.get_ref());
        let err = self.ctx.err(full, key.span(), msg, "unknown key");
        match closest(key.get_ref(), allowed) {
            Some(near) => Err(err.with_help(format!("did you mean `{near}`?"))),
            None => Err(err),
        }
    }

    /// The schema's entry for `key` of this section.
    fn spec(&self, key: &str) -> &'static schema::Key {
        schema::key(&self.full_key(key))
    }

    /// The schema's bound of `key` (an `Above` bound needs its value: see
    /// [`Sect::req_above`]).
    fn bound(&self, key: &str) -> Bound {
        Bound::of(self.spec(key).domain, f64::NEG_INFINITY)
    }

    /// An optional number, with the schema's bound and unit.
    fn opt(&self, key: &str) -> Res<Option<f64>> {
        self.opt_num(key, self.bound(key), self.spec(key).unit)
    }

    /// A required number, with the schema's bound and unit.
    fn req(&self, key: &str) -> Res<f64> {
        self.num(key, self.bound(key), self.spec(key).unit)
    }

    /// A required number in `unit` (where the unit follows `supply.drive`).
    fn req_in(&self, key: &str, unit: &str) -> Res<f64> {
        self.num(key, self.bound(key), unit)
    }

    /// A required number above `lower`, the value of the key the schema's
    /// `Above` bound names.
    fn req_above(&self, key: &str, lower: f64) -> Res<f64> {
        self.req_above_in(key, lower, self.spec(key).unit)
    }

    fn req_above_in(&self, key: &str, lower: f64, unit: &str) -> Res<f64> {
        self.num(key, Bound::of(self.spec(key).domain, lower), unit)
    }

    /// An optional number with the schema's default.
    fn or_default(&self, key: &str) -> Res<f64> {
        let spec = self.spec(key);
        let schema::Presence::Default(default) = spec.presence else {
            unreachable!("`{}` has no default in the schema", spec.path);
        };
        self.num_or(key, self.bound(key), spec.unit, default)
    }

    /// A required array of numbers, with the schema's bound and unit.
    fn req_array(&self, key: &str) -> Res<Vec<f64>> {
        self.array(key, self.bound(key), self.spec(key).unit)
    }

    /// An optional array of numbers, with the schema's bound and unit.
    fn opt_numbers(&self, key: &str) -> Res<Option<Vec<f64>>> {
        self.opt_array(key, self.bound(key), self.spec(key).unit)
    }

    fn opt_num(&self, key: &str, bound: Bound, unit: &str) -> Res<Option<f64>> {
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        let (full, span) = (self.full_key(key), self.key_span(key));
        self.ctx.number(full, span, value, bound, unit).map(Some)
    }

    fn num(&self, key: &str, bound: Bound, unit: &str) -> Res<f64> {
        let x = self.opt_num(key, bound, unit)?;
        x.ok_or_else(|| self.missing(key, &format!("{} [{unit}]", bound.describe())))
    }

    fn num_or(&self, key: &str, bound: Bound, unit: &str, default: f64) -> Res<f64> {
        Ok(self.opt_num(key, bound, unit)?.unwrap_or(default))
    }

    /// A required string among `allowed`.
    fn choice(&self, key: &str, what: &str) -> Res<&'static str> {
        let list = quoted_list(schema::values(&self.full_key(key)));
        self.opt_choice(key, what)?
            .ok_or_else(|| self.missing(key, &format!("one of {list}")))
    }

    /// An optional boolean.
    fn opt_bool(&self, key: &str) -> Res<Option<bool>> {
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        match value.get_ref() {
            DeValue::Boolean(b) => Ok(Some(*b)),
            _ => {
                let msg = format!("expected a boolean, found {}", self.ctx.found(value));
                Err(self.err(key, msg, "expected true or false"))
            }
        }
    }

    /// An optional string among `allowed`.
    fn opt_choice(&self, key: &str, what: &str) -> Res<Option<&'static str>> {
        let allowed = schema::values(&self.full_key(key));
        let list = quoted_list(allowed);
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        let Some(text) = value.get_ref().as_str() else {
            let msg = format!(
                "expected a string, one of {list}, found {}",
                self.ctx.found(value)
            );
            return Err(self.err(key, msg, "expected a string"));
        };
        match allowed.iter().find(|a| **a == text) {
            Some(a) => Ok(Some(a)),
            None => {
                let msg = format!("unknown {what} \"{text}\"; expected one of {list}");
                Err(self.err(key, msg, &format!("unknown {what}")))
            }
        }
    }

    fn array(&self, key: &str, bound: Bound, unit: &str) -> Res<Vec<f64>> {
        let what = format!("an array of numbers [{unit}]");
        self.opt_array(key, bound, unit)?
            .ok_or_else(|| self.missing(key, &what))
    }

    fn opt_array(&self, key: &str, bound: Bound, unit: &str) -> Res<Option<Vec<f64>>> {
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        let Some(items) = value.get_ref().as_array() else {
            let msg = format!(
                "expected an array of numbers [{unit}], found {}",
                self.ctx.found(value)
            );
            return Err(self.err(key, msg, "expected an array"));
        };
        let full = self.full_key(key);
        let numbers = items
            .iter()
            .enumerate()
            .map(|(i, item)| {
                self.ctx
                    .number(format!("{full}[{i}]"), item.span(), item, bound, unit)
            })
            .collect::<Res<Vec<f64>>>()?;
        Ok(Some(numbers))
    }

    fn same_length(&self, key: &str, values: &[f64], n: usize) -> Res<()> {
        if values.len() == n {
            return Ok(());
        }
        let msg = format!(
            "expected {n} values (as many as {}), found {}",
            self.full_key("z"),
            values.len()
        );
        Err(self.err(key, msg, "length differs from `z`"))
    }

    fn strictly_increasing(&self, key: &str, values: &[f64], why: &str) -> Res<()> {
        let full = self.full_key(key);
        for i in 1..values.len() {
            if values[i] <= values[i - 1] {
                let msg = format!(
                    "expected strictly increasing values{why}: {full}[{i}] = {} is not > \
                     {full}[{}] = {}",
                    values[i],
                    i - 1,
                    values[i - 1]
                );
                return Err(self.elem_err(key, i, msg, "not increasing"));
            }
        }
        Ok(())
    }
}

/// `"a", "b", "c"`.
fn quoted_list(allowed: &[&str]) -> String {
    allowed
        .iter()
        .map(|a| format!("\"{a}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The allowed key nearest to a misspelt one (at most 2 edits away).
fn closest<'k>(key: &str, allowed: &[&'k str]) -> Option<&'k str> {
    allowed
        .iter()
        .map(|a| (edit_distance(key, a), *a))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
        .map(|(_, a)| a)
}

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != *cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn misspelt_keys_get_a_suggestion() {
        assert_eq!(edit_distance("resistence", "resistance"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(
            closest("stifness", &["mass", "stiffness"]),
            Some("stiffness")
        );
        assert_eq!(closest("inductance", &["turns", "resistance"]), None);
    }

    #[test]
    fn help_is_attached_to_unknown_keys() {
        use miette::Diagnostic;
        let text = "name = \"v\"\nnme = 1\n";
        let err = parse_str(text, "t.toml").unwrap_err();
        assert_eq!(err.key(), "nme");
        let help = err.help().map(|h| h.to_string());
        assert_eq!(help.as_deref(), Some("did you mean `name`?"));
    }
}
