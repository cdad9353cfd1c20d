//! The model-based observers as emitted code: the extended and the unscented
//! Kalman filter on the discretised model of jiles-atherton-actuator-model
//! §6.1 (eqs. 84–87), built by `designer::observe::discrete::DiscreteModel`.
//!
//! [`emit_ekf`] and [`emit_ukf`] return formatted module items, one
//! `pub mod f64 { … }` / `pub mod f32 { … }` per requested float type (the
//! caller wraps them, e.g. in `pub mod ekf { … }`, which [`wrap_module`]
//! does with indentation). Each module holds:
//!
//! - the parameters as named consts (one parameter, one line; the model's,
//!   then T_s, z_min, z_max and, with the saturating core, the flux bound of
//!   the model's domain) and the filter settings as consts of their own;
//! - the model functions, written by the expression emitter as straight-line
//!   code with CSE'd `let`s and equation numbers in comments: `transition`
//!   (84)–(85) with the acceleration f_v of (87) (the EKF's also returns the
//!   symbolic Jacobian ∂F/∂x and g = ∂F/∂u), `measurement` h and ∂h/∂u (and
//!   ∂h/∂x for the EKF), `input_gain` g (UKF);
//! - `Estimate` (z, v, a, φ, H_c with the Jiles–Atherton core, the mode) and
//!   a `Filter` with `const fn new()` and `step(u, i) -> Estimate`, the same
//!   algorithm as the designer's f64 reference filters
//!   (`designer::observe::ekf::Ekf`, `designer::observe::ukf::Ukf`).
//!
//! The emitted code is `no_std`, allocation-free (fixed-size arrays, the
//! helpers of `reldesign_runtime::linalg`), panic-free (no indexing, no
//! `unwrap`, no `as`), deterministic, and NaN-safe: a measurement update
//! whose inputs, innovation variance or innovation is not finite is
//! skipped, a non-finite input is replaced by the last finite one, and a
//! non-finite prediction restarts the filter from its initial state.

use designer::description::Drive;
use designer::observe::discrete::{DiscreteModel, StateKind, MODE_BAND_SIGMAS};
use designer::observe::ukf::{REPAIR_JITTER, REPAIR_JITTER_F32};
use designer::sym::{Graph, Id};
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use crate::emit::{function_tokens, FunctionSpec};
use crate::error::EmitError;
use crate::float::Float;
use crate::format::{comment_lets, format_items, space_items};
use crate::names::const_name;
use crate::param::Param;

/// Everything [`emit_ekf`] and [`emit_ukf`] need.
#[derive(Clone)]
pub struct ObserverInput<'a> {
    /// The description name (for docs).
    pub name: &'a str,
    /// The discretised model with its settings
    /// (`DiscreteModel::new(&model, &settings)`).
    pub discrete: &'a DiscreteModel,
    /// Emitted float types, in this order (duplicates dropped).
    pub floats: Vec<Float>,
}

/// Why an observer could not be emitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObserverError {
    #[error(transparent)]
    Emit(#[from] EmitError),
    #[error("no float type to emit")]
    NoFloat,
    #[error("the observer value `{name}` = {value:e} is not finite in {float}")]
    BadValue {
        name: String,
        value: f64,
        float: &'static str,
    },
    #[error("the parameter const `{0}` collides with a constant of the observer")]
    NameTaken(String),
}

/// The extended Kalman filter: formatted `pub mod f64 { … }` /
/// `pub mod f32 { … }` items.
pub fn emit_ekf(input: &ObserverInput) -> Result<String, ObserverError> {
    emit(input, Kind::Ekf)
}

/// The unscented Kalman filter: formatted `pub mod f64 { … }` /
/// `pub mod f32 { … }` items.
pub fn emit_ukf(input: &ObserverInput) -> Result<String, ObserverError> {
    emit(input, Kind::Ukf)
}

/// `items` (the text of [`emit_ekf`] or [`emit_ukf`]) as a module `name`
/// with a doc line: `/// doc` `pub mod name {` the items indented by four
/// spaces `}` (the emitted text has no multi-line literals, so indenting
/// every non-empty line keeps it valid and formatted).
pub fn wrap_module(name: &str, doc: &str, items: &str) -> String {
    let mut out = String::with_capacity(items.len() + items.len() / 8 + 64);
    for line in doc.lines() {
        out.push_str("/// ");
        out.push_str(line);
        out.push('\n');
    }
    out.push_str(&format!("pub mod {name} {{\n"));
    for line in items.lines() {
        if !line.is_empty() {
            out.push_str("    ");
            out.push_str(line);
        }
        out.push('\n');
    }
    out.push_str("}\n");
    out
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Ekf,
    Ukf,
}

/// How a state is named: the Rust name (function arguments), its short form
/// (in output names) and how it reads in docs.
struct StateName {
    name: &'static str,
    short: &'static str,
    doc: &'static str,
}

fn state_name(kind: StateKind) -> StateName {
    let (name, short, doc) = match kind {
        StateKind::Position => ("z", "z", "z"),
        StateKind::PreviousPosition => ("z_prev", "zp", "z_prev"),
        StateKind::Flux => ("phi", "phi", "φ"),
        StateKind::CoreField => ("hc", "hc", "H_c"),
        StateKind::Resistance => ("r", "r", "R"),
    };
    StateName { name, short, doc }
}

/// The names of the discretised model's states, in order.
fn state_names(dm: &DiscreteModel) -> Vec<StateName> {
    dm.kinds.iter().map(|&k| state_name(k)).collect()
}

