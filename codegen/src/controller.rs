//! The perfect-tracking soft-landing controller as one generated Rust file
//! (perfect-tracking-soft-landing §3.2 and §4).
//!
//! [`gains`] turns the description's `[controller].gains` into K of the
//! tracking law (48); [`emit_controller`] writes the whole controller:
//!
//! - a header (generator, source file, SHA-256 of its text, "do not edit");
//! - `macro_rules! params`: the model parameters, one `pub const` per line,
//!   instantiated in every float module (so one parameter change is one
//!   changed line, whatever the number of float types);
//! - per float type a module `pub mod f64 { … }` / `pub mod f32 { … }` with
//!   the design constants (gains, supply bounds, timing, guard threshold),
//!   the reference tables (one `[[f; 7]; N]` per operation, rows
//!   `[t_k, z_k, v_k, c0, c1, c2, c3]` as in `designer::design::Segments`),
//!   the law (50) `law_terms`/`law`, its guarded and saturated form
//!   `guarded_law`, and a `Controller` running one whole operation.
//!
//! Rules of the emitted controller (stated in its docs too):
//!
//! - before t₀ (pre-movement stage, §4): ξ_r = [z₀, 0, 0], j_r = 0, so the
//!   law brings ξ₃ = a(x) to 0, i.e. the forces into balance at takeoff;
//! - on [t₀, t_f]: ξ_r, j_r from the table, the segment cursor advanced
//!   monotonically (lookup with `.get()`);
//! - after t_f: ξ_r = [z_f + (z_f − z₀)·(PRESS + CREEP·(t − t_f)), (z_f − z₀)·CREEP, 0],
//!   a reference just beyond the end stop (10⁻⁶ of the stroke) that keeps
//!   creeping beyond it (at `[controller] creep_speed`, by default 2.5·10⁻³
//!   stroke per motion time, 0.5 mm/s for a 1 mm stroke in 5 ms; up to
//!   `CREEP_MAX` = 5 % of the stroke), so the loop
//!   closes whatever gap the tracking error left gently (at about λ·gap, tens
//!   of µm/s) and, when the plant differs from the model so that a
//!   pure hold would hover short of the stop, still lands (at about the
//!   creep speed); then, once the armature is at its end stop (within
//!   `LANDED_BAND`, 10⁻⁹ of the stroke: contact, not proximity — switching to
//!   full voltage a few nm early would slam it in), the expert rules of
//!   model-free-sliding-mode-soft-landing (43): closing → u = u_max·sgn φ
//!   (holds it closed; sgn 0 taken as +1), opening → u = 0;
//! - guard at φ → 0: where φ ≤ `PHI_GUARD` (10⁻³ of the smallest flux the
//!   reference needs, rounded down to one significant digit) the law is not
//!   evaluated and u = u_max drives the flux into D₀⁺ = {φ > 0};
//! - every output goes through `reldesign_runtime::saturate` (NaN → the
//!   bound nearest 0, ±∞ → the bounds), so any input gives a finite u in
//!   [u_min, u_max].
//!
//! The emitted code has no `unwrap`, `expect`, indexing, `panic`, `as` or
//! allocation, and depends only on `reldesign_runtime`.

use designer::description::{Gains, Operation};
use designer::design::{Linearization, Segments};
use designer::sym::{Graph, Id, Tape};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use crate::emit::{function_tokens_inline, FunctionSpec, Inline};
use crate::error::EmitError;
use crate::float::Float;
use crate::format::{comment_lets, format_items, space_items};
use crate::header::Header;
use crate::names::const_name;
use crate::param::Param;

/// 5 % settling-time criterion of a triple real pole.
const SETTLING_FRACTION: f64 = 0.05;

/// Fraction of the smallest reference flux below which the law is not
/// evaluated (before rounding down to one significant digit).
const GUARD_FRACTION: f64 = 1e-3;

