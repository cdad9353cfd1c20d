//! The observers' constants, written once per file as macros the float
//! modules invoke (like the controller's `params!`): `kalman!` holds the
//! filters' settings (`[observer]`, `[observer.kalman]`), one per line, and
//! what the filters derive from them (the runtime's `Settings`); `params!`
//! the model's parameters with the stops, for a file without a controller
//! (whose emitter writes it otherwise).

use designer::description::Drive;
use designer::observe::discrete::{DiscreteModel, StateKind, FLUX_DOMAIN_MARGIN, MODE_BAND_SIGMAS};
use designer::observe::discrete::{PHI_LIM, Z_MAX, Z_MIN};
use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

use crate::float::{Float, MACRO_FLOAT};
use crate::format::{format_items, macro_rules};
use crate::names::const_name;

use super::{doc_attrs, lit, ObserverError, ObserverInput};

/// The names `kalman!` defines (checked against the parameters' const names).
pub(super) const KALMAN_CONSTS: &[&str] = &[
    "T_S",
    "VOLTAGE_NOISE",
    "CURRENT_NOISE",
    "PROCESS_Z",
    "PROCESS_PHI",
    "PROCESS_HC",
    "INITIAL_Z_STD",
    "INITIAL_PHI_STD",
    "INITIAL_HC_STD",
    "RESISTANCE_RATE_STD",
    "INITIAL_RESISTANCE_STD",
    "UKF_ALPHA",
    "UKF_BETA",
    "UKF_KAPPA",
    "UKF_LAMBDA",
    "PHI_LIM",
    "SETTINGS",
];

/// The settings as (const name, value, doc), in the order of the macro.
fn named_settings(dm: &DiscreteModel) -> Vec<(&'static str, f64, &'static str)> {
    let s = &dm.settings;
    let mut settings: Vec<(&str, f64, &str)> = vec![
        ("T_S", s.sample_period, "T_s [s]: the sample period."),
        (
            "VOLTAGE_NOISE",
            s.voltage_noise,
            "σ_v [V]: standard deviation of the measured coil voltage's noise.",
        ),
        (
            "CURRENT_NOISE",
            s.current_noise,
            "σ_i [A]: standard deviation of the measured coil current's noise.",
        ),
        (
            "PROCESS_Z",
            s.process_z,
            "σ of w_z [m] per sample [JA 84a].",
        ),
        (
            "PROCESS_PHI",
            s.process_phi,
            "σ of w_φ [Wb] per sample [JA 84c].",
        ),
    ];
    if let Some(q) = s.process_hc {
        settings.push(("PROCESS_HC", q, "σ of w_Hc [A/m] per sample [JA 84d]."));
    }
    settings.push((
        "INITIAL_Z_STD",
        s.initial_z_std,
        "Initial σ of z [m] (shared by z_prev: the filter starts at rest).",
    ));
    settings.push(("INITIAL_PHI_STD", s.initial_phi_std, "Initial σ of φ [Wb]."));
    if let Some(h) = s.initial_hc_std {
        settings.push(("INITIAL_HC_STD", h, "Initial σ of H_c [A/m]."));
    }
    if let Some(r) = dm.resistance {
        settings.push((
            "RESISTANCE_RATE_STD",
            r.rate_std,
            "σ_Ṙ [Ω/s]: the resistance's random walk, w_R of σ = σ_Ṙ·T_s per sample.",
        ));
        settings.push((
            "INITIAL_RESISTANCE_STD",
            r.initial_std,
            "Initial σ of R [Ω].",
        ));
    }
    settings.extend([
        (
            "UKF_ALPHA",
            s.ukf_alpha,
            "α of the unscented transform (spread).",
        ),
        (
            "UKF_BETA",
            s.ukf_beta,
            "β of the unscented transform (prior knowledge; 2 for Gaussian).",
        ),
        ("UKF_KAPPA", s.ukf_kappa, "κ of the unscented transform."),
    ]);
    settings
}