/// Consts the module defines besides the parameters.
const OBSERVER_CONSTS: &[&str] = &[
    "DIM",
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
    "INITIAL_RESISTANCE",
    "UKF_ALPHA",
    "UKF_BETA",
    "UKF_KAPPA",
    "INPUT_VARIANCE",
    "MEASUREMENT_VARIANCE",
    "PROCESS_VARIANCE",
    "INITIAL_STATE",
    "INITIAL_COVARIANCE",
    "INITIAL_FACTOR",
    "MODE_BAND",
    "GAMMA",
    "WEIGHT_MEAN0",
    "WEIGHT_COV0",
    "WEIGHT",
    "REPAIR_JITTER",
    "POINTS",
];

fn emit(input: &ObserverInput, kind: Kind) -> Result<String, ObserverError> {
    let mut floats: Vec<Float> = Vec::new();
    for &f in &input.floats {
        if !floats.contains(&f) {
            floats.push(f);
        }
    }
    if floats.is_empty() {
        return Err(ObserverError::NoFloat);
    }
    let dm = input.discrete;
    for (name, _, _) in dm.param_list() {
        let c = const_name(name)?;
        if OBSERVER_CONSTS.contains(&c.as_str()) {
            return Err(ObserverError::NameTaken(c));
        }
    }
    let mut out = String::new();
    for float in floats {
        if !out.is_empty() {
            out.push('\n');
        }
        out.push_str(&float_module(input, kind, float)?);
    }
    Ok(out)
}

/// One model function: its outputs (name, expression, doc).
struct Function {
    name: &'static str,
    doc: String,
    outputs: Vec<(String, Id, String)>,
}

impl Function {
    fn tokens(
        &self,
        graph: &Graph,
        dm: &DiscreteModel,
        params: &[Param],
        float: Float,
    ) -> Result<TokenStream, EmitError> {
        let mut inputs: Vec<(&str, Id)> = state_names(dm)
            .iter()
            .zip(&dm.states)
            .map(|(n, &id)| (n.name, id))
            .collect();
        inputs.push(("u", dm.input));
        if dm.uses_time {
            inputs.push(("t", dm.time));
        }
        let spec = FunctionSpec {
            name: self.name,
            doc: &self.doc,
            inputs,
            outputs: self
                .outputs
                .iter()
                .map(|(n, id, d)| (n.as_str(), *id, d.as_str()))
                .collect(),
            named: vec![],
            output_symbols: vec![],
            float,
        };
        function_tokens(graph, &spec, params)
    }

    fn comments(&self) -> Vec<(&str, &str)> {
        self.outputs
            .iter()
            .map(|(n, _, d)| (n.as_str(), d.as_str()))
            .collect()
    }
}

/// An entry of a vector or matrix the filter assembles from a function's
/// outputs: a constant (0, 1 of the structure) or the output's field.
#[derive(Clone)]
enum Entry {
    Const(f64),
    Field(String),
}

/// Adds `id` as an output called `name` unless it is a constant.
fn entry(
    g: &Graph,
    outputs: &mut Vec<(String, Id, String)>,
    name: String,
    id: Id,
    doc: String,
) -> Entry {
    match g.as_const(id) {
        Some(c) => Entry::Const(c),
        None => {
            outputs.push((name.clone(), id, doc));
            Entry::Field(name)
        }
    }
}

/// The model functions and how the filter reads them.
struct Layout {
    n: usize,
    /// Name of the measured quantity (`i`, or `u_coil` with current drive).
    y: String,
    transition: Function,
    measurement: Function,
    /// f_v of (87) alone, for the estimate at the posterior.
    acceleration: Function,
    /// UKF: g = ∂F/∂u (none if every entry is constant).
    input_gain: Option<Function>,
    /// ∂F/∂x (EKF), from `transition`.
    jacobian: Vec<Vec<Entry>>,
    /// g (from `transition` for the EKF, from `input_gain` for the UKF).
    gain: Vec<Entry>,
    /// ∂h/∂x (EKF), from `measurement`.
    h_row: Vec<Entry>,
}

