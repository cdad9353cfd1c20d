//! The perfect-tracking soft-landing controller as emitted Rust
//! (perfect-tracking-soft-landing [PT §3.2] and [PT §4]): a rendering of
//! `designer::design::ControllerDesign`. The law's functions are written
//! once, in `macro_rules! law { ($f:ty) => { … } }` over the float type:
//! `law_terms` (the law [PT 50] through the expression emitter, with
//! unsuffixed literals that `$f` types, see `float::Scalar`), `law` and the
//! guarded, saturated `guarded_law`. Then one module per float type (`pub mod
//! f64 { … }` / `pub mod f32 { … }`) holds
//!
//! - `params!(f…)`: the model parameters, the stroke limits `Z_MIN`,
//!   `Z_MAX` and the physical constants `MU0`, `Z_EPS`, from the file's one
//!   `params!` macro (`emit::params_macro`), and `law!(f…)`;
//! - the design constants (gains, supply bounds, timing, guard threshold,
//!   landed band, press, creep), in literals of the float type;
//! - the reference tables, one `[[f; 7]; N]` per operation, one row
//!   `[t_k, z_k, v_k, c0, c1, c2, c3]` per line (`designer::design::Segments`);
//! - `Operation`, `Design` (the runtime's `control::Law` over the consts,
//!   tables and law) and `Controller = control::SoftLanding<Design, f…>`.
//!
//! The operation logic (pre-movement, table lookup, press and creep, the
//! hold rules [SM 43], the guard at φ → 0, saturation) is not emitted: it is
//! `reldesign_runtime::control`, written once; its module docs state the
//! rules. The emitted code has no `unwrap`, `expect`, indexing, `panic`,
//! `as` or allocation, and depends only on `reldesign_runtime`.

use designer::description::Operation;
use designer::design::ControllerDesign;
use designer::model::Model;
use designer::sym::{Graph, Id};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use crate::emit::{function_tokens_as, FunctionSpec, Inline};
use crate::error::EmitError;
use crate::float::{Float, Scalar, MACRO_LITERALS};
use crate::format::{comment_lets, format_items, macro_rules, space_items};
use crate::names::const_name;
use crate::param::Param;
use crate::physical::{in_scope, of_model};

/// Why a controller could not be emitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControllerError {
    #[error(transparent)]
    Emit(#[from] EmitError),
    #[error("no float type to emit")]
    NoFloat,
    #[error("the design value `{name}` = {value} is not finite in the float type")]
    BadValue { name: String, value: f64 },
    #[error(
        "the name `{0}` of a design constant or reference symbol is already taken by the model"
    )]
    NameTaken(String),
}

/// Everything [`emit_controller`] needs.
#[derive(Clone)]
pub struct ControllerInput<'a> {
    /// The model the design is for (graph, parameters, states, stroke).
    pub model: &'a Model,
    pub design: &'a ControllerDesign,
    /// Emitted float types, in this order (duplicates ignored).
    pub floats: Vec<Float>,
}

/// Names of the design constants (checked against the parameters' const names).
const DESIGN_CONSTS: &[&str] = &[
    "GAIN_K1",
    "GAIN_K2",
    "GAIN_K3",
    "U_MIN",
    "U_MAX",
    "T_TAKEOFF",
    "T_LANDING",
    "SAMPLE_PERIOD",
    "PHI_GUARD",
    "LANDED_BAND",
    "PRESS",
    "CREEP",
    "CREEP_MAX",
    "REFERENCE_CLOSING",
    "REFERENCE_OPENING",
];

/// Symbols of the law's reference inputs and gains (must be new to the graph).
const REF_SYMBOLS: [&str; 4] = ["z_ref", "v_ref", "a_ref", "j_ref"];
const GAIN_SYMBOLS: [&str; 3] = ["gain_k1", "gain_k2", "gain_k3"];