/// Fraction of the stroke within which the armature counts as landed.
const LANDED_FRACTION: f64 = 1e-9;
/// The reference after t_f lies this fraction of the stroke beyond the end stop.
const PRESS_FRACTION: f64 = 1e-6;
/// After t_f the reference creeps on beyond the stop by this fraction of the
/// stroke per motion time t_f − t₀ …
const CREEP_FRACTION: f64 = 2.5e-3;
/// … up to this fraction of the stroke beyond it.
const CREEP_MAX_FRACTION: f64 = 0.05;

/// CREEP [1/s]: the creep after t_f in strokes per second, from
/// `creep_speed` [m/s] if given, else [`CREEP_FRACTION`] per motion time.
fn creep(input: &ControllerInput) -> f64 {
    let stroke = input
        .operations
        .first()
        .map_or(0.0, |o| (o.zf - o.z0).abs());
    match input.creep_speed {
        Some(speed) if stroke > 0.0 => speed / stroke,
        _ => CREEP_FRACTION / (input.landing - input.takeoff),
    }
}

/// Reference samples per segment when searching the smallest flux.
const FLUX_SAMPLES: usize = 64;

/// λ·t_s of a triple real pole −λ with 5 % settling time t_s: the root of
/// e^{−x}(1 + x + x²/2) = 0.05 (≈ 6.2958).
pub fn triple_pole_settling_product() -> f64 {
    // The residual decreases strictly for x > 0: bisection on [0, 50].
    let residual = |x: f64| (-x).exp() * (1.0 + x + 0.5 * x * x) - SETTLING_FRACTION;
    let (mut lo, mut hi) = (0.0_f64, 50.0_f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if residual(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// K = [k1, k2, k3] of (48): the error dynamics (49) ξ̃' = (A − BK)ξ̃ of the
/// triple integrator have the characteristic polynomial
/// s³ + k3·s² + k2·s + k1 = Π(s − p_i).
///
/// A settling time t_s places a triple pole at −λ, λ = 6.2958…/t_s (5 %
/// criterion), so K = [λ³, 3λ², 3λ].
pub fn gains(g: &Gains) -> [f64; 3] {
    let [p1, p2, p3] = match *g {
        Gains::SettlingTime(ts) => {
            let lambda = triple_pole_settling_product() / ts;
            [-lambda; 3]
        }
        Gains::Poles(p) => p,
    };
    [
        -(p1 * p2 * p3),
        p1 * p2 + p1 * p3 + p2 * p3,
        -(p1 + p2 + p3),
    ]
}

/// Why a controller could not be emitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControllerError {
    #[error(transparent)]
    Emit(#[from] EmitError),
    #[error("no operation to emit")]
    NoOperation,
    #[error("the {0:?} operation is given twice")]
    DuplicateOperation(Operation),
    #[error("no float type to emit")]
    NoFloat,
    #[error("the reference table of the {0:?} operation is empty")]
    EmptyTable(Operation),
    #[error("the reference table of the {operation:?} operation spans [{first}, {end}] s, not the motion [t0, tf] = [{takeoff}, {landing}] s")]
    TableTiming {
        operation: Operation,
        first: f64,
        end: f64,
        takeoff: f64,
        landing: f64,
    },
    #[error("the design value `{name}` = {value} is not finite or out of range")]
    BadValue { name: String, value: f64 },
    #[error(
        "the name `{0}` of a design constant or reference symbol is already taken by the model"
    )]
    NameTaken(String),
    #[error("the reference never needs a positive, finite flux: no guard threshold for φ → 0 can be derived")]
    NoFluxFloor,
}

/// One operation's reference.
#[derive(Debug, Clone, Copy)]
pub struct OperationTable<'a> {
    pub operation: Operation,
    /// Rest position before t₀ (z₀ of (51)).
    pub z0: f64,
    /// Rest position after t_f (z_f of (51)); the end stop of the hold.
    pub zf: f64,
    /// z_m on [t₀, t_f], times from the operation's start.
    pub segments: &'a Segments,
}

