//! The run-to-run self-calibration as emitted Rust (`[controller]
//! self_calibration`, a rendering of `designer::calibrate::CalibrationDesign`
//! with the innovations update): the file's `calibration!` macro (θ's keys,
//! the design's values θ_d as the `params!` consts, the domain, the record's
//! capacity and the runtime's `calibrate::Settings`), and θ as the one
//! argument `theta: &[f; P]` of the law's and the filter model's functions
//! ([`theta_args`]), which the module's `Design` and `Model` carry as a field
//! (θ_d their `const` default). The update itself is
//! `reldesign_runtime::calibrate::innovations`, written once.

use designer::calibrate::CalibrationDesign;
use designer::model::Params;
use designer::sym::Id;

use crate::emit::macro_literal;
use crate::error::EmitError;
use crate::names::const_name;

/// (local name, symbol) of each adapted parameter in θ's order: the
/// argument the emitted functions destructure (`emit::Theta`).
pub(crate) fn theta_args(
    params: &Params,
    c: &CalibrationDesign,
) -> Result<Vec<(String, Id)>, EmitError> {
    c.parameters
        .iter()
        .map(|a| {
            let id = params
                .symbol(a.symbol)
                .ok_or_else(|| EmitError::UnboundSymbol(a.symbol.to_owned()))?;
            Ok((const_name(a.symbol)?.to_lowercase(), id))
        })
        .collect()
}

/// The symbols of θ (to leave out of a function's folded parameters).
pub(crate) fn theta_symbols(theta: &[(String, Id)]) -> Vec<Id> {
    theta.iter().map(|t| t.1).collect()
}