/// `macro_rules! kalman` for `input` (the model's dimension and settings):
/// invoked as `kalman!(f64)` / `kalman!(f32)` in every EKF and UKF module.
pub fn emit_kalman_macro(input: &ObserverInput) -> Result<String, ObserverError> {
    let dm = input.discrete;
    let f = Ident::new(MACRO_FLOAT, Span::call_site());
    let mut items = TokenStream::new();
    for (name, value, doc) in named_settings(dm) {
        let id = Ident::new(name, Span::call_site());
        let v = lit(Float::F64, name, value)?;
        let docs = doc_attrs(doc);
        items.extend(quote!(#docs pub const #id: #f = #v;));
    }
    let n = lit(Float::F64, "n", dm.dim() as f64)?;
    let lambda_doc = format!(
        " λ = α²·(n + κ) − n of the unscented transform, n = {} states.",
        dm.dim()
    );
    items.extend(quote! {
        #[doc = #lambda_doc]
        pub const UKF_LAMBDA: #f = UKF_ALPHA * UKF_ALPHA * (#n + UKF_KAPPA) - #n;
    });
    if dm.params.symbol(PHI_LIM).is_some() {
        let margin = lit(Float::F64, "FLUX_DOMAIN_MARGIN", FLUX_DOMAIN_MARGIN)?;
        items.extend(quote! {
            /// φ_lim [Wb]: the filters evaluate the saturating core at |φ| ≤ φ_lim (R_core is
            /// infinite at φ_sat).
            pub const PHI_LIM: #f = (1.0 - #margin) * PHI_SAT;
        });
    }
    items.extend(settings_const(dm, &f, &n)?);
    let doc = format!(
        "The Kalman filters' settings of `{}` (`[observer]`, `[observer.kalman]`), one per\n\
         line, and the filters' `Settings` derived from them; declared in each filter module\n\
         as `kalman!(f64)` / `kalman!(f32)`.",
        input.name
    );
    Ok(macro_rules("kalman", &doc, &format_items(items)?))
}

/// `pub const SETTINGS`: the runtime's `Settings` from the named settings.
fn settings_const(
    dm: &DiscreteModel,
    f: &Ident,
    n: &TokenStream,
) -> Result<TokenStream, ObserverError> {
    let dim = proc_macro2::Literal::usize_unsuffixed(dm.dim());
    let zero = quote!(0.0);
    let kinds = &dm.kinds;
    let process = kinds.iter().map(|k| match k {
        StateKind::Position => quote!(PROCESS_Z * PROCESS_Z),
        StateKind::Flux => quote!(PROCESS_PHI * PROCESS_PHI),
        StateKind::CoreField => quote!(PROCESS_HC * PROCESS_HC),
        StateKind::Resistance => quote!((RESISTANCE_RATE_STD * T_S) * (RESISTANCE_RATE_STD * T_S)),
        StateKind::PreviousPosition => zero.clone(),
    });
    let x0 = kinds.iter().map(|k| match k {
        StateKind::Position | StateKind::PreviousPosition => quote!(Z_MAX),
        StateKind::Resistance => quote!(R),
        StateKind::Flux | StateKind::CoreField => zero.clone(),
    });
    let p0 = kinds.iter().enumerate().map(|(i, ki)| {
        let row = kinds.iter().enumerate().map(|(j, kj)| match (ki, kj) {
            (StateKind::Position, StateKind::Position)
            | (StateKind::PreviousPosition, StateKind::PreviousPosition) => {
                quote!(INITIAL_Z_STD * INITIAL_Z_STD + PROCESS_Z * PROCESS_Z)
            }
            (StateKind::Position, StateKind::PreviousPosition)
            | (StateKind::PreviousPosition, StateKind::Position) => {
                quote!(INITIAL_Z_STD * INITIAL_Z_STD)
            }
            (StateKind::Flux, _) if i == j => quote!(INITIAL_PHI_STD * INITIAL_PHI_STD),
            (StateKind::CoreField, _) if i == j => quote!(INITIAL_HC_STD * INITIAL_HC_STD),
            (StateKind::Resistance, _) if i == j => {
                quote!(INITIAL_RESISTANCE_STD * INITIAL_RESISTANCE_STD)
            }
            _ => zero.clone(),
        });
        quote!([#(#row),*])
    });
    let index = |kind: StateKind| match kinds.iter().position(|&k| k == kind) {
        Some(i) => {
            let i = proc_macro2::Literal::usize_unsuffixed(i);
            quote!(Some(#i))
        }
        None => quote!(None),
    };
    let (field, resistance) = (index(StateKind::CoreField), index(StateKind::Resistance));
    let (input_noise, measurement_noise) = if dm.drive == Drive::Voltage {
        (quote!(VOLTAGE_NOISE), quote!(CURRENT_NOISE))
    } else {
        (quote!(CURRENT_NOISE), quote!(VOLTAGE_NOISE))
    };
    let band = lit(Float::F64, "MODE_BAND_SIGMAS", MODE_BAND_SIGMAS)?;
    let gamma = lit(Float::F64, "gamma", dm.settings.unscented(dm.dim()).gamma)?;
    let factor = dm
        .initial_factor()
        .iter()
        .map(|row| {
            let cells = row
                .iter()
                .map(|&x| lit(Float::F64, "chol P₀", x))
                .collect::<Result<Vec<_>, _>>()?;
            Ok(quote!([#(#cells),*]))
        })
        .collect::<Result<Vec<_>, ObserverError>>()?;
    Ok(quote! {
        /// The filters' settings. Mode band of [JA 86]: 3·q_z. Q = diag(q_z², 0, q_φ²(, q_Hc²)) +
        /// σ_u²·g·gᵀ (g = ∂F/∂u: the measured input's noise), measurement variance
        /// σ_y² + σ_u²·(∂h/∂u)². x₀: at rest at z_max, φ = 0(, H_c = 0). P₀: z and z_prev share
        /// the initial σ (at rest: v = 0 is known), each with q_z² added so that P₀ is positive
        /// definite. The unscented transform's weights W₀ᵐ = λ/(n + λ), W₀ᶜ = W₀ᵐ + 1 − α² + β,
        /// Wᵢ = 1/(2·(n + λ)); γ = √(n + λ) and chol P₀ are evaluated when generated (they
        /// change with α, κ and the initial σ; in f32 the f64 text rounds to the nearest f32).
        #[allow(clippy::excessive_precision)]
        pub const SETTINGS: reldesign_runtime::observe::Settings<#f, #dim> =
            reldesign_runtime::observe::Settings {
                sample_period: T_S,
                z_min: Z_MIN,
                z_max: Z_MAX,
                mode_band: #band * PROCESS_Z,
                input_variance: #input_noise * #input_noise,
                measurement_variance: #measurement_noise * #measurement_noise,
                process_variance: [#(#process),*],
                initial_state: [#(#x0),*],
                initial_covariance: [#(#p0),*],
                field: #field,
                resistance: #resistance,
                unscented: reldesign_runtime::observe::Weights {
                    gamma: #gamma,
                    mean0: UKF_LAMBDA / (#n + UKF_LAMBDA),
                    cov0: UKF_LAMBDA / (#n + UKF_LAMBDA) + (1.0 - UKF_ALPHA * UKF_ALPHA + UKF_BETA),
                    other: 0.5 / (#n + UKF_LAMBDA),
                },
                initial_factor: [#(#factor),*],
            };
    })
}

/// `macro_rules! params` of the discretised model's physics: the model's
/// parameters (R too when it is a state: its description value starts the
/// estimate) and the stops `Z_MIN`, `Z_MAX`, one per line, in the
/// controller's format (for a file without a controller, whose emitter
/// writes it otherwise).
pub fn emit_observer_params(input: &ObserverInput) -> Result<String, ObserverError> {
    let dm = input.discrete;
    let mut body = String::new();
    let mut line = |name: &str, value: f64| -> Result<(), ObserverError> {
        let cname = const_name(name)?;
        if cname != name {
            body.push_str(&format!("        /// `{name}`\n"));
        }
        if !value.is_finite() {
            return Err(ObserverError::BadValue {
                name: name.to_owned(),
                value,
                float: "f64",
            });
        }
        // shortest round-trip f64 text (an f32 module rounds it to the nearest f32)
        let v = if value == 0.0 { 0.0 } else { value };
        body.push_str(&format!("        pub const {cname}: $f = {v:?};\n"));
        Ok(())
    };
    for (name, _, value) in dm.model_params.iter() {
        line(name, value)?;
    }
    line(Z_MIN, dm.z_min)?;
    line(Z_MAX, dm.z_max)?;
    Ok(format!(
        "/// The model parameters of `{name}` (SI units), one per line, declared in\n\
         /// each float module as `params!(f64)` / `params!(f32)`.\n\
         macro_rules! params {{\n    ($f:ty) => {{\n{body}    }};\n}}\n",
        name = input.name
    ))
}