/// Everything [`emit_controller`] needs.
#[derive(Clone)]
pub struct ControllerInput<'a> {
    /// The description name (for the header and docs).
    pub name: &'a str,
    pub graph: &'a Graph,
    /// The model parameters, e.g. `model.params.iter().collect()`.
    pub params: Vec<Param<'a>>,
    /// The state symbols [z, v, φ] (`model.states[..3]`).
    pub states: [Id; 3],
    pub linearization: &'a Linearization,
    /// K = [k1, k2, k3] (see [`gains`]).
    pub gains: [f64; 3],
    /// T_s [s].
    pub sample_period: f64,
    /// Supply limits [u_min, u_max].
    pub u_min: f64,
    pub u_max: f64,
    /// t₀, t_f [s] from the operation's start.
    pub takeoff: f64,
    pub landing: f64,
    /// `[controller] creep_speed` [m/s]; `None`: the default creep.
    pub creep_speed: Option<f64>,
    pub operations: Vec<OperationTable<'a>>,
    /// Emitted float types, in this order.
    pub floats: Vec<Float>,
    pub source_file: &'a str,
    pub source_text: &'a str,
    /// `env!("CARGO_PKG_VERSION")` of the generator.
    pub generator_version: &'a str,
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

/// The controller as one formatted, deterministic Rust file (a module body,
/// usable as a file module or through `include!`).
pub fn emit_controller(input: &ControllerInput) -> Result<String, ControllerError> {
    let design = Design::check(input)?;
    let mut graph = input.graph.clone();
    let law = LawSymbols::build(&mut graph, input)?;

    let header = Header {
        what: &format!(
            "perfect-tracking soft-landing controller of `{}` (feedback linearization, eq. 50)",
            input.name
        ),
        generator_version: input.generator_version,
        source_file: input.source_file,
        source_text: input.source_text,
    }
    .text();

    let mut out = header;
    out.push('\n');
    out.push_str(&params_macro(input)?);
    let mut floats: Vec<Float> = Vec::new();
    for &f in &input.floats {
        if !floats.contains(&f) {
            floats.push(f);
        }
    }
    for float in floats {
        out.push('\n');
        out.push_str(&float_module(&graph, input, &design, &law, float)?);
    }
    Ok(out)
}

/// Derived design values, checked.
struct Design {
    phi_guard: f64,
    landed_band: f64,
}

impl Design {
    fn check(input: &ControllerInput) -> Result<Design, ControllerError> {
        if input.operations.is_empty() {
            return Err(ControllerError::NoOperation);
        }
        if input.floats.is_empty() {
            return Err(ControllerError::NoFloat);
        }
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(ControllerError::BadValue {
                    name: name.to_owned(),
                    value: v,
                })
            }
        };
        let finite = |name: &str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(ControllerError::BadValue {
                    name: name.to_owned(),
                    value: v,
                })
            }
        };
        for (k, &g) in input.gains.iter().enumerate() {
            positive(&format!("k{}", k + 1), g)?;
        }
        positive("sample_period", input.sample_period)?;
        positive("takeoff", input.takeoff)?;
        positive("landing - takeoff", input.landing - input.takeoff)?;
        finite("u_min", input.u_min)?;
        finite("u_max", input.u_max)?;
        positive("u_max - u_min", input.u_max - input.u_min)?;
        let mut stroke: f64 = 0.0;
        for (k, op) in input.operations.iter().enumerate() {
            if input.operations[..k]
                .iter()
                .any(|o| o.operation == op.operation)
            {
                return Err(ControllerError::DuplicateOperation(op.operation));
            }
            finite("z0", op.z0)?;
            finite("zf", op.zf)?;
            stroke = stroke.max((op.z0 - op.zf).abs());
            let s = op.segments;
            let first = s
                .segments
                .first()
                .ok_or(ControllerError::EmptyTable(op.operation))?[0];
            let tol = 1e-9 * input.landing;
            if (first - input.takeoff).abs() > tol || (s.end - input.landing).abs() > tol {
                return Err(ControllerError::TableTiming {
                    operation: op.operation,
                    first,
                    end: s.end,
                    takeoff: input.takeoff,
                    landing: input.landing,
                });
            }
            for row in &s.segments {
                for &x in row {
                    finite("reference table entry", x)?;
                }
            }
        }
        positive("stroke |z0 - zf|", stroke)?;
        let phi_min = smallest_reference_flux(input)?;
        Ok(Design {
            phi_guard: round_down_1sig(GUARD_FRACTION * phi_min),
            landed_band: round_down_1sig(LANDED_FRACTION * stroke),
        })
    }
}

