//! The model-free estimators of semera-electromagnetic-estimation as emitted
//! Rust: [`emit_semera`] writes, per float type, a module `pub mod f64 { … }`
//! / `pub mod f32 { … }` holding
//!
//! - the parameters as named consts, one per line (Δ, σ_v, σ_i, N and the
//!   `[observer.semera]` / `[observer.integral]` values), and the constants
//!   the step needs, derived from them in const expressions (1/Δ, σ_v²,
//!   (σ_ṙΔ)², (σ_l̈Δ²)², n_σσ_i, N², 1/N, the prior P₀ of (26));
//! - `Estimate`: r̂, l̂, λ̂, φ̂ = λ̂/N, R̂ = N²/l̂ and the CI detector's `valid`;
//! - `Semera` (Algorithm 1, when "semera" is requested) and `Integral`
//!   (Algorithm 2, when "integral" is): `const fn new()` starts at rest,
//!   `step(v, i)` takes one sample of the coil voltage and current.
//!
//! The step is the f64 reference of `designer::observe::semera` /
//! `designer::observe::integral` operation for operation (the same
//! expressions in the same order, so the f64 module reproduces it to the
//! last bit; the module docs there state the choices the paper leaves open).
//! It is `no_std`, allocation- and panic-free (no indexing, no `as`, no
//! unwrap), with two divisions per SEMERA step (1/s, s ≥ σ_v² > 0, and
//! N²/l̂) and none by the current; the covariance update corrects its
//! rounding in the l block (Joseph form) so that the f32 step stays stable: ι → 0 (the device at rest) is the normal
//! case, handled by the expert rule. Non-finite samples are skipped as
//! missing measurements. Math goes through `reldesign_runtime::math::Real`.
//!
//! The caller wraps the items in a module of its own (e.g. `pub mod semera
//! { … }`); nothing is emitted at the top level besides the float modules.

use designer::description::{Description, Estimator, FloatType, IntegralSettings, SemeraSettings};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use crate::error::EmitError;
use crate::float::Float;
use crate::format::{format_items, space_items};

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
    /// N.
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
        let semera = o
            .estimators
            .contains(&Estimator::Semera)
            .then_some(o.semera)
            .flatten();
        let integral = o
            .estimators
            .contains(&Estimator::Integral)
            .then_some(o.integral)
            .flatten();
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
    #[error(transparent)]
    Emit(#[from] EmitError),
    #[error("no estimator to emit (neither SEMERA nor the integral estimator is requested)")]
    NoEstimator,
    #[error("no float type to emit")]
    NoFloat,
    #[error("the estimator parameter `{name}` = {value} is not finite or out of range")]
    BadValue { name: String, value: f64 },
}

/// The SEMERA and/or integral estimator modules, formatted and
/// deterministic: `pub mod f64 { … }` and/or `pub mod f32 { … }` (in the
/// order of `input.floats`).
pub fn emit_semera(input: &SemeraInput) -> Result<String, SemeraError> {
    check(input)?;
    let mut floats: Vec<Float> = Vec::new();
    for &f in &input.floats {
        if !floats.contains(&f) {
            floats.push(f);
        }
    }
    let mut tokens = TokenStream::new();
    for float in floats {
        tokens.extend(float_module(input, float)?);
    }
    let text = space_items(&format_items(tokens)?);
    Ok(annotate(&text))
}

