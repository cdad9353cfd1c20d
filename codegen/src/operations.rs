//! What every controller module states, whichever its law: its input
//! ([`ControllerInput`]: model, design, float types), the design
//! constants the runtime's `control::Settings` reads (supply bounds, timing,
//! guard threshold, landed band, press, creep), the reference tables (one
//! `[[f; 7]; N]` per operation, one row `[t_k, z_k, v_k, c0, c1, c2, c3]` per
//! line, `designer::design::Segments`), the `Operation` enum and the unit
//! struct `Design` with the runtime's `control::ConstPlan` and
//! `control::Plan`. The law's own items (`controller.rs`, `sliding.rs`) come
//! beside them.

use designer::description::Operation;
use designer::design::ControllerDesign;
use designer::model::Model;
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use crate::emit::doc_attrs;
use crate::error::{ControllerError, EmitError};
use crate::float::Float;
use crate::names::const_name;

/// Everything a tracking law's module (`controller.rs`, `sliding.rs`)
/// needs: [`crate::emit_controller`]'s input.
#[derive(Clone)]
pub struct ControllerInput<'a> {
    /// The model the design is for (graph, parameters, states, stroke).
    pub model: &'a Model,
    pub design: &'a ControllerDesign,
    /// Emitted float types, in this order (duplicates ignored).
    pub floats: Vec<Float>,
    /// The self-calibration (`[controller] self_calibration`): the law reads
    /// the adapted parameters at run time.
    pub calibration: Option<&'a designer::calibrate::CalibrationDesign>,
}

/// Names of the plan's constants (checked against the parameters' const names).
const PLAN_CONSTS: &[&str] = &[
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
    "ARRIVAL_MARGIN",
    "REFERENCE_CLOSING",
    "REFERENCE_OPENING",
];

/// The float types of `input`, each once in the order given (at least one),
/// after checking that no model parameter's const takes the name of a plan
/// const or of one of the law's own `law_consts`.
pub fn checked_floats(
    input: &ControllerInput,
    law_consts: &[&str],
) -> Result<Vec<Float>, ControllerError> {
    unique_floats(input.model, &input.floats, &[PLAN_CONSTS, law_consts])
}

/// `floats` each once in the order given (at least one), after checking
/// that no parameter const of `model` takes a name of the `taken` lists
/// (the module's own consts).
pub fn unique_floats(
    model: &Model,
    floats: &[Float],
    taken: &[&[&str]],
) -> Result<Vec<Float>, ControllerError> {
    let mut unique: Vec<Float> = Vec::new();
    for &f in floats {
        if !unique.contains(&f) {
            unique.push(f);
        }
    }
    if unique.is_empty() {
        return Err(ControllerError::NoFloat);
    }
    for (name, _, _) in model.params.iter() {
        let cname = const_name(name)?;
        if taken.iter().any(|names| names.contains(&cname.as_str())) {
            return Err(ControllerError::NameTaken(cname));
        }
    }
    Ok(unique)
}