/// `x > 0` rounded down to one significant digit (so that a small change of
/// the design does not change the emitted threshold).
fn round_down_1sig(x: f64) -> f64 {
    let e = x.log10().floor();
    let digit = (x / 10f64.powf(e)).floor().clamp(1.0, 9.0);
    format!("{digit}e{e}").parse().unwrap_or(x)
}

/// min over the reference (rest positions and samples of every segment) of
/// the flux T⁻¹ needs, √((ξ₃ − a₀)/c₂) (42), over the samples where it is
/// positive and finite.
fn smallest_reference_flux(input: &ControllerInput) -> Result<f64, ControllerError> {
    let lin = input.linearization;
    let mut inputs: Vec<Id> = lin.xi.to_vec();
    inputs.extend(input.params.iter().map(|p| p.symbol));
    let tape = Tape::compile(input.graph, &inputs, &[lin.flux_squared])
        .map_err(|e| EmitError::UnboundSymbol(e.0))?;
    let mut scratch = tape.scratch();
    let mut point: Vec<f64> = vec![0.0; 3];
    point.extend(input.params.iter().map(|p| p.value));
    let mut out = [0.0];
    let mut smallest = f64::INFINITY;
    let mut visit = |xi: [f64; 3]| {
        point[..3].copy_from_slice(&xi);
        tape.eval(&point, &mut scratch, &mut out);
        let phi2 = out[0];
        if phi2.is_finite() && phi2 > 0.0 {
            smallest = smallest.min(phi2.sqrt());
        }
    };
    for op in &input.operations {
        visit([op.z0, 0.0, 0.0]);
        visit([op.zf, 0.0, 0.0]);
        let segs = &op.segments.segments;
        for (k, seg) in segs.iter().enumerate() {
            let next = segs.get(k + 1).map_or(op.segments.end, |s| s[0]);
            let h = next - seg[0];
            for i in 0..=FLUX_SAMPLES {
                let tau = h * i as f64 / FLUX_SAMPLES as f64;
                let f = Segments::eval_segment(seg, tau);
                visit([f.z, f.v, f.a]);
            }
        }
    }
    if smallest.is_finite() {
        Ok(smallest)
    } else {
        Err(ControllerError::NoFluxFloor)
    }
}

/// The law's symbols and expressions in the (cloned) graph. The outputs
/// build on each other through symbols that stand for earlier outputs, as
/// the equations do: w uses ξ₃, u = β·(w − L_f³h) uses β, w and L_f³h.
struct LawSymbols {
    refs: [Id; 4],
    gains: [Id; 3],
    /// Symbols standing for the outputs ξ₃, L_f³h, β, w.
    staged: [Id; 4],
    /// (41) ξ₃ = L_f²h, (31) L_f³h, (32) β: the linearization's expressions
    /// with common factors pulled out of their sums (`Graph::factor_sums`).
    xi3: Id,
    lf3h: Id,
    beta: Id,
    /// (32) α = −L_f³h·β
    alpha: Id,
    /// (48) w = K·(ξ_r − T(x)) + j_r
    w: Id,
    /// (50) u = α + β·w = β·(w − L_f³h)
    u: Id,
}

/// Output names the `staged` symbols stand for, in order.
const STAGED_OUTPUTS: [&str; 4] = ["xi3", "lf3h", "beta", "w"];