impl Layout {
    fn new(dm: &DiscreteModel, kind: Kind) -> Layout {
        let g = &dm.graph;
        let n = dm.dim();
        let voltage_drive = dm.drive == Drive::Voltage;
        let y = if voltage_drive { "i" } else { "u_coil" }.to_owned();
        let names = state_names(dm);
        let next_doc = |k: StateKind| {
            match k {
            StateKind::Position => "(84a) z_{k+1} = sat_{z_min}^{z_max}(2·z − z_prev + T_s²·f_v(z, v, φ)), v = (z − z_prev)/T_s (85)",
            StateKind::PreviousPosition => "(84b) z_prev,{k+1} = sat_{z_min}^{z_max}(z)",
            StateKind::Flux => "(84c) φ_{k+1} = φ + T_s·f_φ(z, φ, H_c, u)",
            StateKind::CoreField => "(84d) H_c,{k+1} = H_c + T_s·f_Hc(z, φ, H_c, u)",
            StateKind::Resistance => "R_{k+1} = R (random walk)",
        }
        };
        let mut outputs = Vec::new();
        for i in 0..n {
            outputs.push((
                format!("{}_next", names[i].short),
                dm.transition[i],
                next_doc(dm.kinds[i]).to_owned(),
            ));
        }
        outputs.push((
            "accel".to_owned(),
            dm.acceleration,
            "(87) a = f_v(z, v, φ), the free-motion acceleration at v of (85)".to_owned(),
        ));
        let mut jacobian = Vec::new();
        let mut gain = Vec::new();
        let mut input_gain = None;
        if kind == Kind::Ekf {
            for i in 0..n {
                let mut row = Vec::new();
                for j in 0..n {
                    row.push(entry(
                        g,
                        &mut outputs,
                        format!("d{}_d{}", names[i].short, names[j].short),
                        dm.transition_jacobian[i][j],
                        format!("∂{}_{{k+1}}/∂{}", names[i].doc, names[j].doc),
                    ));
                }
                jacobian.push(row);
            }
        }
        let mut gain_outputs = Vec::new();
        {
            let target = if kind == Kind::Ekf {
                &mut outputs
            } else {
                &mut gain_outputs
            };
            for i in 0..n {
                gain.push(entry(
                    g,
                    target,
                    format!("d{}_du", names[i].short),
                    dm.input_gain[i],
                    format!(
                        "g = ∂{}_{{k+1}}/∂u (maps the input's noise into Q)",
                        names[i].doc
                    ),
                ));
            }
        }
        if kind == Kind::Ukf && !gain_outputs.is_empty() {
            input_gain = Some(Function {
                name: "input_gain",
                doc: "g = ∂F/∂u of the transition (84): the input's noise σ_u enters the process\n\
                      noise as σ_u²·g·gᵀ. Entries not listed are constant."
                    .to_owned(),
                outputs: gain_outputs,
            });
        }
        let transition = Function {
            name: "transition",
            doc: if kind == Kind::Ekf {
                "The discretised model (84)–(85) at x = [z, z_prev, φ(, H_c)] with the input u held\n\
                 over the sample, the acceleration f_v of (87), and the symbolic Jacobians\n\
                 ∂F/∂x and g = ∂F/∂u (entries not listed are constant)."
            } else {
                "The discretised model (84)–(85) at x = [z, z_prev, φ(, H_c)] with the input u held\n\
                 over the sample, and the acceleration f_v of (87)."
            }
            .to_owned(),
            outputs,
        };

        let y_doc = if voltage_drive {
            "i = (N·(R_gap(z)·φ + MMF_core) + k_e·u)/(N² + R·k_e), the coil current (jiles-atherton-actuator-model (41))"
        } else {
            "u_coil = R·u + N·f_φ, the coil voltage (eq. 1)"
        };
        let mut m_outputs = vec![
            (y.clone(), dm.measurement, y_doc.to_owned()),
            (
                format!("d{y}_du"),
                dm.measurement_input_gain,
                format!("∂{y}/∂u (the input's noise in the measurement variance)"),
            ),
        ];
        let mut h_row = Vec::new();
        if kind == Kind::Ekf {
            for j in 0..n {
                h_row.push(entry(
                    g,
                    &mut m_outputs,
                    format!("d{y}_d{}", names[j].short),
                    dm.measurement_jacobian[j],
                    format!("H = ∂{y}/∂{}", names[j].doc),
                ));
            }
        }
        let measurement = Function {
            name: "measurement",
            doc: if kind == Kind::Ekf {
                "The measured quantity y = h(x, u) on the model's domain and its derivatives\n\
                 (entries of ∂h/∂x not listed are constant)."
            } else {
                "The measured quantity y = h(x, u) on the model's domain and ∂h/∂u."
            }
            .to_owned(),
            outputs: m_outputs,
        };
        let acceleration = Function {
            name: "acceleration",
            doc: "The acceleration f_v of (87) at x = [z, z_prev, φ(, H_c)] (v of (85)): the\n\
                  estimate's a, at the posterior."
                .to_owned(),
            outputs: vec![(
                "accel".to_owned(),
                dm.acceleration,
                "(87) a = f_v(z, v, φ), the free-motion acceleration at v of (85)".to_owned(),
            )],
        };
        Layout {
            n,
            y,
            transition,
            measurement,
            acceleration,
            input_gain,
            jacobian,
            gain,
            h_row,
        }
    }
}

/// Typed literal of `value` in `float`.
fn lit(float: Float, name: &str, value: f64) -> Result<TokenStream, ObserverError> {
    float
        .unsuffixed_signed(value)
        .ok_or_else(|| ObserverError::BadValue {
            name: name.to_owned(),
            value,
            float: float.name(),
        })
}