/// `macro_rules! calibration`: θ's keys, θ_d, the domain, the record's
/// capacity and the runtime's settings, written once for every float module
/// that invokes it (after `params!`).
pub fn calibration_macro(name: &str, c: &CalibrationDesign) -> Result<String, EmitError> {
    let p = c.parameters.len();
    let mut list = String::new();
    let (mut keys, mut nominal, mut lower, mut upper) = (vec![], vec![], vec![], vec![]);
    for a in &c.parameters {
        let (lo, hi) = (
            macro_literal(a.key, a.lower)?,
            macro_literal(a.key, a.upper)?,
        );
        list.push_str(&format!(
            "        /// - `{}` (`{}`): {} within [{lo}, {hi}]\n",
            a.key,
            a.symbol,
            macro_literal(a.key, a.nominal)?,
        ));
        keys.push(format!("\"{}\"", a.key));
        nominal.push(const_name(a.symbol)?);
        lower.push(lo);
        upper.push(hi);
    }
    let array = |items: &[String]| -> String {
        let mut s = String::from("[\n");
        for item in items {
            s.push_str(&format!("            {item},\n"));
        }
        s.push_str("        ]");
        s
    };
    let settings = format!(
        "        pub const CALIBRATION: reldesign_runtime::calibrate::Settings<$f, {p}> =\n\
         \x20           reldesign_runtime::calibrate::Settings {{\n\
         \x20               nominal: THETA_DESIGN,\n\
         \x20               lower: THETA_LOWER,\n\
         \x20               upper: THETA_UPPER,\n\
         \x20               max_step: {max_step},\n\
         \x20               sample_period: {ts},\n\
         \x20               decimation: {decimation},\n\
         \x20               z_min: Z_MIN,\n\
         \x20               z_max: Z_MAX,\n\
         \x20               iterations: {iterations},\n\
         \x20               min_samples: {min_samples},\n\
         \x20               current_limit: {current_limit},\n\
         \x20               dip_tolerance: {dip_tolerance},\n\
         \x20               dip_share: {dip_share},\n\
         \x20               motion_evidence: {motion_evidence},\n\
         \x20               difference_step: {difference_step},\n\
         \x20               unexplained: {unexplained},\n\
         \x20           }};\n",
        max_step = macro_literal("max_step", c.max_step)?,
        ts = macro_literal("sample_period", c.sample_period)?,
        decimation = c.decimation,
        iterations = c.iterations,
        min_samples = c.min_samples,
        current_limit = macro_literal("current_limit", c.current_limit)?,
        dip_tolerance = macro_literal("dip_tolerance", c.dip_tolerance)?,
        dip_share = macro_literal("dip_share", c.dip_share)?,
        motion_evidence = macro_literal("motion_evidence", c.motion_evidence)?,
        difference_step = macro_literal("difference_step", c.difference_step)?,
        unexplained = if c.unexplained.is_finite() {
            macro_literal("unexplained", c.unexplained)?
        } else {
            "$f::INFINITY".to_owned()
        },
    );
    let innovations = c.method == designer::calibrate::Method::Innovations;
    let (which, starts, record, update, method) = if innovations {
        (
            "every physics parameter the filter's model reads, each",
            "`Design` and `Model` start there.",
            "Samples a run's `Record` holds: every sample of every operation's window.",
            "(`reldesign_runtime::calibrate::innovations`): steps of at\n\
             \x20       /// most `max_step`·θ_d, `iterations` Levenberg–Marquardt steps, forward differences\n\
             \x20       /// of `difference_step`·θ_d;",
            "the innovations update: θ chosen so that the filter's one-step current\n\
             /// predictions over a run are right",
        )
    } else {
        (
            "the parameters the planned operations' current identifies, each",
            "`Design` starts there.",
            "Samples an operation's `Record` holds: every `decimation`-th sample of its window.",
            "(`reldesign_runtime::calibrate::calibrate`): steps of at\n\
             \x20       /// most `max_step`·θ_d, `iterations` Levenberg–Marquardt steps on the symbolic\n\
             \x20       /// sensitivities;",
            "the replay update: θ chosen so that the model, replayed over an\n\
             /// operation's measured voltage, predicts its measured current",
        )
    };
    let body = format!(
        "        /// The parameters θ the self-calibration adapts, in θ's order (their\n\
         \x20       /// description keys): {which}\n\
         \x20       /// from the design's value within its physical domain:\n\
         {list}\
         \x20       pub const ADAPTED: [&str; {p}] = {keys};\n\
         \x20       /// θ_d: the design's values (the `params!` consts); {starts}\n\
         \x20       pub const THETA_DESIGN: [$f; {p}] = {nominal};\n\
         \x20       /// The lower end of θ's domain: the update never leaves [THETA_LOWER, THETA_UPPER].\n\
         \x20       #[allow(clippy::excessive_precision)]\n\
         \x20       pub const THETA_LOWER: [$f; {p}] = {lower};\n\
         \x20       /// The upper end of θ's domain.\n\
         \x20       #[allow(clippy::excessive_precision)]\n\
         \x20       pub const THETA_UPPER: [$f; {p}] = {upper};\n\
         \x20       /// {record}\n\
         \x20       /// RAM: 2·RECORD_CAPACITY floats.\n\
         \x20       pub const RECORD_CAPACITY: usize = {capacity};\n\
         \x20       /// The update's settings {update} a record shorter than `min_samples`, with a current\n\
         \x20       /// at `current_limit` [A] (a saturated ADC) or more than `dip_share` of its samples\n\
         \x20       /// `dip_tolerance` [V] below the command (a supply dip) is refused. An update that\n\
         \x20       /// leaves a mean squared current error above `unexplained` [A²] (a multiple of σ_i²; ∞:\n\
         \x20       /// never) has not found a model that explains the valve's current, whatever θ:\n\
         \x20       /// `Calibration::unexplained` counts such updates in a row.\n\
         \x20       #[allow(clippy::excessive_precision)]\n\
         {settings}",
        keys = array(&keys),
        nominal = array(&nominal),
        lower = array(&lower),
        upper = array(&upper),
        capacity = c.capacity,
    );
    Ok(format!(
        "/// The run-to-run self-calibration of `{name}` (`[controller] self_calibration`,\n\
         /// {method}), declared in each float module as\n\
         /// `calibration!(f64)` / `calibration!(f32)` after `params!`.\n\
         macro_rules! calibration {{\n    ($f:ident) => {{\n{body}    }};\n}}\n"
    ))
}