impl LawSymbols {
    fn build(g: &mut Graph, input: &ControllerInput) -> Result<LawSymbols, ControllerError> {
        let fresh = |g: &mut Graph, name: &str| {
            if g.find_symbol(name).is_some() {
                Err(ControllerError::NameTaken(name.to_owned()))
            } else {
                Ok(g.symbol(name))
            }
        };
        let refs = [
            fresh(g, REF_SYMBOLS[0])?,
            fresh(g, REF_SYMBOLS[1])?,
            fresh(g, REF_SYMBOLS[2])?,
            fresh(g, REF_SYMBOLS[3])?,
        ];
        let gains = [
            fresh(g, GAIN_SYMBOLS[0])?,
            fresh(g, GAIN_SYMBOLS[1])?,
            fresh(g, GAIN_SYMBOLS[2])?,
        ];
        let staged = [
            fresh(g, "law_xi3")?,
            fresh(g, "law_lf3h")?,
            fresh(g, "law_beta")?,
            fresh(g, "law_w")?,
        ];
        let [xi3, lf3h, beta, w_sym] = staged;
        let lin = input.linearization;
        // (41) T(x) = [z, v, ξ₃]
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
        let factored = g.factor_sums(&[lin.transform[2], lin.lf3h, lin.beta, w, alpha, u]);
        let &[xi3_expr, lf3h_expr, beta_expr, w, alpha, u] = factored.as_slice() else {
            unreachable!("factor_sums maps each root")
        };
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
        })
    }
}

/// Shortest round-trip f64 text with sign, as an unsuffixed literal.
fn f64_text(v: f64) -> String {
    let v = if v == 0.0 { 0.0 } else { v };
    format!("{v:?}")
}