/// `pub const NAME: f = value;` per entry, each with its doc.
pub fn documented_consts(
    float: Float,
    consts: &[(&str, f64, &str)],
) -> Result<TokenStream, ControllerError> {
    let ty = float.ty();
    let mut items = TokenStream::new();
    for &(name, value, doc) in consts {
        let id = format_ident!("{name}");
        let value = lit(float, name, value)?;
        let docs = doc_attrs(doc);
        items.extend(quote!(#docs pub const #id: #ty = #value;));
    }
    Ok(items)
}

/// The plan's constants, documented.
fn plan_consts(d: &ControllerDesign, float: Float) -> Result<TokenStream, ControllerError> {
    documented_consts(
        float,
        &[
            ("U_MIN", d.u_min, "Lower supply limit u_min."),
            ("U_MAX", d.u_max, "Upper supply limit u_max."),
            ("T_TAKEOFF", d.takeoff, "t₀ [s] from the operation's start: end of the pre-movement stage [PT 51]."),
            ("T_LANDING", d.landing, "t_f [s] from the operation's start: end of the motion [PT 51]."),
            ("SAMPLE_PERIOD", d.sample_period, "T_s [s]: call `Controller::step` once per sample period."),
            ("PHI_GUARD", d.phi_guard, "Guard at φ → 0 [Wb]: where φ ≤ PHI_GUARD the feedback-linearizing law is not\nevaluated and u = u_max (drives the flux into D₀⁺). 10⁻³ of the smallest flux the\nreference needs, rounded down. (The sliding-mode law has no singularity there.)"),
            ("LANDED_BAND", d.landed_band, "Distance [m] to the end stop within which the armature counts as in contact\n(the expert rules [SM 43]): 10⁻⁹ of the stroke, rounded down."),
            ("PRESS", d.press, "After t_f the reference lies PRESS·stroke beyond the end stop: the loop closes\nthe last gap gently and the contact is certain."),
            ("CREEP", d.creep, "After t_f the reference creeps on beyond the stop at CREEP·stroke per second [1/s]:\nwhere the plant differs from the model and a pure hold would hover short of the\nstop, the armature still lands, at about that speed."),
            ("CREEP_MAX", d.creep_max, "The creep stops CREEP_MAX·stroke beyond the end stop."),
            ("ARRIVAL_MARGIN", d.arrival_margin, "No hover [s]: an armature not at its end stop by t_f + ARRIVAL_MARGIN is driven\nthere (closing: u_max; opening: the flux quenched, then 0 V), and the operation is\nflagged late unless it was then held or read within ARRIVAL_BAND of its stop. The\nmotion time t_f − t₀: a slow landing is not pushed."),
            ("ARRIVAL_BAND", d.arrival_band, "Distance [m] to the end stop within which the armature read at t_f + ARRIVAL_MARGIN\nhad arrived in time (not flagged late, though pushed): LANDED_BAND where the law reads\nthe position; where it reads an estimate, which creeps onto its clamp, the larger of\nLANDED_BAND and 1 % of the stroke."),
        ],
    )
}

/// The plan's items in a float module: its constants, tables (rows left to
/// [`splice_tables`]), `Operation`, `Design` (documented by `design_doc`) and
/// the runtime's `control::ConstPlan` and `control::Plan` on it.
pub fn plan_items(
    model: &Model,
    design: &ControllerDesign,
    float: Float,
    design_doc: &str,
    adapted: usize,
) -> Result<TokenStream, ControllerError> {
    let ty = float.ty();
    let consts = plan_consts(design, float)?;
    let design_type = design_type(adapted, &ty);
    let Operations {
        tables,
        variants,
        motions,
    } = operations(model, design, float)?;
    let design_doc = doc_attrs(design_doc);
    Ok(quote! {
        #consts

        #tables

        /// A designed switching operation.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Operation {
            #variants
        }

        #design_doc
        #design_type

        impl control::Plan<#ty> for Design {
            type Operation = Operation;

            #[inline(always)]
            fn settings(&self) -> control::Settings<#ty> {
                control::Settings {
                    u_min: U_MIN,
                    u_max: U_MAX,
                    takeoff: T_TAKEOFF,
                    landing: T_LANDING,
                    phi_guard: PHI_GUARD,
                    landed_band: LANDED_BAND,
                    press: PRESS,
                    creep: CREEP,
                    creep_max: CREEP_MAX,
                    arrival_margin: ARRIVAL_MARGIN,
                    arrival_band: ARRIVAL_BAND,
                }
            }

            fn motion(&self, operation: Operation) -> control::Motion<'_, #ty> {
                match operation {
                    #motions
                }
            }
        }
    })
}

/// `Design` and its `control::ConstPlan`: zero-sized, or (a self-calibrating
/// design) carrying θ, the adapted parameters the law reads, θ_d its default.
fn design_type(adapted: usize, ty: &proc_macro2::Ident) -> TokenStream {
    if adapted == 0 {
        return quote! {
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
            pub struct Design;

            impl control::ConstPlan for Design {
                const PLAN: Self = Design;
            }
        };
    }
    let p = proc_macro2::Literal::usize_unsuffixed(adapted);
    quote! {
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Design {
            /// θ: the adapted parameters, in the order of `ADAPTED` (set from
            /// `ukf::…::Calibration::theta` after an update).
            pub theta: [#ty; #p],
        }

        impl control::ConstPlan for Design {
            const PLAN: Self = Design { theta: THETA_DESIGN };
        }

        impl Default for Design {
            fn default() -> Self {
                <Self as control::ConstPlan>::PLAN
            }
        }
    }
}

/// Every table of `design` spliced into the formatted module `text`.
pub fn splice_tables(
    text: &str,
    design: &ControllerDesign,
    float: Float,
) -> Result<String, ControllerError> {
    let mut text = text.to_owned();
    for op in &design.operations {
        let (_, table_name, _, _) = names(op.operation);
        text = splice_table(&text, table_name, &op.table.segments, float)?;
    }
    Ok(text)
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
    /// The match arms of `Plan::motion`.
    motions: TokenStream,
}

fn operations(
    model: &Model,
    design: &ControllerDesign,
    float: Float,
) -> Result<Operations, ControllerError> {
    let ty = float.ty();
    let mech = &model.description.mechanics;
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
    for op in &design.operations {
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
