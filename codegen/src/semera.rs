//! The model-free estimators of semera-electromagnetic-estimation as emitted
//! Rust: settings only. The algorithms (SEMERA, [SE Alg. 1]; the integral
//! estimator, [SE Alg. 2]) are `reldesign_runtime::{semera, integral}`,
//! generic over the float; [`emit_semera`] writes what a description adds:
//!
//! - `macro_rules! settings`: the `[observer]`, `[observer.semera]` and
//!   `[observer.integral]` values, one per line (the same line serves f32 and
//!   f64, like `params!`), as the runtime's `semera::Settings` (`SEMERA`) and
//!   `integral::Settings` (`INTEGRAL`); the coil's N is `params!`'s `N`;
//! - per float, `pub mod f64 { … }` / `pub mod f32 { … }`: `params!`,
//!   `settings!` and the types `Estimate`, `Semera`, `Integral` (aliases of
//!   the runtime's), used as `Semera::new(&SEMERA)`, `.step(v, i)`.
//!
//! The caller wraps the items in a module of its own (e.g. `pub mod
//! estimators { … }`) in a file whose top level defines `params!` (the
//! model parameters).

use std::fmt::Write as _;

use designer::description::{Description, Estimator, FloatType, IntegralSettings, SemeraSettings};

use crate::float::Float;

/// Everything [`emit_semera`] needs.
#[derive(Debug, Clone, PartialEq)]
pub struct SemeraInput<'a> {
    /// The description's name (docs only).
    pub name: &'a str,
    /// Δ [s].
    pub sample_period: f64,
    /// σ_v [V].
    pub voltage_noise: f64,
    /// σ_i [A].
    pub current_noise: f64,
    /// N (checked here; emitted by `params!`).
    pub turns: f64,
    /// Emit `Semera` with these parameters.
    pub semera: Option<SemeraSettings>,
    /// Emit `Integral` with these parameters.
    pub integral: Option<IntegralSettings>,
    /// Emitted float types, in this order (duplicates ignored).
    pub floats: Vec<Float>,
}

impl<'a> SemeraInput<'a> {
    /// The estimators a description's `[observer]` asks for among "semera"
    /// and "integral"; `None` when it asks for neither (or has no
    /// `[observer]`).
    pub fn from_description(d: &'a Description) -> Option<SemeraInput<'a>> {
        let o = d.observer.as_ref()?;
        let asked = |e: Estimator| o.estimators.contains(&e);
        let semera = o.semera.filter(|_| asked(Estimator::Semera));
        let integral = o.integral.filter(|_| asked(Estimator::Integral));
        if semera.is_none() && integral.is_none() {
            return None;
        }
        Some(SemeraInput {
            name: &d.name,
            sample_period: o.sample_period,
            voltage_noise: o.voltage_noise,
            current_noise: o.current_noise,
            turns: d.coil.turns,
            semera,
            integral,
            floats: o
                .floats
                .iter()
                .map(|f| match f {
                    FloatType::F32 => Float::F32,
                    FloatType::F64 => Float::F64,
                })
                .collect(),
        })
    }
}

/// Why the estimators could not be emitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SemeraError {
    #[error("no estimator to emit (neither SEMERA nor the integral estimator is requested)")]
    NoEstimator,
    #[error("no float type to emit")]
    NoFloat,
    #[error("the estimator parameter `{name}` = {value} is not finite in an emitted float type")]
    BadValue { name: String, value: f64 },
}

/// One setting: its TOML key (the runtime's field) and its `//` note.
type Key = (&'static str, &'static str);

/// `[observer]`: consts both estimators read, `observer.<key>`.
#[rustfmt::skip]
const OBSERVER: [Key; 3] = [
    ("sample_period", "Δ [s], call `step` once per sample."),
    ("voltage_noise", "σ_v [V], in the gain [SE 43]."),
    ("current_noise", "σ_i [A], the CI detector's unit."),
];