/// `macro_rules! params` with one `pub const NAME: $f = value;` line per
/// parameter (the value in shortest round-trip f64 form: in an `f32`
/// module the literal rounds to the nearest `f32`).
fn params_macro(input: &ControllerInput) -> Result<String, ControllerError> {
    let mut body = String::new();
    for &Param { name, value, .. } in &input.params {
        let cname = const_name(name)?;
        if DESIGN_CONSTS.contains(&cname.as_str()) {
            return Err(ControllerError::NameTaken(cname));
        }
        if !value.is_finite() {
            return Err(EmitError::NonFinite {
                name: name.to_owned(),
                value: format!("{value:?}"),
                float: "f64",
            }
            .into());
        }
        if cname != name {
            body.push_str(&format!("        /// `{name}`\n"));
        }
        body.push_str(&format!(
            "        pub const {cname}: $f = {};\n",
            f64_text(value)
        ));
    }
    Ok(format!(
        "/// The model parameters of `{name}` (SI units), one per line, declared in\n\
         /// each float module as `params!(f64)` / `params!(f32)`.\n\
         macro_rules! params {{\n    ($f:ty) => {{\n{body}    }};\n}}\n",
        name = input.name
    ))
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

fn variant(op: Operation) -> (proc_macro2::Ident, &'static str, &'static str) {
    match op {
        Operation::Closing => (
            format_ident!("Closing"),
            "REFERENCE_CLOSING",
            "Closing: z_max → z_min.",
        ),
        Operation::Opening => (
            format_ident!("Opening"),
            "REFERENCE_OPENING",
            "Opening: z_min → z_max.",
        ),
    }
}

/// One `pub mod f64 { … }` / `pub mod f32 { … }`, formatted.
fn float_module(
    graph: &Graph,
    input: &ControllerInput,
    design: &Design,
    law: &LawSymbols,
    float: Float,
) -> Result<String, ControllerError> {
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let saturate = match float {
        Float::F64 => format_ident!("saturate"),
        Float::F32 => format_ident!("saturate_f32"),
    };

    // the law (50), through the expression emitter
    let [z, v, phi] = input.states;
    let mut params: Vec<Param> = input.params.clone();
    for (k, (&id, name)) in law.gains.iter().zip(GAIN_SYMBOLS).enumerate() {
        params.push(Param::from((name, id, input.gains[k])));
    }
    let spec = FunctionSpec {
        name: "law_terms",
        doc: "The terms of the tracking law (50) at the state x = [z, v, φ] and the\n\
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
        outputs: vec![
            ("xi3", law.xi3, "(41) ξ₃ = a(x) = L_f²h"),
            ("lf3h", law.lf3h, "(31) L_f³h"),
            ("beta", law.beta, "(32) β(x) = 1 / L_g L_f²h"),
            (
                "w",
                law.w,
                "(48) w = K·(ξ_r − T(x)) + z_r⁽³⁾, T(x) = [z, v, ξ₃] (41)",
            ),
            (
                "alpha",
                law.alpha,
                "(32) α(x) = −L_f³h / L_g L_f²h = −L_f³h·β",
            ),
            ("u", law.u, "(50) u = α + β·w = β·(w − L_f³h)"),
        ],
        named: vec![],
        output_symbols: STAGED_OUTPUTS.into_iter().zip(law.staged).collect(),
        float,
    };
    // inlined into both `law` and `guarded_law` (one call, no stored outputs)
    let law_fn = function_tokens_inline(graph, &spec, &params, Inline::Always)?;

    // design constants
    let [k1, k2, k3] = input.gains;
    let consts = [
        ("GAIN_K1", k1, "k1 of K = [k1, k2, k3] (48): s³ + k3·s² + k2·s + k1 is the characteristic polynomial of (49)."),
        ("GAIN_K2", k2, "k2 of K (48)."),
        ("GAIN_K3", k3, "k3 of K (48)."),
        ("U_MIN", input.u_min, "Lower supply limit u_min."),
        ("U_MAX", input.u_max, "Upper supply limit u_max."),
        ("T_TAKEOFF", input.takeoff, "t₀ [s] from the operation's start: end of the pre-movement stage (51)."),
        ("T_LANDING", input.landing, "t_f [s] from the operation's start: end of the motion (51)."),
        ("SAMPLE_PERIOD", input.sample_period, "T_s [s]: call `Controller::step` once per sample period."),
        ("PHI_GUARD", design.phi_guard, "Guard at φ → 0 [Wb]: where φ ≤ PHI_GUARD the law is not evaluated and u = u_max\n(drives the flux into D₀⁺). 10⁻³ of the smallest flux the reference needs, rounded down."),
        ("LANDED_BAND", design.landed_band, "Distance [m] to the end stop within which the armature counts as in contact\n(expert rules after t_f): 10⁻⁹ of the stroke, rounded down."),
        ("PRESS", PRESS_FRACTION, "After t_f the reference lies PRESS·stroke beyond the end stop: the loop closes\nthe last gap gently and the contact is certain."),
        ("CREEP", creep(input), "After t_f the reference creeps on beyond the stop at CREEP·stroke per second [1/s]:\nwhere the plant differs from the model and a pure hold would hover short of the\nstop, the armature still lands, at about that speed."),
        ("CREEP_MAX", CREEP_MAX_FRACTION, "The creep stops CREEP_MAX·stroke beyond the end stop."),
    ];
    let mut items = TokenStream::new();
    for (name, value, doc) in consts {
        let id = format_ident!("{name}");
        let value = lit(float, name, value)?;
        let docs = doc_attrs(doc);
        items.extend(quote!(#docs pub const #id: #ty = #value;));
    }

    // reference tables and the operation enum
    let mut variants = TokenStream::new();
    let mut plan_arms = TokenStream::new();
    let mut hold_arms = TokenStream::new();
    for op in &input.operations {
        let (var, table_name, var_doc) = variant(op.operation);
        let table = format_ident!("{table_name}");
        let n = Literal::usize_unsuffixed(op.segments.segments.len());
        let mut rows = Vec::new();
        for row in &op.segments.segments {
            let cells = row
                .iter()
                .map(|&x| lit(float, table_name, x))
                .collect::<Result<Vec<_>, _>>()?;
            rows.push(quote!([#(#cells),*]));
        }
        let table_doc = doc_attrs(&format!(
            "Reference of the {} motion z_m on [t₀, t_f] (51): one row\n[t_k, z_k, v_k, c0, c1, c2, c3] per segment, t_k from the operation's start;\na(τ) = c0 + c1·τ + c2·τ² + c3·τ³ with τ = t − t_k, v and z its integrals.",
            var.to_string().to_lowercase()
        ));
        items.extend(quote!(
            #table_doc
            pub const #table: [[#ty; 7]; #n] = [#(#rows),*];
        ));
        let var_doc = format!(" {var_doc}");
        variants.extend(quote!(#[doc = #var_doc] #var,));
        let z0 = lit(float, "z0", op.z0)?;
        let zf = lit(float, "zf", op.zf)?;
        plan_arms.extend(quote!(Operation::#var => (&#table, #z0, #zf),));
        hold_arms.extend(match op.operation {
            // model-free-sliding-mode (43), first case: z = z_f = z_min
            Operation::Closing => quote!(
                Operation::#var => {
                    if z <= zf + LANDED_BAND {
                        let u = if phi < 0.0 {
                            -U_MAX
                        } else if phi >= 0.0 {
                            U_MAX
                        } else {
                            0.0
                        };
                        return Some(#saturate(u, U_MIN, U_MAX));
                    }
                }
            ),
            // (43), second case: z = z_f = z_max
            Operation::Opening => quote!(
                Operation::#var => {
                    if z >= zf - LANDED_BAND {
                        return Some(#saturate(0.0, U_MIN, U_MAX));
                    }
                }
            ),
        });
    }

    // `phi` is only read by the closing hold rule
    let hold_phi = if input
        .operations
        .iter()
        .any(|o| o.operation == Operation::Closing)
    {
        format_ident!("phi")
    } else {
        format_ident!("_phi")
    };
    let law_args = quote!(z: #ty, v: #ty, phi: #ty, zr: #ty, vr: #ty, ar: #ty, jr: #ty);
    let tokens = quote! {
        #[doc = " The controller in this float type."]
        pub mod #module {
            use reldesign_runtime::#saturate;

            params!(#ty);

            #items

            #law_fn

            /// u of the tracking law (50), not saturated and not guarded.
            #[must_use]
            pub fn law(#law_args) -> #ty {
                law_terms(z, v, phi, zr, vr, ar, jr).u
            }

            /// The law (50) as applied: if φ ≤ `PHI_GUARD` (φ → 0, where β = 1/L_g L_f²h
            /// blows up and D₀⁺ is left) it is not evaluated and u = u_max drives the
            /// flux back into D₀⁺; otherwise u of (50). Saturated to [u_min, u_max]
            /// (a NaN maps to the bound nearest 0, ±∞ to the bounds).
            #[must_use]
            pub fn guarded_law(#law_args) -> #ty {
                if phi <= PHI_GUARD {
                    return #saturate(U_MAX, U_MIN, U_MAX);
                }
                #saturate(law_terms(z, v, phi, zr, vr, ar, jr).u, U_MIN, U_MAX)
            }

            /// [z_r, v_r, a_r, j_r] of one table row at τ = t − t_k.
            fn eval_segment(row: &[#ty; 7], tau: #ty) -> [#ty; 4] {
                let [_, z, v, c0, c1, c2, c3] = *row;
                [
                    z + tau * (v + tau * (c0 / 2.0 + tau * (c1 / 6.0 + tau * (c2 / 12.0 + tau * c3 / 20.0)))),
                    v + tau * (c0 + tau * (c1 / 2.0 + tau * (c2 / 3.0 + tau * c3 / 4.0))),
                    c0 + tau * (c1 + tau * (c2 + tau * c3)),
                    c1 + tau * (2.0 * c2 + tau * 3.0 * c3),
                ]
            }

            /// A designed switching operation.
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub enum Operation {
                #variants
            }

            impl Operation {
                /// (reference table, z₀, z_f) of (51).
                fn plan(self) -> (&'static [[#ty; 7]], #ty, #ty) {
                    match self {
                        #plan_arms
                    }
                }
            }

            /// One operation of the actuator: pre-movement stage before t₀ (ξ_r = [z₀, 0, 0],
            /// which brings ξ₃ to 0 so the forces balance at takeoff), tracking of the
            /// table on [t₀, t_f], hold at z_f after t_f with the expert rules of
            /// model-free-sliding-mode (43) at the end stop. Allocation- and panic-free.
            #[derive(Clone, Debug, PartialEq)]
            pub struct Controller {
                operation: Operation,
                /// Time at which the operation started [s].
                start: #ty,
                /// Current segment of the table (only moves forward).
                cursor: usize,
            }

            impl Controller {
                /// A controller for `operation`, started at t = 0.
                #[must_use]
                pub const fn new(operation: Operation) -> Self {
                    Controller { operation, start: 0.0, cursor: 0 }
                }

                /// Starts the operation at `t_start` [s]: reference times count from here.
                pub fn start(&mut self, t_start: #ty) {
                    self.start = t_start;
                    self.cursor = 0;
                }

                /// The operation this controller runs.
                #[must_use]
                pub const fn operation(&self) -> Operation {
                    self.operation
                }

                /// [z_r, v_r, a_r, j_r] at `t` (51): z₀ at rest before t₀, the table on
                /// [t₀, t_f], after t_f just beyond z_f and creeping on (PRESS, CREEP).
                /// Advances the segment cursor.
                pub fn reference(&mut self, t: #ty) -> [#ty; 4] {
                    let time = t - self.start;
                    let (table, z0, zf) = self.operation.plan();
                    if (T_TAKEOFF..=T_LANDING).contains(&time) {
                        while let Some(&[t_next, ..]) = table.get(self.cursor.saturating_add(1)) {
                            if t_next <= time {
                                self.cursor = self.cursor.saturating_add(1);
                            } else {
                                break;
                            }
                        }
                        match table.get(self.cursor) {
                            Some(row) => {
                                let [t_k, ..] = *row;
                                eval_segment(row, time - t_k)
                            }
                            None => [z0, 0.0, 0.0, 0.0],
                        }
                    } else if time > T_LANDING {
                        let creep = CREEP * (time - T_LANDING);
                        if creep < CREEP_MAX {
                            [zf + (zf - z0) * (PRESS + creep), (zf - z0) * CREEP, 0.0, 0.0]
                        } else {
                            [zf + (zf - z0) * (PRESS + CREEP_MAX), 0.0, 0.0, 0.0]
                        }
                    } else {
                        // before t₀ (and a NaN time): pre-movement stage
                        [z0, 0.0, 0.0, 0.0]
                    }
                }

                /// After t_f at the end stop: the expert rule of model-free-sliding-mode (43),
                /// closing → u = u_max·sgn φ (sgn 0 = +1, NaN φ → 0), opening → u = 0.
                fn hold(&self, time: #ty, z: #ty, #hold_phi: #ty) -> Option<#ty> {
                    if time > T_LANDING {
                        let (_, _, zf) = self.operation.plan();
                        match self.operation {
                            #hold_arms
                        }
                    }
                    None
                }

                /// The input u in [u_min, u_max] at time `t` [s] for the measured state
                /// x = [z, v, φ]: the rules of the hold, else [`guarded_law`] at the
                /// reference of [`Controller::reference`]. Finite for any input.
                pub fn step(&mut self, t: #ty, z: #ty, v: #ty, phi: #ty) -> #ty {
                    if let Some(u) = self.hold(t - self.start, z, phi) {
                        return u;
                    }
                    let [zr, vr, ar, jr] = self.reference(t);
                    guarded_law(z, v, phi, zr, vr, ar, jr)
                }
            }

            impl reldesign_runtime::Controller<#ty> for Controller {
                fn step(&mut self, t: #ty, y: &reldesign_runtime::Measurement<#ty>) -> #ty {
                    Controller::step(self, t, y.z, y.v, y.phi)
                }
            }
        }
    };
    let text = space_items(&format_items(tokens)?);
    let comments: Vec<(&str, &str)> = spec.outputs.iter().map(|&(n, _, d)| (n, d)).collect();
    Ok(comment_lets(&text, spec.name, &comments))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_significant_digit_rounds_down() {
        assert_eq!(round_down_1sig(3.7e-9), 3e-9);
        assert_eq!(round_down_1sig(1e-6), 1e-6);
        assert_eq!(round_down_1sig(9.99e-4), 9e-4);
    }
}