/// `//` comments of `Semera::step` (tokens carry none): (the start of a
/// line, the comment put above it), in order.
const SEMERA_NOTES: [(&str, &str); 8] = [
    ("let h1 = ", "line 7: H_k (11)"),
    (
        "let g1 = ",
        "line 8: K̂ (43) = g/s with g = Σ Hᵀ, s = H Σ Hᵀ + σ_v²",
    ),
    (
        "let mut r = self.r;",
        "line 9: x̂_{k/k} = x̂_{k/k−1} + K̂·(z_k − H_k x̂_{k/k−1}), K̂·ν = g·(ν/s)",
    ),
    (
        "let used = ",
        "a non-finite sample is a missing measurement: prediction only",
    ),
    (
        "let b11 = ",
        "line 10: Σ_{k/k} = (I − K̂ H) Σ = B = Σ − K̂ gᵀ (symmetric: upper triangle);\n\
         the l block as the equal Joseph form B − d K̂ᵀ, d = B Hᵀ − σ_v² K̂, which is 0 up\n\
         to rounding: it undoes the cancellation in the nearly singular l block\n\
         (with B alone Σ turns indefinite in f32)",
    ),
    (
        "self.r = r;",
        "lines 11–12: x̂_{k+1/k} = F x̂_{k/k}, Σ_{k+1/k} = F Σ Fᵀ + G Q Gᵀ (21)–(24)",
    ),
    (
        "let valid = ",
        "lines 13–15: the CI detector and the expert rule",
    ),
    (
        "let lambda = ",
        "line 16 and §II-C: λ = l·ι, φ = λ/N, R = N²/l",
    ),
];

/// `//` comments of `Integral::step`.
const INTEGRAL_NOTES: [(&str, &str); 6] = [
    (
        "if v > INTEGRAL_ENERGIZE_THRESHOLD",
        "lines 10–11 of sample k − 1 (the voltage rose since): (47) and the reset",
    ),
    (
        "if self.sum_i > 0.0",
        "(47) only when S_ι is more than noise: |S_ι| > n_σ·σ_i·√m",
    ),
    (
        "if v.is_finite()",
        "line 5 (a non-finite sample is missing: nothing is summed)",
    ),
    ("let lambda = ", "line 6: (46)"),
    (
        "let valid = ",
        "lines 7–9: the CI detector, (48) or the expert rule",
    ),
    ("Estimate {", "line 12: r̂_k = r̄"),
];

/// Puts the notes' `// comment`s into the `step` of `impl Semera` and of
/// `impl Integral`: each above the first line that starts (after its indent)
/// with its anchor, searching on from the previous note.
fn annotate(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2048);
    let mut notes: &[(&str, &str)] = &[];
    let mut in_step = false;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if trimmed.starts_with("impl Semera {") {
            notes = &SEMERA_NOTES;
        } else if trimmed.starts_with("impl Integral {") {
            notes = &INTEGRAL_NOTES;
        }
        if trimmed.starts_with("pub fn ") || trimmed.starts_with("pub const fn ") {
            in_step = trimmed.starts_with("pub fn step(");
        }
        if let (true, Some(((anchor, note), rest))) = (in_step, notes.split_first()) {
            if trimmed.starts_with(anchor) {
                for part in note.lines() {
                    out.push_str(&line[..line.len() - trimmed.len()]);
                    out.push_str("// ");
                    out.push_str(part);
                    out.push('\n');
                }
                notes = rest;
            }
        }
        out.push_str(line);
    }
    out
}

fn check(input: &SemeraInput) -> Result<(), SemeraError> {
    if input.semera.is_none() && input.integral.is_none() {
        return Err(SemeraError::NoEstimator);
    }
    if input.floats.is_empty() {
        return Err(SemeraError::NoFloat);
    }
    let bad = |name: &str, value: f64| SemeraError::BadValue {
        name: name.to_owned(),
        value,
    };
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(bad(name, v))
        }
    };
    positive("sample_period", input.sample_period)?;
    positive("voltage_noise", input.voltage_noise)?;
    positive("current_noise", input.current_noise)?;
    positive("turns", input.turns)?;
    if let Some(s) = &input.semera {
        positive("semera.initial_resistance", s.initial_resistance)?;
        positive("semera.initial_resistance_std", s.initial_resistance_std)?;
        positive("semera.initial_inductance", s.initial_inductance)?;
        positive("semera.initial_inductance_std", s.initial_inductance_std)?;
        positive("semera.ci_sigmas", s.ci_sigmas)?;
        for (name, v) in [
            ("semera.resistance_rate_std", s.resistance_rate_std),
            ("semera.inductance_accel_std", s.inductance_accel_std),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, v));
            }
        }
    }
    if let Some(g) = &input.integral {
        positive("integral.initial_resistance", g.initial_resistance)?;
        positive("integral.initial_inductance", g.initial_inductance)?;
        positive("integral.ci_sigmas", g.ci_sigmas)?;
        positive("integral.energize_threshold", g.energize_threshold)?;
        if !g.initial_flux_linkage.is_finite() {
            return Err(bad("integral.initial_flux_linkage", g.initial_flux_linkage));
        }
    }
    Ok(())
}