/// Tokens of an assembled entry (`out` is the struct holding the fields).
fn entry_tokens(e: &Entry, out: &Ident, float: Float) -> Result<TokenStream, ObserverError> {
    Ok(match e {
        Entry::Const(c) => lit(float, "a constant entry", *c)?,
        Entry::Field(f) => {
            let f = format_ident!("{f}");
            quote!(#out.#f)
        }
    })
}

fn vector_tokens(es: &[Entry], out: &Ident, float: Float) -> Result<TokenStream, ObserverError> {
    let items = es
        .iter()
        .map(|e| entry_tokens(e, out, float))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(quote!([#(#items),*]))
}

/// `#[doc = " line"]` per line.
fn doc_attrs(text: &str) -> TokenStream {
    let mut out = TokenStream::new();
    for line in text.lines() {
        let line = if line.is_empty() {
            String::new()
        } else {
            format!(" {line}")
        };
        out.extend(quote!(#[doc = #line]));
    }
    out
}

/// The `Filter` struct both filters keep (posterior mean and covariance, the
/// last finite input, skip and repair counters) and its `Default`.
fn filter_struct(which: &str, ty: &Ident, dim: &Literal, time_field: &TokenStream) -> TokenStream {
    let doc = format!(" {which} Kalman filter (see the module docs). Allocation- and panic-free.");
    quote! {
        #[doc = #doc]
        #[derive(Clone, Debug, PartialEq)]
        pub struct Filter {
            /// Posterior mean x_{k|k} of the last sample (x₀ before the first).
            x: [#ty; #dim],
            /// Its covariance.
            p: [[#ty; #dim]; #dim],
            /// The last finite input.
            u_last: #ty,
            #time_field
            skipped: u32,
            repairs: u32,
        }

        impl Default for Filter {
            fn default() -> Self {
                Self::new()
            }
        }
    }
}

/// One `pub mod f64 { … }` / `pub mod f32 { … }`, formatted.
fn float_module(input: &ObserverInput, kind: Kind, float: Float) -> Result<String, ObserverError> {
    let dm = input.discrete;
    let s = &dm.settings;
    let g = &dm.graph;
    let layout = Layout::new(dm, kind);
    let n = layout.n;
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let params: Vec<Param> = dm.param_list().into_iter().map(Param::from).collect();
    let has_field = dm.has_field_state();
    let voltage_drive = dm.drive == Drive::Voltage;

    // ---- consts
    let mut items = crate::emit::params_tokens(g, &params, float)?;
    let dim = Literal::usize_unsuffixed(n);
    let mut settings: Vec<(&str, f64, &str)> = vec![
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
        ("PROCESS_Z", s.process_z, "σ of w_z [m] per sample (84a)."),
        (
            "PROCESS_PHI",
            s.process_phi,
            "σ of w_φ [Wb] per sample (84c).",
        ),
    ];
    if let Some(q) = s.process_hc {
        settings.push(("PROCESS_HC", q, "σ of w_Hc [A/m] per sample (84d)."));
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
        settings.push((
            "INITIAL_RESISTANCE",
            dm.nominal_resistance,
            "R₀ [Ω]: the description's coil resistance, R's initial estimate.",
        ));
    }
    if kind == Kind::Ukf {
        settings.push((
            "UKF_ALPHA",
            s.ukf_alpha,
            "α of the unscented transform (spread).",
        ));
        settings.push((
            "UKF_BETA",
            s.ukf_beta,
            "β of the unscented transform (prior knowledge; 2 for Gaussian).",
        ));
        settings.push(("UKF_KAPPA", s.ukf_kappa, "κ of the unscented transform."));
    }
    for (name, value, doc) in &settings {
        let id = format_ident!("{name}");
        let v = lit(float, name, *value)?;
        let docs = doc_attrs(doc);
        items.extend(quote!(#docs pub const #id: #ty = #v;));
    }
    let (input_noise, measurement_noise) = if voltage_drive {
        (quote!(VOLTAGE_NOISE), quote!(CURRENT_NOISE))
    } else {
        (quote!(CURRENT_NOISE), quote!(VOLTAGE_NOISE))
    };
    let zero = quote!(0.0);
    let kinds = &dm.kinds;
    let process: Vec<TokenStream> = kinds
        .iter()
        .map(|k| match k {
            StateKind::Position => quote!(PROCESS_Z * PROCESS_Z),
            StateKind::Flux => quote!(PROCESS_PHI * PROCESS_PHI),
            StateKind::CoreField => quote!(PROCESS_HC * PROCESS_HC),
            StateKind::Resistance => {
                quote!((RESISTANCE_RATE_STD * T_S) * (RESISTANCE_RATE_STD * T_S))
            }
            StateKind::PreviousPosition => zero.clone(),
        })
        .collect();
    let x0: Vec<TokenStream> = kinds
        .iter()
        .map(|k| match k {
            StateKind::Position | StateKind::PreviousPosition => quote!(Z_MAX),
            StateKind::Resistance => quote!(INITIAL_RESISTANCE),
            StateKind::Flux | StateKind::CoreField => zero.clone(),
        })
        .collect();
    let mut p0_rows = Vec::new();
    for i in 0..n {
        let row: Vec<TokenStream> = (0..n)
            .map(|j| match (i, j, kinds[i]) {
                (0, 0, _) | (1, 1, _) => {
                    quote!(INITIAL_Z_STD * INITIAL_Z_STD + PROCESS_Z * PROCESS_Z)
                }
                (0, 1, _) | (1, 0, _) => quote!(INITIAL_Z_STD * INITIAL_Z_STD),
                (i, j, StateKind::Flux) if i == j => quote!(INITIAL_PHI_STD * INITIAL_PHI_STD),
                (i, j, StateKind::CoreField) if i == j => quote!(INITIAL_HC_STD * INITIAL_HC_STD),
                (i, j, StateKind::Resistance) if i == j => {
                    quote!(INITIAL_RESISTANCE_STD * INITIAL_RESISTANCE_STD)
                }
                _ => zero.clone(),
            })
            .collect();
        p0_rows.push(quote!([#(#row),*]));
    }
    let band_sigmas = lit(float, "MODE_BAND_SIGMAS", MODE_BAND_SIGMAS)?;
    let state_doc = state_names(dm)
        .iter()
        .map(|s| s.doc)
        .collect::<Vec<_>>()
        .join(", ");
    let dim_doc = format!(" Number of states: x = [{state_doc}].");
    items.extend(quote! {
        #[doc = #dim_doc]
        pub const DIM: usize = #dim;
        /// σ_u²: variance of the measured input's noise.
        pub const INPUT_VARIANCE: #ty = #input_noise * #input_noise;
        /// σ_y²: variance of the measured output's noise.
        pub const MEASUREMENT_VARIANCE: #ty = #measurement_noise * #measurement_noise;
        /// diag(q_z², 0, q_φ²(, q_Hc²)): the part of the process noise Q that does not come
        /// from the input (which adds σ_u²·g·gᵀ, g = ∂F/∂u).
        pub const PROCESS_VARIANCE: [#ty; #dim] = [#(#process),*];
        /// x₀: at rest at z_max, φ = 0(, H_c = 0).
        pub const INITIAL_STATE: [#ty; #dim] = [#(#x0),*];
        /// P₀: z and z_prev share the initial σ (at rest: v = 0 is known), each with q_z²
        /// added so that P₀ is positive definite.
        pub const INITIAL_COVARIANCE: [[#ty; #dim]; #dim] = [#(#p0_rows),*];
        /// (86): the estimate rests on a stop when within this distance [m] of it.
        pub const MODE_BAND: #ty = #band_sigmas * PROCESS_Z;
    });
    let points = 2 * n + 1;
    let m_lit = Literal::usize_unsuffixed(points);
    if kind == Kind::Ukf {
        let w = s.unscented(n);
        let jitter = match float {
            Float::F64 => REPAIR_JITTER,
            Float::F32 => REPAIR_JITTER_F32,
        };
        let l0 = dm.initial_factor();
        let mut l0_rows = Vec::new();
        for row in l0.iter().take(n) {
            let cells = row
                .iter()
                .take(n)
                .map(|&x| lit(float, "INITIAL_FACTOR", x))
                .collect::<Result<Vec<_>, _>>()?;
            l0_rows.push(quote!([#(#cells),*]));
        }
        let consts = [
            (
                "GAMMA",
                w.gamma,
                "γ = √(n + λ), λ = α²·(n + κ) − n: sigma points x̄ ± γ·(columns of chol P).",
            ),
            (
                "WEIGHT_MEAN0",
                w.mean0,
                "W₀ᵐ = λ/(n + λ): weight of the centre point in means.",
            ),
            (
                "WEIGHT_COV0",
                w.cov0,
                "W₀ᶜ = W₀ᵐ + 1 − α² + β: weight of the centre point in covariances.",
            ),
            (
                "WEIGHT",
                w.other,
                "Wᵢ = 1/(2·(n + λ)): weight of the other points.",
            ),
            (
                "REPAIR_JITTER",
                jitter,
                "Relative diagonal jitter of the first repair of a failed Cholesky factorisation.",
            ),
        ];
        for (name, value, doc) in consts {
            let id = format_ident!("{name}");
            let v = lit(float, name, value)?;
            let docs = doc_attrs(doc);
            items.extend(quote!(#docs pub const #id: #ty = #v;));
        }
        items.extend(quote! {
            /// Number of sigma points, 2n + 1.
            pub const POINTS: usize = #m_lit;
            /// chol P₀, the factor a reset of the covariance starts from.
            pub const INITIAL_FACTOR: [[#ty; #dim]; #dim] = [#(#l0_rows),*];
        });
    }

    // ---- model functions
    let mut functions = vec![
        &layout.transition,
        &layout.measurement,
        &layout.acceleration,
    ];
    if let Some(f) = &layout.input_gain {
        functions.push(f);
    }
    for f in &functions {
        items.extend(f.tokens(g, dm, &params, float)?);
    }

    // ---- estimate, helpers, filter
    let names: Vec<Ident> = state_names(dm)
        .iter()
        .map(|s| format_ident!("{}", s.name))
        .collect();
    let time_arg = if dm.uses_time { quote!(, t) } else { quote!() };
    let time_field = if dm.uses_time {
        quote!(
            /// Time of the last posterior [s] from the first sample (−T_s before it; the model
            /// depends on it through the resistance drift).
            time: #ty,
        )
    } else {
        quote!()
    };
    let time_init = if dm.uses_time {
        quote!(time: -T_S,)
    } else {
        quote!()
    };
    let time_let = if dm.uses_time {
        quote!(let t = self.time;)
    } else {
        quote!()
    };
    let time_advance = if dm.uses_time {
        quote!(self.time += T_S;)
    } else {
        quote!()
    };
    let hc_field = if has_field {
        quote!(
            /// H_c [A/m]
            pub hc: #ty,
        )
    } else {
        quote!()
    };
    let hc_init = if has_field { quote!(hc,) } else { quote!() };
    let has_r = dm.resistance_index().is_some();
    let r_field = if has_r {
        quote!(
            /// R [Ω], the estimated coil resistance
            pub r: #ty,
        )
    } else {
        quote!()
    };
    let r_init = if has_r { quote!(r,) } else { quote!() };
    let y = format_ident!("{}", layout.y);
    let y_doc = if voltage_drive {
        "the measured coil current [A]"
    } else {
        "the measured coil voltage [V]"
    };
    let u_doc = if voltage_drive {
        "the measured coil voltage [V]"
    } else {
        "the measured coil current [A]"
    };
    let step_doc = doc_attrs(&format!(
        "One sample k: `u` is {u_doc} held over the last sample (u_{{k−1}}, what\n\
         was applied since the previous call), `{}` is {y_doc} at t_k. Predicts\n\
         the prior from the last posterior with u, updates it with the measurement and\n\
         returns the posterior estimate, so that the controller acts on an estimate\n\
         without lag and the prediction uses the input actually applied. A non-finite\n\
         `u` is replaced by the last finite one and its update skipped; a non-finite\n\
         measurement skips the update.",
        layout.y
    ));
    let rest_pattern: Vec<TokenStream> = (2..n)
        .map(|i| {
            let v = &names[i];
            quote!(#v)
        })
        .collect();

    let common = quote! {
        /// The estimate at one sample: what the controllers consume.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Estimate {
            /// z [m], in [z_min, z_max]
            pub z: #ty,
            /// v [m/s] = (z − z_prev)/T_s (85)
            pub v: #ty,
            /// a [m/s²] (87): f_v(z, v, φ) in mode 2, else 0
            pub a: #ty,
            /// φ [Wb]
            pub phi: #ty,
            #hc_field
            #r_field
            /// q of (86): 1 at z_min, 2 moving, 3 at z_max (within `MODE_BAND` of a stop)
            pub mode: u8,
        }

        /// z projected onto [z_min, z_max] (a NaN stays NaN). Not `clamp`, which has a
        /// panic path (for bounds out of order).
        #[allow(clippy::manual_clamp)]
        fn project(z: #ty) -> #ty {
            if z < Z_MIN {
                Z_MIN
            } else if z > Z_MAX {
                Z_MAX
            } else {
                z
            }
        }

        /// (86) with the band: 1 within `MODE_BAND` of z_min, 3 within it of z_max, else 2
        /// (also for a NaN z).
        fn mode_of(z: #ty) -> u8 {
            if z <= Z_MIN + MODE_BAND {
                1
            } else if z >= Z_MAX - MODE_BAND {
                3
            } else {
                2
            }
        }

        /// The stop the estimate stays on over the next sample: the free acceleration points
        /// into a stop (the automaton's lift-off guard does not fire) and the estimate is on
        /// it by its mode (86), or reaches it within the sample (its own prediction (84a)
        /// `z_next` saturates there); the prediction then keeps z = the stop. A NaN
        /// acceleration stays nowhere.
        fn resting_stop(mode: u8, accel: #ty, z_next: #ty) -> Option<#ty> {
            if accel <= 0.0 && (mode == 1 || z_next == Z_MIN) {
                Some(Z_MIN)
            } else if accel >= 0.0 && (mode == 3 || z_next == Z_MAX) {
                Some(Z_MAX)
            } else {
                None
            }
        }
    };
    items.extend(common);

    let o = format_ident!("o");
    let mo = format_ident!("m");
    let go = format_ident!("gain_out");
    let next_fields: Vec<TokenStream> = state_names(dm)
        .iter()
        .map(|s| {
            let f = format_ident!("{}_next", s.short);
            quote!(o.#f)
        })
        .collect();
    let next_rest: Vec<TokenStream> = next_fields[2..].to_vec();
    let accessors = quote! {
        /// The posterior mean x_{k|k} (after the last `step`).
        #[must_use]
        pub const fn state(&self) -> [#ty; #dim] {
            self.x
        }

        /// The posterior covariance.
        #[must_use]
        pub const fn covariance(&self) -> [[#ty; #dim]; #dim] {
            self.p
        }

        /// Samples whose measurement update was skipped (non-finite data).
        #[must_use]
        pub const fn skipped(&self) -> u32 {
            self.skipped
        }
    };
    // The estimate (85)–(87) at the posterior.
    let estimate = {
        quote! {
            let a = if mode == 2 {
                acceleration(#(#names),*, u #time_arg).accel
            } else {
                0.0
            };
            Estimate {
                z,
                v: (z - z_prev) / T_S,
                a,
                phi,
                #hc_init
                #r_init
                mode,
            }
        }
    };
    // The predicted prior if finite, else a restart from (x₀, P₀), counted.
    let accept = |next: TokenStream| {
        quote! {
            if linalg::all_finite(&#next) && linalg::all_finite_matrix(&p) {
                self.x = #next;
                self.p = p;
            } else {
                self.x = INITIAL_STATE;
                self.p = INITIAL_COVARIANCE;
                self.repairs = self.repairs.saturating_add(1);
            }
            #time_advance
        }
    };
    let accept_next = accept(quote!(next));
    let accept_mean = accept(quote!(mean));
    let head = quote! {
        let u_ok = u.is_finite();
        if u_ok {
            self.u_last = u;
        }
        let u = self.u_last;
        #time_let
    };
    let filter = match kind {
        Kind::Ekf => {
            let jac_rows = layout
                .jacobian
                .iter()
                .map(|row| vector_tokens(row, &o, float))
                .collect::<Result<Vec<_>, _>>()?;
            let jac_rest: Vec<TokenStream> = jac_rows[2..].to_vec();
            let (j0, j1) = (&jac_rows[0], &jac_rows[1]);
            let gain = vector_tokens(&layout.gain, &o, float)?;
            let h = vector_tokens(&layout.h_row, &mo, float)?;
            let dy_du = format_ident!("d{}_du", layout.y);
            let (n0, n1) = (&next_fields[0], &next_fields[1]);
            let filter_struct = filter_struct("The extended", &ty, &dim, &time_field);
            quote! {
                #filter_struct

                impl Filter {
                    /// A filter at rest at z_max with φ = 0 (and H_c = 0): x₀, P₀.
                    #[must_use]
                    pub const fn new() -> Self {
                        Filter {
                            x: INITIAL_STATE,
                            p: INITIAL_COVARIANCE,
                            u_last: 0.0,
                            #time_init
                            skipped: 0,
                            repairs: 0,
                        }
                    }

                    #step_doc
                    pub fn step(&mut self, u: #ty, #y: #ty) -> Estimate {
                        #head
                        let [#(#names),*] = self.x;
                        let o = transition(#(#names),*, u #time_arg);
                        let resting = resting_stop(mode_of(z), o.accel, o.z_next);
                        let (next, f) = match resting {
                            Some(stop) => (
                                [stop, #n1, #(#next_rest),*],
                                [[0.0; #dim], #j1, #(#jac_rest),*],
                            ),
                            None => (
                                [#n0, #n1, #(#next_rest),*],
                                [#j0, #j1, #(#jac_rest),*],
                            ),
                        };
                        let mut p = linalg::sandwich(&f, &self.p);
                        p = linalg::add(&p, &linalg::diagonal(&PROCESS_VARIANCE));
                        linalg::rank1_update(&mut p, INPUT_VARIANCE, &#gain);
                        #accept_next
                        #time_let
                        let mut updated = false;
                        if u_ok && #y.is_finite() {
                            let [#(#names),*] = self.x;
                            let m = measurement(#(#names),*, u #time_arg);
                            let h = #h;
                            let r = MEASUREMENT_VARIANCE + INPUT_VARIANCE * (m.#dy_du * m.#dy_du);
                            let ph = linalg::mat_vec(&self.p, &h);
                            let s = linalg::dot(&h, &ph) + r;
                            let innovation = #y - m.#y;
                            if innovation.is_finite() && s.is_finite() && s > 0.0 {
                                let k = ph.map(|x| x / s);
                                linalg::axpy(&mut self.x, innovation, &k);
                                self.p = linalg::joseph_update(&self.p, &k, &h, r);
                                updated = true;
                            }
                        }
                        if !updated {
                            self.skipped = self.skipped.saturating_add(1);
                        }
                        let [z, z_prev, #(#rest_pattern),*] = self.x;
                        let (z, z_prev) = (project(z), project(z_prev));
                        self.x = [z, z_prev, #(#rest_pattern),*];
                        let mode = mode_of(z);
                        #estimate
                    }

                    #accessors

                    /// Restarts after a non-finite prediction.
                    #[must_use]
                    pub const fn repairs(&self) -> u32 {
                        self.repairs
                    }
                }
            }
        }
        Kind::Ukf => {
            let dy_du = format_ident!("d{}_du", layout.y);
            let gain_call = match &layout.input_gain {
                Some(_) => quote!(
                    let [#(#names),*] = self.x;
                    let gain_out = input_gain(#(#names),*, u #time_arg);
                ),
                None => quote!(),
            };
            let gain = vector_tokens(&layout.gain, &go, float)?;
            let rest_next_pattern: Vec<TokenStream> = (1..n)
                .map(|i| {
                    let v = format_ident!("{}", state_names(dm)[i].short);
                    quote!(#v)
                })
                .collect();
            let filter_struct = filter_struct("The unscented", &ty, &dim, &time_field);
            quote! {
                #filter_struct

                /// Weight of sigma point `k` in means.
                fn weight_mean(k: usize) -> #ty {
                    if k == 0 { WEIGHT_MEAN0 } else { WEIGHT }
                }

                /// Weight of sigma point `k` in covariances.
                fn weight_cov(k: usize) -> #ty {
                    if k == 0 { WEIGHT_COV0 } else { WEIGHT }
                }

                impl Filter {
                    /// A filter at rest at z_max with φ = 0 (and H_c = 0): x₀, P₀.
                    #[must_use]
                    pub const fn new() -> Self {
                        Filter {
                            x: INITIAL_STATE,
                            p: INITIAL_COVARIANCE,
                            u_last: 0.0,
                            #time_init
                            skipped: 0,
                            repairs: 0,
                        }
                    }

                    /// The lower Cholesky factor of P. If the factorisation fails (P not
                    /// numerically positive definite) P is repaired and the repair counted:
                    /// first jitter on the diagonal, Pᵢᵢ += REPAIR_JITTER·(|Pᵢᵢ| + P₀ᵢᵢ), then,
                    /// if that fails too, P = P₀.
                    fn factor(&mut self) -> [[#ty; #dim]; #dim] {
                        if let Some(l) = linalg::cholesky(&self.p) {
                            return l;
                        }
                        self.repairs = self.repairs.saturating_add(1);
                        let d = linalg::diag_of(&self.p);
                        let d0 = linalg::diag_of(&INITIAL_COVARIANCE);
                        let mut jitter = [0.0; #dim];
                        for ((j, &pi), &p0) in jitter.iter_mut().zip(&d).zip(&d0) {
                            *j = REPAIR_JITTER * (reldesign_runtime::math::Real::abs(pi) + p0);
                        }
                        let q = linalg::add(&self.p, &linalg::diagonal(&jitter));
                        if let Some(l) = linalg::cholesky(&q) {
                            self.p = q;
                            return l;
                        }
                        self.p = INITIAL_COVARIANCE;
                        INITIAL_FACTOR
                    }

                    #step_doc
                    pub fn step(&mut self, u: #ty, #y: #ty) -> Estimate {
                        #head
                        let l = self.factor();
                        let pts: [[#ty; #dim]; #m_lit] = linalg::sigma_points(&self.x, &l, GAMMA);
                        let mut next = pts;
                        let mut accel = 0.0;
                        let mut z_next = 0.0;
                        for (k, (nk, pt)) in next.iter_mut().zip(&pts).enumerate() {
                            let [#(#names),*] = *pt;
                            let o = transition(#(#names),*, u #time_arg);
                            *nk = [#(#next_fields),*];
                            if k == 0 {
                                accel = o.accel;
                                z_next = o.z_next;
                            }
                        }
                        let [z_post, ..] = self.x;
                        if let Some(stop) = resting_stop(mode_of(z_post), accel, z_next) {
                            for nk in next.iter_mut() {
                                let [_, #(#rest_next_pattern),*] = *nk;
                                *nk = [stop, #(#rest_next_pattern),*];
                            }
                        }
                        let mean = linalg::weighted_mean(&next, WEIGHT_MEAN0, WEIGHT);
                        let mut p = linalg::weighted_covariance(&next, &mean, WEIGHT_COV0, WEIGHT);
                        p = linalg::add(&p, &linalg::diagonal(&PROCESS_VARIANCE));
                        #gain_call
                        linalg::rank1_update(&mut p, INPUT_VARIANCE, &#gain);
                        #accept_mean
                        #time_let
                        let mut updated = false;
                        if u_ok && #y.is_finite() {
                            let l = self.factor();
                            let pts: [[#ty; #dim]; #m_lit] = linalg::sigma_points(&self.x, &l, GAMMA);
                            let mut ys = [0.0; #m_lit];
                            let mut dy_du = 0.0;
                            for (k, (yk, pt)) in ys.iter_mut().zip(&pts).enumerate() {
                                let [#(#names),*] = *pt;
                                let m = measurement(#(#names),*, u #time_arg);
                                *yk = m.#y;
                                if k == 0 {
                                    dy_du = m.#dy_du;
                                }
                            }
                            let mut y_mean = 0.0;
                            for (k, &yk) in ys.iter().enumerate() {
                                y_mean += weight_mean(k) * yk;
                            }
                            let mut s = 0.0;
                            for (k, &yk) in ys.iter().enumerate() {
                                let d = yk - y_mean;
                                s += weight_cov(k) * (d * d);
                            }
                            let r = MEASUREMENT_VARIANCE + INPUT_VARIANCE * (dy_du * dy_du);
                            let s = s + r;
                            let pxy = linalg::weighted_cross(&pts, &self.x, &ys, y_mean, WEIGHT_COV0, WEIGHT);
                            let innovation = #y - y_mean;
                            if innovation.is_finite() && s.is_finite() && s > 0.0 {
                                let k = pxy.map(|x| x / s);
                                linalg::axpy(&mut self.x, innovation, &k);
                                linalg::rank1_update(&mut self.p, -s, &k);
                                updated = true;
                            }
                        }
                        if !updated {
                            self.skipped = self.skipped.saturating_add(1);
                        }
                        let [z, z_prev, #(#rest_pattern),*] = self.x;
                        let (z, z_prev) = (project(z), project(z_prev));
                        self.x = [z, z_prev, #(#rest_pattern),*];
                        let mode = mode_of(z);
                        #estimate
                    }

                    #accessors

                    /// Repaired factorisations and restarts after a non-finite prediction.
                    #[must_use]
                    pub const fn repairs(&self) -> u32 {
                        self.repairs
                    }
                }
            }
        }
    };
    items.extend(filter);

    let (what, algorithm) = match kind {
        Kind::Ekf => (
            "extended",
            "Update with the symbolic ∂h/∂x in Joseph form, prediction with the symbolic ∂F/∂x.",
        ),
        Kind::Ukf => (
            "unscented",
            "Sigma points x̄ ± γ·(columns of chol P) through h and F; Cholesky failures\n\
             are repaired and counted.",
        ),
    };
    let module_doc = doc_attrs(&format!(
        "The {what} Kalman filter of `{name}` in {float}, on the discretised model of\n\
         jiles-atherton-actuator-model §6.1 (84)–(87) with x = [{state_doc}].\n\
         {algorithm}\n\
         Process noise Q = diag(q_z², 0, q_φ²(, q_Hc²)) + σ_u²·g·gᵀ (g = ∂F/∂u: the\n\
         measured input's noise), measurement variance σ_y² + σ_u²·(∂h/∂u)². The model is\n\
         evaluated at z in [z_min, z_max]; the posterior z, z_prev are projected onto it.",
        name = input.name,
        float = float.name(),
    ));
    let tokens = quote! {
        #module_doc
        pub mod #module {
            use reldesign_runtime::linalg;

            #items
        }
    };
    let mut text = space_items(&format_items(tokens)?);
    for f in &functions {
        text = comment_lets(&text, f.name, &f.comments());
    }
    Ok(comment_lines(&text, &step_comments(kind)))
}

/// `//` comments of the filter's code (tokens cannot carry them): (the start
/// of the line they precede, the comment).
fn step_comments(kind: Kind) -> Vec<(&'static str, &'static str)> {
    let mut c = vec![
        (
            "let u = self.u_last;",
            "a non-finite input is replaced by the last finite one (and its update skipped)",
        ),
        (
            "let mut updated = false;",
            match kind {
                Kind::Ekf => "Measurement update, Joseph form (symmetric and positive semi-definite for any\n\
                              rounding of the gain). Skipped when u, the measurement, the innovation\n\
                              variance or the innovation is not finite: a NaN or ∞ never enters the state\n\
                              (where it would stay forever).",
                Kind::Ukf => "Measurement update through the sigma points. Skipped when u, the measurement,\n\
                              the innovation variance or the innovation is not finite: a NaN or ∞ never\n\
                              enters the state (where it would stay forever).",
            },
        ),
        (
            "let (z, z_prev) = (project(z), project(z_prev));",
            "the posterior: z and z_prev projected onto [z_min, z_max], mode (86)",
        ),
        (
            "self.x = INITIAL_STATE;",
            "a non-finite prediction: restart from x₀, P₀ (counted)",
        ),
        (
            "let resting = resting_stop(",
            "on a stop, or reaching it (f_v into it): the prediction keeps z = the stop",
        ),
        (
            "let a = if mode == 2",
            "the estimate (85)–(87) at the posterior; f_v of (87) only in mode 2",
        ),
        (
            "if let Some(stop) = resting_stop(",
            "on a stop, or reaching it (f_v into it): every point keeps z = the stop",
        ),
    ];
    match kind {
        Kind::Ekf => c.push((
            "let o = transition(",
            "prediction (84) from the last posterior with u held over the last sample:\n\
             x = F(x, u), P = F_x·P·F_xᵀ + Q",
        )),
        Kind::Ukf => {
            c.push((
                "let mut next = pts;",
                "prediction: the last posterior's sigma points through (84), u held over the\n\
                 last sample",
            ));
            c.push((
                "linalg::rank1_update(&mut p, INPUT_VARIANCE,",
                "the input's noise: Q += σ_u²·g·gᵀ, g = ∂F/∂u at the posterior mean",
            ));
        }
    }
    c
}

/// Puts `// comment` (each of its lines) above every line starting (after
/// its indent) with one of the anchors.
fn comment_lines(text: &str, comments: &[(&str, &str)]) -> String {
    let mut out = String::with_capacity(text.len() + 1024);
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if let Some((_, comment)) = comments.iter().find(|(a, _)| trimmed.starts_with(a)) {
            let indent = &line[..line.len() - trimmed.len()];
            for c in comment.lines() {
                out.push_str(indent);
                out.push_str("// ");
                out.push_str(c.trim_start());
                out.push('\n');
            }
        }
        out.push_str(line);
    }
    out
}