/// `[observer.semera]`, in the runtime's field order.
#[rustfmt::skip]
const SEMERA: [Key; 7] = [
    ("initial_resistance", "r̄₀ [Ω], [SE 25]"),
    ("initial_resistance_std", "σ_r0 [Ω], [SE 26]"),
    ("initial_inductance", "l̄₀ [H], [SE 25], the expert rule's l̂"),
    ("initial_inductance_std", "σ_l0 [H], [SE 26]"),
    ("resistance_rate_std", "σ_ṙ [Ω/s], [SE 24]"),
    ("inductance_accel_std", "σ_l̈ [H/s²], [SE 24]"),
    ("ci_sigmas", "n_σ: the CI detector's half-width in σ_i"),
];

/// `[observer.integral]`, in the runtime's field order.
#[rustfmt::skip]
const INTEGRAL: [Key; 5] = [
    ("initial_resistance", "r̄₀ [Ω] until the first [SE 47]"),
    ("initial_inductance", "l̄₀ [H], the expert rule's l̂"),
    ("initial_flux_linkage", "λ₀ [Wb] at each reset [SE 46]"),
    ("ci_sigmas", "n_σ: the CI detector's half-width in σ_i"),
    ("energize_threshold", "[V]: u rising above it starts an operation"),
];

/// One estimator: its runtime module and type, what its `Settings` const
/// reads from `[observer]`, its own section's keys and their values.
struct Section {
    module: &'static str,
    ty: &'static str,
    doc: &'static str,
    observer: &'static [&'static str],
    keys: &'static [Key],
    values: Vec<f64>,
}

/// The estimators `input` asks for, SEMERA first.
fn sections(input: &SemeraInput) -> Vec<Section> {
    let semera = input.semera.map(|s| Section {
        module: "semera",
        ty: "Semera",
        doc: "SEMERA [SE Alg. 1]",
        observer: &["sample_period", "voltage_noise", "current_noise"],
        keys: &SEMERA,
        values: vec![
            s.initial_resistance,
            s.initial_resistance_std,
            s.initial_inductance,
            s.initial_inductance_std,
            s.resistance_rate_std,
            s.inductance_accel_std,
            s.ci_sigmas,
        ],
    });
    let integral = input.integral.map(|g| Section {
        module: "integral",
        ty: "Integral",
        doc: "The integral estimator [SE Alg. 2]",
        observer: &["sample_period", "current_noise"],
        keys: &INTEGRAL,
        values: vec![
            g.initial_resistance,
            g.initial_inductance,
            g.initial_flux_linkage,
            g.ci_sigmas,
            g.energize_threshold,
        ],
    });
    semera.into_iter().chain(integral).collect()
}

/// `[observer]`'s values in the order of [`OBSERVER`].
fn observer_values(input: &SemeraInput) -> [f64; 3] {
    [
        input.sample_period,
        input.voltage_noise,
        input.current_noise,
    ]
}

/// The settings macro, then one module per float type (in the order of
/// `input.floats`): deterministic text.
pub fn emit_semera(input: &SemeraInput) -> Result<String, SemeraError> {
    check(input)?;
    let sections = sections(input);
    let mut floats: Vec<Float> = Vec::new();
    for &f in &input.floats {
        if !floats.contains(&f) {
            floats.push(f);
        }
    }
    let mut out = settings_macro(input, &sections);
    for float in floats {
        out.push('\n');
        out.push_str(&float_module(input.name, &sections, float));
    }
    Ok(out)
}

/// Shortest round-trip f64 text with sign (in an `f32` module the literal
/// rounds to the nearest `f32`, as in `params!`).
fn literal(v: f64) -> String {
    let v = if v == 0.0 { 0.0 } else { v };
    format!("{v:?}")
}