/// `#[doc = " line"]` per line.
fn doc_attrs(text: &str) -> TokenStream {
    let mut out = TokenStream::new();
    for line in text.lines() {
        let line = format!(" {line}");
        out.extend(quote!(#[doc = #line]));
    }
    out
}

/// `pub const NAME: T = value;` with its doc: one parameter, one line.
fn param(float: Float, name: &str, value: f64, doc: &str) -> Result<TokenStream, SemeraError> {
    let ty = float.ty();
    let id = format_ident!("{name}");
    let lit = float
        .unsuffixed_signed(value)
        .ok_or_else(|| SemeraError::BadValue {
            name: format!("{name} ({})", float.name()),
            value,
        })?;
    let docs = doc_attrs(doc);
    Ok(quote!(#docs pub const #id: #ty = #lit;))
}

/// `pub const NAME: T = expression;` derived from the parameters.
fn derived(float: Float, name: &str, expr: TokenStream, doc: &str) -> TokenStream {
    let ty = float.ty();
    let id = format_ident!("{name}");
    let docs = doc_attrs(doc);
    quote!(#docs pub const #id: #ty = #expr;)
}

fn float_module(input: &SemeraInput, float: Float) -> Result<TokenStream, SemeraError> {
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let mut consts = TokenStream::new();
    consts.extend(param(
        float,
        "SAMPLE_PERIOD",
        input.sample_period,
        "Δ [s]: call `step` once per sample, every Δ.",
    )?);
    if input.semera.is_some() {
        consts.extend(param(
            float,
            "VOLTAGE_NOISE",
            input.voltage_noise,
            "σ_v [V]: standard deviation of the voltage measurement noise (43).",
        )?);
    }
    consts.extend(param(
        float,
        "CURRENT_NOISE",
        input.current_noise,
        "σ_i [A]: standard deviation of the current measurement noise (the CI detector).",
    )?);
    consts.extend(param(
        float,
        "TURNS",
        input.turns,
        "N, the coil's turns: φ = λ/N, R = N²/l (§II-C).",
    )?);
    consts.extend(derived(float, "INV_TURNS", quote!(1.0 / TURNS), "1/N."));
    consts.extend(derived(float, "TURNS_SQ", quote!(TURNS * TURNS), "N²."));

    let mut items = TokenStream::new();
    if let Some(s) = &input.semera {
        consts.extend(semera_consts(float, s)?);
        items.extend(semera_tokens(float));
    }
    if let Some(g) = &input.integral {
        consts.extend(integral_consts(float, g)?);
        items.extend(integral_tokens(float));
    }
    let doc = doc_attrs(&format!(
        "The model-free estimators of `{}` in {} (semera-electromagnetic-estimation §II).",
        input.name,
        float.name()
    ));
    Ok(quote! {
        #doc
        pub mod #module {
            use reldesign_runtime::math::Real;

            #consts

            /// The estimate of one sample.
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct Estimate {
                /// r̂ [Ω], the coil resistance.
                pub r: #ty,
                /// l̂ [H], the apparent inductance (l̄₀ under the expert rule).
                pub l: #ty,
                /// λ̂ [Wb], the flux linkage.
                pub lambda: #ty,
                /// φ̂ = λ̂/N [Wb], the magnetic flux.
                pub phi: #ty,
                /// R̂ = N²/l̂ [H⁻¹], the reluctance.
                pub reluctance: #ty,
                /// The confidence-interval detector: |ι_k| and |ι_{k−1}| both exceed n_σ·σ_i
                /// (and the sample was usable), so r̂ and l̂ come from the estimator; false
                /// under the expert rule (r̂ held, l̂ = l̄₀).
                pub valid: bool,
            }

            #items
        }
    })
}

fn semera_consts(float: Float, s: &SemeraSettings) -> Result<TokenStream, SemeraError> {
    let mut out = TokenStream::new();
    for (name, value, doc) in [
        (
            "SEMERA_INITIAL_RESISTANCE",
            s.initial_resistance,
            "r̄₀ [Ω]: expected initial resistance (25).",
        ),
        (
            "SEMERA_INITIAL_RESISTANCE_STD",
            s.initial_resistance_std,
            "σ_r0 [Ω] (26).",
        ),
        (
            "SEMERA_INITIAL_INDUCTANCE",
            s.initial_inductance,
            "l̄₀ [H]: inductance at rest (25); the expert rule's l̂.",
        ),
        (
            "SEMERA_INITIAL_INDUCTANCE_STD",
            s.initial_inductance_std,
            "σ_l0 [H] (26).",
        ),
        (
            "SEMERA_RESISTANCE_RATE_STD",
            s.resistance_rate_std,
            "σ_ṙ [Ω/s] (24).",
        ),
        (
            "SEMERA_INDUCTANCE_ACCEL_STD",
            s.inductance_accel_std,
            "σ_l̈ [H/s²] (24).",
        ),
        (
            "SEMERA_CI_SIGMAS",
            s.ci_sigmas,
            "n_σ: half-width of the current's noise interval in σ_i.",
        ),
    ] {
        out.extend(param(float, name, value, doc)?);
    }
    out.extend(derived(
        float,
        "SEMERA_INV_SAMPLE_PERIOD",
        quote!(1.0 / SAMPLE_PERIOD),
        "1/Δ (11).",
    ));
    out.extend(derived(
        float,
        "SEMERA_VOLTAGE_VARIANCE",
        quote!(VOLTAGE_NOISE * VOLTAGE_NOISE),
        "σ_v² (43).",
    ));
    out.extend(derived(
        float,
        "SEMERA_PROCESS_R",
        quote!(
            (SEMERA_RESISTANCE_RATE_STD * SAMPLE_PERIOD)
                * (SEMERA_RESISTANCE_RATE_STD * SAMPLE_PERIOD)
        ),
        "(σ_ṙ·Δ)²: G Q Gᵀ (1, 1), (23)–(24).",
    ));
    out.extend(derived(
        float,
        "SEMERA_PROCESS_L",
        quote!(
            (SEMERA_INDUCTANCE_ACCEL_STD * SAMPLE_PERIOD * SAMPLE_PERIOD)
                * (SEMERA_INDUCTANCE_ACCEL_STD * SAMPLE_PERIOD * SAMPLE_PERIOD)
        ),
        "(σ_l̈·Δ²)²: G Q Gᵀ (2, 2), (23)–(24).",
    ));
    out.extend(derived(
        float,
        "SEMERA_CI",
        quote!(SEMERA_CI_SIGMAS * CURRENT_NOISE),
        "n_σ·σ_i [A]: the CI detector's bound.",
    ));
    out.extend(derived(
        float,
        "SEMERA_VAR_R0",
        quote!(SEMERA_INITIAL_RESISTANCE_STD * SEMERA_INITIAL_RESISTANCE_STD),
        "σ²_r0: P₀ (1, 1) of (26) (ERRATA: the text prints σ_r0).",
    ));
    out.extend(derived(
        float,
        "SEMERA_VAR_L0",
        quote!(SEMERA_INITIAL_INDUCTANCE_STD * SEMERA_INITIAL_INDUCTANCE_STD),
        "σ²_l0: the l block of P₀ (26) is [[σ²_l0, σ²_l0], [σ²_l0, σ²_l0]] (l₋₁ = l₀).",
    ));
    Ok(out)
}

fn integral_consts(float: Float, g: &IntegralSettings) -> Result<TokenStream, SemeraError> {
    let mut out = TokenStream::new();
    for (name, value, doc) in [
        (
            "INTEGRAL_INITIAL_RESISTANCE",
            g.initial_resistance,
            "r̄₀ [Ω]: the resistance until the first update (47).",
        ),
        (
            "INTEGRAL_INITIAL_INDUCTANCE",
            g.initial_inductance,
            "l̄₀ [H]: the expert rule's l̂.",
        ),
        (
            "INTEGRAL_INITIAL_FLUX_LINKAGE",
            g.initial_flux_linkage,
            "λ₀ [Wb]: the flux linkage at each reset (46).",
        ),
        (
            "INTEGRAL_CI_SIGMAS",
            g.ci_sigmas,
            "n_σ: half-width of the current's noise interval in σ_i.",
        ),
        (
            "INTEGRAL_ENERGIZE_THRESHOLD",
            g.energize_threshold,
            "[V]: the voltage rising above it starts an energizing operation.",
        ),
    ] {
        out.extend(param(float, name, value, doc)?);
    }
    out.extend(derived(
        float,
        "INTEGRAL_CI",
        quote!(INTEGRAL_CI_SIGMAS * CURRENT_NOISE),
        "n_σ·σ_i [A]: the CI detector's bound.",
    ));
    out.extend(derived(
        float,
        "INTEGRAL_CI_SQ",
        quote!(INTEGRAL_CI * INTEGRAL_CI),
        "(n_σ·σ_i)²: (47) is used when S_ι² > (n_σ·σ_i)²·m (the sum is more than noise).",
    ));
    Ok(out)
}

/// `Semera`: Algorithm 1 (`designer::observe::semera`, operation for operation).
fn semera_tokens(float: Float) -> TokenStream {
    let ty = float.ty();
    quote! {
        /// SEMERA (semera Algorithm 1): Kalman estimation of x = [r, l, l₋₁] (10) from the
        /// observation u_k = H_k x_k + v_k (8)–(12), H_k = [ι_k, ι_k/Δ, −ι_{k−1}/Δ], with
        /// F of (21) (r constant, l linear in time), Q of (24) and the gain (43)
        /// K̂ = Σ Hᵀ (H Σ Hᵀ + σ_v²)⁻¹. r̂ and l̂ are the a posteriori estimates when the
        /// CI detector finds |ι_k| and |ι_{k−1}| above n_σ·σ_i; otherwise the expert rule
        /// r̂_k = r̂_{k−1}, l̂_k = l̄₀. λ̂ = l̂·ι, φ̂ = λ̂/N, R̂ = N²/l̂.
        ///
        /// A sample whose update is not finite (NaN or infinite v or i) is a missing
        /// measurement: prediction only, and the expert rule.
        #[derive(Clone, Debug, PartialEq)]
        pub struct Semera {
            /// x̂_{k+1/k} = [r, l, l₋₁]
            r: #ty,
            l: #ty,
            lp: #ty,
            /// Σ_{k+1/k}, symmetric
            p11: #ty,
            p12: #ty,
            p13: #ty,
            p22: #ty,
            p23: #ty,
            p33: #ty,
            /// ι_{k−1}
            i_prev: #ty,
            /// r̂_{k−1}
            r_hat: #ty,
        }

        impl Semera {
            /// At rest (Algorithm 1, lines 1–3): x̂_{1/0} = [r̄₀, l̄₀, l̄₀] (25),
            /// Σ_{1/0} = P₀ (26), ι₀ = 0.
            #[must_use]
            pub const fn new() -> Self {
                Semera {
                    r: SEMERA_INITIAL_RESISTANCE,
                    l: SEMERA_INITIAL_INDUCTANCE,
                    lp: SEMERA_INITIAL_INDUCTANCE,
                    p11: SEMERA_VAR_R0,
                    p12: 0.0,
                    p13: 0.0,
                    p22: SEMERA_VAR_L0,
                    p23: SEMERA_VAR_L0,
                    p33: SEMERA_VAR_L0,
                    i_prev: 0.0,
                    r_hat: SEMERA_INITIAL_RESISTANCE,
                }
            }

            /// One sample k (Algorithm 1, lines 5–16): the coil voltage u_k = `v` [V] and
            /// current ι_k = `i` [A], taken every Δ.
            #[must_use]
            pub fn step(&mut self, v: #ty, i: #ty) -> Estimate {
                let h1 = i;
                let h2 = i * SEMERA_INV_SAMPLE_PERIOD;
                let h3 = -(self.i_prev * SEMERA_INV_SAMPLE_PERIOD);
                let g1 = self.p11 * h1 + self.p12 * h2 + self.p13 * h3;
                let g2 = self.p12 * h1 + self.p22 * h2 + self.p23 * h3;
                let g3 = self.p13 * h1 + self.p23 * h2 + self.p33 * h3;
                let s = h1 * g1 + h2 * g2 + h3 * g3 + SEMERA_VOLTAGE_VARIANCE;
                let w = 1.0 / s;
                let mut r = self.r;
                let mut l = self.l;
                let mut lp = self.lp;
                let nu = v - (h1 * r + h2 * l + h3 * lp);
                let mut p11 = self.p11;
                let mut p12 = self.p12;
                let mut p13 = self.p13;
                let mut p22 = self.p22;
                let mut p23 = self.p23;
                let mut p33 = self.p33;
                let m = nu * w;
                let used = m.is_finite();
                if used {
                    let k1 = g1 * w;
                    let k2 = g2 * w;
                    let k3 = g3 * w;
                    r += g1 * m;
                    l += g2 * m;
                    lp += g3 * m;
                    let b11 = p11 - k1 * g1;
                    let b12 = p12 - k1 * g2;
                    let b13 = p13 - k1 * g3;
                    let b22 = p22 - k2 * g2;
                    let b23 = p23 - k2 * g3;
                    let b33 = p33 - k3 * g3;
                    let d2 = b12 * h1 + b22 * h2 + b23 * h3 - SEMERA_VOLTAGE_VARIANCE * k2;
                    let d3 = b13 * h1 + b23 * h2 + b33 * h3 - SEMERA_VOLTAGE_VARIANCE * k3;
                    p11 = b11;
                    p12 = b12;
                    p13 = b13;
                    p22 = b22 - d2 * k2;
                    p23 = b23 - d2 * k3;
                    p33 = b33 - d3 * k3;
                }
                self.r = r;
                self.l = 2.0 * l - lp;
                self.lp = l;
                self.p11 = p11 + SEMERA_PROCESS_R;
                self.p12 = 2.0 * p12 - p13;
                self.p13 = p12;
                self.p22 = 4.0 * (p22 - p23) + p33 + SEMERA_PROCESS_L;
                self.p23 = 2.0 * p22 - p23;
                self.p33 = p22;
                let valid = used
                    && Real::abs(i) > SEMERA_CI
                    && Real::abs(self.i_prev) > SEMERA_CI;
                let (r_hat, l_hat) = if valid {
                    (r, l)
                } else {
                    (self.r_hat, SEMERA_INITIAL_INDUCTANCE)
                };
                self.r_hat = r_hat;
                self.i_prev = i;
                let lambda = l_hat * i;
                Estimate {
                    r: r_hat,
                    l: l_hat,
                    lambda,
                    phi: lambda * INV_TURNS,
                    reluctance: TURNS_SQ / l_hat,
                    valid,
                }
            }
        }

        impl Default for Semera {
            fn default() -> Self {
                Self::new()
            }
        }
    }
}

/// `Integral`: Algorithm 2 (`designer::observe::integral`, operation for operation).
fn integral_tokens(float: Float) -> TokenStream {
    let ty = float.ty();
    quote! {
        /// The integral estimator (semera Algorithm 2): λ̂ = λ₀ + Δ·(S_u − r̄·S_ι) (46),
        /// l̂ = λ̂/ι (48) under the CI detector (else l̄₀), and at the start of each
        /// energizing operation (the voltage rising above `INTEGRAL_ENERGIZE_THRESHOLD`
        /// between two samples: the operation started at the earlier one) the resistance
        /// update r̄ = S_u/S_ι (47) — used when S_ι exceeds its noise interval — and the
        /// reset S_u = S_ι = 0. Non-finite samples are skipped (nothing summed).
        #[derive(Clone, Debug, PartialEq)]
        pub struct Integral {
            /// r̄
            r_bar: #ty,
            /// S_u
            sum_u: #ty,
            /// S_ι
            sum_i: #ty,
            /// m, the samples in the sums
            count: #ty,
            /// ι_{k−1}
            i_prev: #ty,
            /// The last finite voltage sample.
            v_prev: #ty,
        }

        impl Integral {
            /// At rest (Algorithm 2, lines 1–2): r̄ = r̄₀, S_u = S_ι = 0, ι₀ = 0.
            #[must_use]
            pub const fn new() -> Self {
                Integral {
                    r_bar: INTEGRAL_INITIAL_RESISTANCE,
                    sum_u: 0.0,
                    sum_i: 0.0,
                    count: 0.0,
                    i_prev: 0.0,
                    v_prev: 0.0,
                }
            }

            /// One sample k: the coil voltage u_k = `v` [V] and current ι_k = `i` [A],
            /// taken every Δ.
            #[must_use]
            pub fn step(&mut self, v: #ty, i: #ty) -> Estimate {
                if v > INTEGRAL_ENERGIZE_THRESHOLD && self.v_prev <= INTEGRAL_ENERGIZE_THRESHOLD {
                    if self.sum_i > 0.0 && self.sum_i * self.sum_i > INTEGRAL_CI_SQ * self.count {
                        let r = self.sum_u / self.sum_i;
                        if r > 0.0 && r.is_finite() {
                            self.r_bar = r;
                        }
                    }
                    self.sum_u = 0.0;
                    self.sum_i = 0.0;
                    self.count = 0.0;
                }
                if v.is_finite() && i.is_finite() {
                    self.sum_u += v;
                    self.sum_i += i;
                    self.count += 1.0;
                    self.v_prev = v;
                }
                let lambda = INTEGRAL_INITIAL_FLUX_LINKAGE
                    + SAMPLE_PERIOD * (self.sum_u - self.r_bar * self.sum_i);
                let valid = Real::abs(i) > INTEGRAL_CI && Real::abs(self.i_prev) > INTEGRAL_CI;
                let l = if valid { lambda / i } else { INTEGRAL_INITIAL_INDUCTANCE };
                self.i_prev = i;
                Estimate {
                    r: self.r_bar,
                    l,
                    lambda,
                    phi: lambda * INV_TURNS,
                    reluctance: TURNS_SQ / l,
                    valid,
                }
            }

            /// r̄, the resistance in use [Ω].
            #[must_use]
            pub const fn resistance(&self) -> #ty {
                self.r_bar
            }
        }

        impl Default for Integral {
            fn default() -> Self {
                Self::new()
            }
        }
    }
}