/// The `law!` macro (the law's functions, written once) and the
/// controller's float modules that invoke it, formatted and deterministic;
/// each module invokes the file's `params!` macro too (which must precede
/// them).
pub fn emit_controller(input: &ControllerInput) -> Result<String, ControllerError> {
    let mut floats: Vec<Float> = Vec::new();
    for &f in &input.floats {
        if !floats.contains(&f) {
            floats.push(f);
        }
    }
    if floats.is_empty() {
        return Err(ControllerError::NoFloat);
    }
    for (name, _, _) in input.model.params.iter() {
        let cname = const_name(name)?;
        if DESIGN_CONSTS.contains(&cname.as_str()) {
            return Err(ControllerError::NameTaken(cname));
        }
    }
    let mut graph = input.model.graph.clone();
    let law = LawSymbols::build(&mut graph, input.design, &input.model.named)?;
    // MU0, Z_EPS as the file's params! declares them
    let physical = in_scope(&mut graph, &of_model(input.model));
    let f32 = floats.contains(&Float::F32);
    let mut out = law_macro(&graph, input, &law, &physical, Scalar::Macro { f32 })?;
    for float in floats {
        out.push('\n');
        out.push_str(&float_module(input, float)?);
    }
    Ok(out)
}

/// The law's symbols and expressions in the (cloned) graph. The outputs
/// build on each other through symbols that stand for earlier outputs, as
/// the equations do: w uses ξ₃, u = β·(w − L_f³h) uses β, w and L_f³h.
struct LawSymbols {
    refs: [Id; 4],
    gains: [Id; 3],
    /// Symbols standing for the outputs ξ₃, L_f³h, β, w.
    staged: [Id; 4],
    /// [PT 41] ξ₃ = L_f²h, [PT 31] L_f³h, [PT 32] β: the linearization's expressions
    /// with common factors pulled out of their sums (`Graph::factor_sums`).
    xi3: Id,
    lf3h: Id,
    beta: Id,
    /// [PT 32] α = −L_f³h·β
    alpha: Id,
    /// [PT 48] w = K·(ξ_r − T(x)) + j_r
    w: Id,
    /// [PT 50] u = α + β·w = β·(w − L_f³h)
    u: Id,
    /// The model's named subexpressions (`Model::named`), factored like the law.
    named: Vec<(&'static str, Id)>,
}

/// Output names the `staged` symbols stand for, in order.
const STAGED_OUTPUTS: [&str; 4] = ["xi3", "lf3h", "beta", "w"];

impl LawSymbols {
    fn build(
        g: &mut Graph,
        design: &ControllerDesign,
        named: &[(&'static str, Id)],
    ) -> Result<LawSymbols, ControllerError> {
        let mut fresh = |name: &str| {
            if g.find_symbol(name).is_some() {
                Err(ControllerError::NameTaken(name.to_owned()))
            } else {
                Ok(g.symbol(name))
            }
        };
        let refs = [
            fresh(REF_SYMBOLS[0])?,
            fresh(REF_SYMBOLS[1])?,
            fresh(REF_SYMBOLS[2])?,
            fresh(REF_SYMBOLS[3])?,
        ];
        let gains = [
            fresh(GAIN_SYMBOLS[0])?,
            fresh(GAIN_SYMBOLS[1])?,
            fresh(GAIN_SYMBOLS[2])?,
        ];
        let staged = [
            fresh("law_xi3")?,
            fresh("law_lf3h")?,
            fresh("law_beta")?,
            fresh("law_w")?,
        ];
        let [xi3, lf3h, beta, w_sym] = staged;
        let lin = &design.linearization;
        // [PT 41] T(x) = [z, v, ξ₃]
        let transform = [lin.transform[0], lin.transform[1], xi3];
        let mut terms = Vec::new();
        for i in 0..3 {
            let err = g.sub(refs[i], transform[i]);
            terms.push(g.mul(gains[i], err));
        }
        terms.push(refs[3]);
        let w = g.sum(&terms);
        let minus_lf3h = g.neg(lf3h);
        let alpha = g.mul(minus_lf3h, beta);
        let w_minus_lf3h = g.sub(w_sym, lf3h);
        let u = g.mul(beta, w_minus_lf3h);
        // the model's named subexpressions go through the same factoring, so
        // that their images are the nodes the law reaches
        let mut roots = vec![lin.transform[2], lin.lf3h, lin.beta, w, alpha, u];
        roots.extend(named.iter().map(|n| n.1));
        let factored = g.factor_sums(&roots);
        let (law, named_images) = factored.split_at(6);
        let &[xi3_expr, lf3h_expr, beta_expr, w, alpha, u] = law else {
            unreachable!("factor_sums maps each root")
        };
        let named = named
            .iter()
            .zip(named_images)
            .map(|(&(name, _), &id)| (name, id))
            .collect();
        Ok(LawSymbols {
            refs,
            gains,
            staged,
            xi3: xi3_expr,
            lf3h: lf3h_expr,
            beta: beta_expr,
            alpha,
            w,
            u,
            named,
        })
    }
}

/// (output, equation) of the `//` comments above the outputs' `let`s.
type Comments = Vec<(&'static str, &'static str)>;

/// `law_terms`, the law [PT 50] through the expression emitter, inlined into
/// every caller (one call, no stored outputs).
fn law_terms(
    graph: &Graph,
    input: &ControllerInput,
    law: &LawSymbols,
    physical: &[Param],
    scalar: Scalar,
) -> Result<(TokenStream, Comments), ControllerError> {
    let model = input.model;
    let mut params: Vec<Param> = model.params.iter().map(Param::from).collect();
    params.extend_from_slice(physical);
    for ((&id, name), &k) in law.gains.iter().zip(GAIN_SYMBOLS).zip(&input.design.gains) {
        params.push(Param::from((name, id, k)));
    }
    let [z, v, phi] = [model.states[0], model.states[1], model.states[2]];
    let outputs = vec![
        ("xi3", law.xi3, "[PT 41] ξ₃ = a(x) = L_f²h"),
        ("lf3h", law.lf3h, "[PT 31] L_f³h"),
        ("beta", law.beta, "[PT 32] β(x) = 1 / L_g L_f²h"),
        (
            "w",
            law.w,
            "[PT 48] w = K·(ξ_r − T(x)) + z_r⁽³⁾, T(x) = [z, v, ξ₃] [PT 41]",
        ),
        (
            "alpha",
            law.alpha,
            "[PT 32] α(x) = −L_f³h / L_g L_f²h = −L_f³h·β",
        ),
        ("u", law.u, "[PT 50] u = α + β·w = β·(w − L_f³h)"),
    ];
    let comments = outputs.iter().map(|&(n, _, d)| (n, d)).collect();
    let spec = FunctionSpec {
        name: "law_terms",
        doc: "The terms of the tracking law [PT 50] at the state x = [z, v, φ] and the\n\
              reference ξ_r = [z_r, v_r, a_r], z_r⁽³⁾ = j_r (not saturated, not guarded:\n\
              φ = 0 makes β infinite, see [`guarded_law`]).",
        inputs: vec![
            ("z", z),
            ("v", v),
            ("phi", phi),
            ("zr", law.refs[0]),
            ("vr", law.refs[1]),
            ("ar", law.refs[2]),
            ("jr", law.refs[3]),
        ],
        outputs,
        named: law.named.clone(),
        output_symbols: STAGED_OUTPUTS.into_iter().zip(law.staged).collect(),
        // written in `scalar` (function_tokens_as)
        float: Float::F64,
    };
    let tokens = function_tokens_as(graph, &spec, &params, Inline::Always, scalar)?;
    Ok((tokens, comments))
}

/// Typed literal of `value` in `float`, or the error naming it.
fn lit(float: Float, name: &str, value: f64) -> Result<TokenStream, ControllerError> {
    float
        .unsuffixed_signed(value)
        .ok_or_else(|| ControllerError::BadValue {
            name: format!("{name} ({})", float.name()),
            value,
        })
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

/// The design constants, documented.
fn design_consts(d: &ControllerDesign, float: Float) -> Result<TokenStream, ControllerError> {
    let [k1, k2, k3] = d.gains;
    let consts = [
        ("GAIN_K1", k1, "k1 of K = [k1, k2, k3] [PT 48]: s³ + k3·s² + k2·s + k1 is the characteristic polynomial of [PT 49]."),
        ("GAIN_K2", k2, "k2 of K [PT 48]."),
        ("GAIN_K3", k3, "k3 of K [PT 48]."),
        ("U_MIN", d.u_min, "Lower supply limit u_min."),
        ("U_MAX", d.u_max, "Upper supply limit u_max."),
        ("T_TAKEOFF", d.takeoff, "t₀ [s] from the operation's start: end of the pre-movement stage [PT 51]."),
        ("T_LANDING", d.landing, "t_f [s] from the operation's start: end of the motion [PT 51]."),
        ("SAMPLE_PERIOD", d.sample_period, "T_s [s]: call `Controller::step` once per sample period."),
        ("PHI_GUARD", d.phi_guard, "Guard at φ → 0 [Wb]: where φ ≤ PHI_GUARD the law is not evaluated and u = u_max\n(drives the flux into D₀⁺). 10⁻³ of the smallest flux the reference needs, rounded down."),
        ("LANDED_BAND", d.landed_band, "Distance [m] to the end stop within which the armature counts as in contact\n(expert rules after t_f): 10⁻⁹ of the stroke, rounded down."),
        ("PRESS", d.press, "After t_f the reference lies PRESS·stroke beyond the end stop: the loop closes\nthe last gap gently and the contact is certain."),
        ("CREEP", d.creep, "After t_f the reference creeps on beyond the stop at CREEP·stroke per second [1/s]:\nwhere the plant differs from the model and a pure hold would hover short of the\nstop, the armature still lands, at about that speed."),
        ("CREEP_MAX", d.creep_max, "The creep stops CREEP_MAX·stroke beyond the end stop."),
    ];
    let ty = float.ty();
    let mut items = TokenStream::new();
    for (name, value, doc) in consts {
        let id = format_ident!("{name}");
        let value = lit(float, name, value)?;
        let docs = doc_attrs(doc);
        items.extend(quote!(#docs pub const #id: #ty = #value;));
    }
    Ok(items)
}

/// The rust names of an operation: (variant, table const, landing, doc).
fn names(
    op: Operation,
) -> (
    proc_macro2::Ident,
    &'static str,
    proc_macro2::Ident,
    &'static str,
) {
    match op {
        Operation::Closing => (
            format_ident!("Closing"),
            "REFERENCE_CLOSING",
            format_ident!("Closing"),
            "Closing: z_max → z_min.",
        ),
        Operation::Opening => (
            format_ident!("Opening"),
            "REFERENCE_OPENING",
            format_ident!("Opening"),
            "Opening: z_min → z_max.",
        ),
    }
}

/// One reference table as text: the const with one row per line (the
/// formatter would put each number on a line of its own), at `indent`.
fn table_text(
    table: &str,
    rows: &[[f64; 7]],
    float: Float,
    indent: &str,
) -> Result<String, ControllerError> {
    let ty = float.name();
    let mut out = format!(
        "{indent}pub const {table}: [[{ty}; 7]; {}] = [\n",
        rows.len()
    );
    for row in rows {
        let mut cells = Vec::with_capacity(row.len());
        for &x in row {
            cells.push(float.literal_text(x).ok_or(ControllerError::BadValue {
                name: format!("{table} ({ty})"),
                value: x,
            })?);
        }
        out.push_str(&format!("{indent}    [{}],\n", cells.join(", ")));
    }
    out.push_str(&format!("{indent}];\n"));
    Ok(out)
}

/// The placeholder a table's rows stand in for until the module is formatted.
fn placeholder(table: &str) -> String {
    format!("__ROWS_OF_{table}__")
}

/// The per-operation items of a float module.
struct Operations {
    /// The table consts, their rows left to [`splice_table`].
    tables: TokenStream,
    /// The `Operation` variants.
    variants: TokenStream,
    /// The match arms of `Law::motion`.
    motions: TokenStream,
}

fn operations(input: &ControllerInput, float: Float) -> Result<Operations, ControllerError> {
    let ty = float.ty();
    let mech = &input.model.description.mechanics;
    // the end stops by the names params! gives them
    let position = |name: &str, z: f64| -> Result<TokenStream, ControllerError> {
        Ok(if z == mech.z_min {
            quote!(Z_MIN)
        } else if z == mech.z_max {
            quote!(Z_MAX)
        } else {
            lit(float, name, z)?
        })
    };
    let (mut tables, mut variants, mut motions) =
        (TokenStream::new(), TokenStream::new(), TokenStream::new());
    for op in &input.design.operations {
        let (variant, table_name, landing, doc) = names(op.operation);
        let table = format_ident!("{table_name}");
        let n = Literal::usize_unsuffixed(op.table.segments.len());
        let rows = format_ident!("{}", placeholder(table_name));
        let table_doc = doc_attrs(&format!(
            "Reference of the {} motion z_m on [t₀, t_f] [PT 51]: one row\n[t_k, z_k, v_k, c0, c1, c2, c3] per segment, t_k from the operation's start;\na(τ) = c0 + c1·τ + c2·τ² + c3·τ³ with τ = t − t_k, v and z its integrals.",
            variant.to_string().to_lowercase()
        ));
        tables.extend(quote!(#table_doc pub const #table: [[#ty; 7]; #n] = #rows;));
        let doc = format!(" {doc}");
        variants.extend(quote!(#[doc = #doc] #variant,));
        let (z0, zf) = (position("z0", op.z0)?, position("zf", op.zf)?);
        motions.extend(quote!(
            Operation::#variant => control::Motion {
                landing: control::Landing::#landing,
                z0: #z0,
                zf: #zf,
                table: &#table,
            },
        ));
    }
    Ok(Operations {
        tables,
        variants,
        motions,
    })
}

/// `macro_rules! law`: `law_terms` (the expression emitter's), `law` and
/// `guarded_law`, written once over the float type `$f`.
fn law_macro(
    graph: &Graph,
    input: &ControllerInput,
    law: &LawSymbols,
    physical: &[Param],
    scalar: Scalar,
) -> Result<String, ControllerError> {
    let ty = scalar.ty();
    let (law_fn, comments) = law_terms(graph, input, law, physical, scalar)?;
    let law_args = quote!(z: #ty, v: #ty, phi: #ty, zr: #ty, vr: #ty, ar: #ty, jr: #ty);
    let tokens = quote! {
        #law_fn

        /// u of the tracking law [PT 50], not saturated and not guarded.
        #[must_use]
        pub fn law(#law_args) -> #ty {
            law_terms(z, v, phi, zr, vr, ar, jr).u
        }

        /// The law [PT 50] as applied (`reldesign_runtime::control::guarded_law`): if
        /// φ ≤ `PHI_GUARD` (φ → 0, where β = 1/L_g L_f²h blows up and D₀⁺ is left) it
        /// is not evaluated and u = u_max drives the flux back into D₀⁺; otherwise u
        /// of [PT 50]. Saturated to [u_min, u_max] (a NaN maps to the bound nearest 0,
        /// ±∞ to the bounds).
        #[must_use]
        pub fn guarded_law(#law_args) -> #ty {
            control::guarded_law::<Design, #ty>([z, v, phi], [zr, vr, ar, jr])
        }
    };
    let text = comment_lets(&space_items(&format_items(tokens)?), "law_terms", &comments);
    let doc = format!(
        "The tracking law [PT 50] of `{}` over the float type `$f`, written once:\n\
         `law_terms`, `law` and `guarded_law`, declared in each float module as `law!(f64)` /\n\
         `law!(f32)` beside the module's `params!`, gains and `Design`.\n{MACRO_LITERALS}",
        input.model.description.name
    );
    Ok(macro_rules("law", &doc, &text))
}

/// One `pub mod f64 { … }` / `pub mod f32 { … }`, formatted.
fn float_module(input: &ControllerInput, float: Float) -> Result<String, ControllerError> {
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let design = input.design;
    let consts = design_consts(design, float)?;
    let Operations {
        tables,
        variants,
        motions,
    } = operations(input, float)?;
    let tokens = quote! {
        #[doc = " The controller in this float type."]
        pub mod #module {
            use reldesign_runtime::control;

            params!(#ty);
            law!(#ty);

            #consts

            #tables

            /// A designed switching operation.
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub enum Operation {
                #variants
            }

            /// This module's design (limits, timing, guards, tables, the law [PT 50] of
            /// `law!`) as the runtime's soft-landing logic reads it.
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub struct Design;

            impl control::Law<#ty> for Design {
                type Operation = Operation;

                const SETTINGS: control::Settings<#ty> = control::Settings {
                    u_min: U_MIN,
                    u_max: U_MAX,
                    takeoff: T_TAKEOFF,
                    landing: T_LANDING,
                    phi_guard: PHI_GUARD,
                    landed_band: LANDED_BAND,
                    press: PRESS,
                    creep: CREEP,
                    creep_max: CREEP_MAX,
                };

                fn motion(operation: Operation) -> control::Motion<#ty> {
                    match operation {
                        #motions
                    }
                }

                #[inline(always)]
                fn law([z, v, phi]: [#ty; 3], [zr, vr, ar, jr]: [#ty; 4]) -> #ty {
                    law_terms(z, v, phi, zr, vr, ar, jr).u
                }
            }

            /// One operation of the actuator (`reldesign_runtime::control::SoftLanding`):
            /// pre-movement stage before t₀ (ξ_r = [z₀, 0, 0], which brings ξ₃ to 0 so the
            /// forces balance at takeoff), tracking of the table on [t₀, t_f], hold at z_f
            /// after t_f with the expert rules of model-free-sliding-mode [SM 43] at the end
            /// stop; `new`, `start`, `reference`, `step`. Allocation- and panic-free.
            pub type Controller = control::SoftLanding<Design, #ty>;
        }
    };
    let mut text = space_items(&format_items(tokens)?);
    for op in &design.operations {
        let (_, table_name, _, _) = names(op.operation);
        text = splice_table(&text, table_name, &op.table.segments, float)?;
    }
    Ok(text)
}

/// Replaces the formatted `pub const TABLE: … = __ROWS_OF_TABLE__;` line by
/// the table with one row per line.
fn splice_table(
    text: &str,
    table: &str,
    rows: &[[f64; 7]],
    float: Float,
) -> Result<String, ControllerError> {
    let marker = format!(" = {};", placeholder(table));
    let mut out = String::with_capacity(text.len() + rows.len() * 160);
    let mut spliced = false;
    for line in text.split_inclusive('\n') {
        if line.trim_end().ends_with(&marker) {
            let indent = &line[..line.len() - line.trim_start().len()];
            out.push_str(&table_text(table, rows, float, indent)?);
            spliced = true;
        } else {
            out.push_str(line);
        }
    }
    if !spliced {
        let what = format!("the line of `{table}` was not found after formatting");
        return Err(EmitError::Syntax(what).into());
    }
    Ok(out)
}