/// `macro_rules! settings { ($f:ty) => { … } }`: the `[observer]` consts the
/// estimators read, then each estimator's `Settings` const, one value per line.
fn settings_macro(input: &SemeraInput, sections: &[Section]) -> String {
    const I: &str = "        ";
    let mut body = String::new();
    for ((key, doc), value) in OBSERVER.iter().zip(observer_values(input)) {
        if sections.iter().any(|s| s.observer.contains(key)) {
            let _ = writeln!(body, "{I}/// `observer.{key}`: {doc}");
            let _ = writeln!(
                body,
                "{I}pub const {}: $f = {};",
                key.to_uppercase(),
                literal(value)
            );
        }
    }
    for s in sections {
        let (module, name) = (s.module, s.module.to_uppercase());
        let _ = writeln!(body, "{I}/// {}: `[observer.{module}]`.", s.doc);
        let _ = writeln!(
            body,
            "{I}pub const {name}: {module}::Settings<$f> = {module}::Settings {{"
        );
        for key in s.observer {
            let _ = writeln!(body, "{I}    {key}: {},", key.to_uppercase());
        }
        let _ = writeln!(body, "{I}    turns: N,");
        let fields: Vec<String> = s
            .keys
            .iter()
            .zip(&s.values)
            .map(|(k, v)| format!("{}: {},", k.0, literal(*v)))
            .collect();
        let width = fields.iter().map(|f| f.chars().count()).max().unwrap_or(0);
        for (field, (_, note)) in fields.iter().zip(s.keys) {
            let _ = writeln!(body, "{I}    {field:<width$} // {note}");
        }
        let _ = writeln!(body, "{I}}};");
    }
    format!(
        "/// The estimators' settings of `{name}`, one value per line, declared in each float\n\
         /// module as `settings!(f64)` / `settings!(f32)` (N is `params!`'s).\n\
         macro_rules! settings {{\n    ($f:ty) => {{\n{body}    }};\n}}\n",
        name = input.name
    )
}

/// `pub mod f32 { … }`: the parameters, the settings and the runtime's types.
fn float_module(name: &str, sections: &[Section], float: Float) -> String {
    let f = float.name();
    let mut uses: Vec<&str> = vec!["semera"];
    let mut aliases = format!(
        "\n    /// The estimate of one sample: r̂, l̂, λ̂, φ̂ = λ̂/N, R̂ = N²/l̂ and the CI detector's `valid`.\n\
         \x20   pub type Estimate = semera::Estimate<{f}>;\n"
    );
    for s in sections {
        let (module, ty, c) = (s.module, s.ty, s.module.to_uppercase());
        let _ = write!(
            aliases,
            "\n    /// {}: `{ty}::new(&{c})`, then `step(v, i)` every Δ.\n    pub type {ty} = {module}::{ty}<{f}>;\n",
            s.doc
        );
        if !uses.contains(&module) {
            uses.push(module);
        }
    }
    uses.sort_unstable();
    format!(
        "/// The model-free estimators of `{name}` in {f} [SE §II].\n\
         pub mod {f} {{\n    use reldesign_runtime::{{{uses}}};\n\n    params!({f});\n    settings!({f});\n{aliases}}}\n",
        uses = uses.join(", "),
    )
}

/// The parser bounds each value; what it cannot know is the emitted float:
/// every value must be finite in each (an f32 literal out of range does not
/// compile).
fn check(input: &SemeraInput) -> Result<(), SemeraError> {
    if input.semera.is_none() && input.integral.is_none() {
        return Err(SemeraError::NoEstimator);
    }
    if input.floats.is_empty() {
        return Err(SemeraError::NoFloat);
    }
    let observer = OBSERVER.iter().zip(observer_values(input));
    let mut values: Vec<(String, f64)> = observer
        .map(|(k, v)| (format!("observer.{}", k.0), v))
        .collect();
    values.push(("coil.turns".to_owned(), input.turns));
    for s in sections(input) {
        let keyed = s.keys.iter().zip(&s.values);
        values.extend(keyed.map(|(k, v)| (format!("observer.{}.{}", s.module, k.0), *v)));
    }
    let finite = |v: f64| input.floats.iter().all(|f| f.magnitude_text(v).is_some());
    match values.into_iter().find(|&(_, v)| !finite(v)) {
        Some((name, value)) => Err(SemeraError::BadValue { name, value }),
        None => Ok(()),
    }
}
