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

use designer::design::{ControllerDesign, LawDesign, Linearization};
use designer::model::Model;
use designer::sym::{Graph, Id};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use crate::calibration::{theta_args, theta_symbols};
use crate::emit::{function_tokens_as, FunctionSpec, Inline, Theta};
use crate::error::ControllerError;
use crate::float::{Float, Scalar, MACRO_LITERALS};
use crate::format::{comment_lets, format_items, macro_rules, space_items};
use crate::operations::{
    checked_floats, documented_consts, plan_items, splice_tables, ControllerInput,
};
use crate::param::Param;
use crate::physical::{in_scope, of_model};

/// Names of the law's own constants (checked against the parameters' const names).
const GAIN_CONSTS: &[&str] = &["GAIN_K1", "GAIN_K2", "GAIN_K3", "SURFACE_P", "REACHING_K"];

/// Symbols of the law's reference inputs and gains (must be new to the graph).
const REF_SYMBOLS: [&str; 4] = ["z_ref", "v_ref", "a_ref", "j_ref"];
const GAIN_SYMBOLS: [&str; 3] = ["gain_k1", "gain_k2", "gain_k3"];

/// The `law!` macro (the law's functions, written once) and the
/// controller's float modules that invoke it, formatted and deterministic;
/// each module invokes the file's `params!` macro too (which must precede
/// them).
pub fn emit_controller(input: &ControllerInput) -> Result<String, ControllerError> {
    let floats = checked_floats(input, GAIN_CONSTS)?;
    let theta = match input.calibration {
        Some(c) => theta_args(&input.model.params, c)?,
        None => Vec::new(),
    };
    let source = LawSource {
        model: input.model,
        linearization: &input.design.linearization,
        gains: fl_gains(input.design)?,
        guarded: true,
        theta: &theta,
    };
    let mut out = law_macro_text(&source, floats.contains(&Float::F32))?;
    if replays(input) {
        out.push('\n');
        out.push_str(&crate::replay::predictor_macro_text(
            input.model,
            &theta,
            floats.contains(&Float::F32),
        )?);
    }
    for float in floats {
        out.push('\n');
        out.push_str(&float_module(input, float, theta.len())?);
    }
    Ok(out)
}

/// Whether the file carries the replay update in the controller's modules
/// (a self-calibrating design whose law reads measured states).
fn replays(input: &ControllerInput) -> bool {
    input
        .calibration
        .is_some_and(|c| c.method == designer::calibrate::Method::Replay)
}

/// What the law [PT 50] is emitted from: the model, its linearization and
/// the gains K, and whether `guarded_law` (over the module's `control::Law`)
/// is emitted too.
pub struct LawSource<'a> {
    pub model: &'a Model,
    pub linearization: &'a Linearization,
    pub gains: [f64; 3],
    pub guarded: bool,
    /// θ of a self-calibrating design (`calibration.rs`): the law reads
    /// them from its `theta` argument; empty otherwise.
    pub theta: &'a Theta,
}

/// The `law!` macro of `source`, its literals typed for `f32` too if asked.
pub fn law_macro_text(source: &LawSource, f32: bool) -> Result<String, ControllerError> {
    let mut graph = source.model.graph.clone();
    let law = LawSymbols::build(&mut graph, source.linearization, &source.model.named)?;
    // MU0, Z_EPS as the file's params! declares them
    let physical = in_scope(&mut graph, &of_model(source.model));
    law_macro(&graph, source, &law, &physical, Scalar::Macro { f32 })
}

/// The law's state arguments: z, v, φ, and H_c on a Jiles–Atherton core.
pub(crate) fn state_args(model: &Model) -> Vec<(&'static str, Id)> {
    let names = ["z", "v", "phi", "hc"];
    names
        .into_iter()
        .zip(model.states.iter().copied())
        .collect()
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
        lin: &Linearization,
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
    source: &LawSource,
    law: &LawSymbols,
    physical: &[Param],
    scalar: Scalar,
) -> Result<(TokenStream, Comments), ControllerError> {
    let model = source.model;
    let adapted = theta_symbols(source.theta);
    let mut params: Vec<Param> = (model.params.iter())
        .filter(|p| !adapted.contains(&p.1))
        .map(Param::from)
        .collect();
    params.extend_from_slice(physical);
    for ((&id, name), &k) in law.gains.iter().zip(GAIN_SYMBOLS).zip(&source.gains) {
        params.push(Param::from((name, id, k)));
    }
    let mut inputs = state_args(model);
    inputs.extend([
        ("zr", law.refs[0]),
        ("vr", law.refs[1]),
        ("ar", law.refs[2]),
        ("jr", law.refs[3]),
    ]);
    let field = if model.states.len() == 4 {
        " with the core's\nfield H_c (which enters L_f³h through dφ/dt)"
    } else {
        ""
    };
    let see = if source.guarded {
        ", see [`guarded_law`]"
    } else {
        ""
    };
    let doc = format!(
        "The terms of the tracking law [PT 50] at the state x = [z, v, φ]{field} and the\n\
         reference ξ_r = [z_r, v_r, a_r], z_r⁽³⁾ = j_r (not saturated, not guarded:\n\
         φ = 0 makes β infinite{see})."
    );
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
        doc: &doc,
        inputs,
        outputs,
        named: law.named.clone(),
        output_symbols: STAGED_OUTPUTS.into_iter().zip(law.staged).collect(),
        // written in `scalar` (function_tokens_as)
        float: Float::F64,
    };
    let tokens = function_tokens_as(graph, &spec, &params, Inline::Always, scalar, source.theta)?;
    Ok((tokens, comments))
}

/// K of [PT 48] (of the feedback-linearizing or the model-based
/// sliding-mode law).
fn fl_gains(d: &ControllerDesign) -> Result<[f64; 3], ControllerError> {
    d.law
        .tracking_gains()
        .ok_or(ControllerError::NotFeedbackLinearization("sliding-mode"))
}

/// The gains K [PT 48], documented (with p and K of the model-based
/// sliding mode [JA 88–93], whose law [JA 89] is [PT 50] with these gains).
fn gain_consts(d: &ControllerDesign, float: Float) -> Result<TokenStream, ControllerError> {
    let [k1, k2, k3] = fl_gains(d)?;
    if let LawDesign::ModelSlidingMode { p, k } = d.law {
        return documented_consts(
            float,
            &[
                ("SURFACE_P", p, "p [1/s] of the sliding surface s = (p + d/dt)²(z − z_r) [JA 88]."),
                ("REACHING_K", k, "K [1/s] of the reaching law ṡ = −K·s [JA 93]."),
                ("GAIN_K1", k1, "k1 = K·p² of K = [k1, k2, k3] [PT 48]: [JA 89] is [PT 50] with these gains (the error dynamics (d/dt + p)²(d/dt + K))."),
                ("GAIN_K2", k2, "k2 = p² + 2p·K [PT 48]."),
                ("GAIN_K3", k3, "k3 = 2p + K [PT 48]."),
            ],
        );
    }
    documented_consts(
        float,
        &[
            ("GAIN_K1", k1, "k1 of K = [k1, k2, k3] [PT 48]: s³ + k3·s² + k2·s + k1 is the characteristic polynomial of [PT 49]."),
            ("GAIN_K2", k2, "k2 of K [PT 48]."),
            ("GAIN_K3", k3, "k3 of K [PT 48]."),
        ],
    )
}

/// `macro_rules! law`: `law_terms` (the expression emitter's), `law` and
/// `guarded_law`, written once over the float type `$f`.
fn law_macro(
    graph: &Graph,
    source: &LawSource,
    law: &LawSymbols,
    physical: &[Param],
    scalar: Scalar,
) -> Result<String, ControllerError> {
    let ty = scalar.ty();
    let (law_fn, comments) = law_terms(graph, source, law, physical, scalar)?;
    let state: Vec<_> = state_args(source.model)
        .into_iter()
        .map(|(name, _)| format_ident!("{name}"))
        .collect();
    let p = source.theta.len();
    let (theta_arg, theta_call, design) = if p > 0 {
        let p = proc_macro2::Literal::usize_unsuffixed(p);
        (
            quote!(, theta: &[#ty; #p]),
            quote!(, theta),
            quote!(Design { theta: *theta }),
        )
    } else {
        (quote!(), quote!(), quote!(Design))
    };
    let law_args = quote!(#(#state: #ty,)* zr: #ty, vr: #ty, ar: #ty, jr: #ty #theta_arg);
    let call = quote!(#(#state,)* zr, vr, ar, jr #theta_call);
    // with H_c (a Jiles–Atherton core) or θ, `law` and `guarded_law` take 8
    // arguments: clippy's limit is 7 (as `law_terms`, emit.rs)
    let arity = state.len() + 4 + usize::from(p > 0);
    let allow = (arity > 7).then(|| quote!(#[allow(clippy::too_many_arguments)]));
    // the runtime's state [z, v, φ, H_c]: H_c = 0 where the core has none
    let runtime_state = if state.len() == 4 {
        quote!([#(#state),*])
    } else {
        quote!([#(#state,)* 0.0])
    };
    let guarded = source.guarded.then(|| {
        quote! {
            /// The law [PT 50] as applied (`reldesign_runtime::control::guarded_law`): if
            /// φ ≤ `PHI_GUARD` (φ → 0, where β = 1/L_g L_f²h blows up and D₀⁺ is left) it
            /// is not evaluated and u = u_max drives the flux back into D₀⁺; otherwise u
            /// of [PT 50]. Saturated to [u_min, u_max] (a NaN maps to the bound nearest 0,
            /// ±∞ to the bounds).
            #[must_use]
            #allow
            pub fn guarded_law(#law_args) -> #ty {
                control::guarded_law(&#design, #runtime_state, [zr, vr, ar, jr])
            }
        }
    });
    let tokens = quote! {
        #law_fn

        /// u of the tracking law [PT 50], not saturated and not guarded.
        #[must_use]
        #allow
        pub fn law(#law_args) -> #ty {
            law_terms(#call).u
        }

        #guarded
    };
    let text = comment_lets(&space_items(&format_items(tokens)?), "law_terms", &comments);
    let functions = if source.guarded {
        "`law_terms`, `law` and `guarded_law`"
    } else {
        "`law_terms` and `law`"
    };
    let doc = format!(
        "The tracking law [PT 50] of `{}` over the float type `$f`, written once:\n\
         {functions}, declared in each float module as `law!(f64)` /\n\
         `law!(f32)` beside the module's `params!`, gains and `Design`.\n{MACRO_LITERALS}",
        source.model.description.name
    );
    Ok(macro_rules("law", &doc, &text))
}

/// The pattern of the runtime's state [z, v, φ, H_c] in `Law::law`/`Hold::law`
/// (H_c `_` where the core has none) and the `law_terms` call's state args.
pub fn runtime_state_pattern(model: &Model) -> (TokenStream, TokenStream) {
    let state: Vec<_> = state_args(model)
        .into_iter()
        .map(|(name, _)| format_ident!("{name}"))
        .collect();
    let pattern = if state.len() == 4 {
        quote!([#(#state),*])
    } else {
        quote!([#(#state,)* _])
    };
    (pattern, quote!(#(#state),*))
}

/// The sentence a controller's docs add where the description sets
/// `controller.compensate_resistance`: firmware applies the correction
/// within the controller's `limits` (the consts' names, e.g. `(U_MIN, U_MAX)`).
pub fn compensation_doc(model: &Model, limits: &str) -> String {
    let on = (model.description.controller.as_ref()).is_some_and(|c| c.compensate_resistance);
    if on {
        format!(
            "\nThe design compensates the coil resistance (`compensate_resistance`): pass the\n\
             step's u through `reldesign_runtime::resistance::compensate_resistance(u, r̂, R,\n\
             i, {limits})` with the observer's R̂ and the measured current i."
        )
    } else {
        String::new()
    }
}

/// One `pub mod f64 { … }` / `pub mod f32 { … }`, formatted.
fn float_module(
    input: &ControllerInput,
    float: Float,
    adapted: usize,
) -> Result<String, ControllerError> {
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let design = input.design;
    let gains = gain_consts(design, float)?;
    let (pattern, args) = runtime_state_pattern(input.model);
    let step = if input.model.states.len() == 4 {
        "`step_with_field(t, z, v, phi, hc)` with the observer's H_c (the law reads it;\n`step` would pass H_c = 0)"
    } else {
        "`step(t, z, v, phi)`"
    };
    let controller_doc = crate::emit::doc_attrs(&format!(
        "One operation of the actuator (`reldesign_runtime::control::SoftLanding`):\n\
         pre-movement stage before t₀ (ξ_r = [z₀, 0, 0], which brings ξ₃ to 0 so the\n\
         forces balance at takeoff), tracking of the table on [t₀, t_f], hold at z_f\n\
         after t_f with the expert rules of model-free-sliding-mode [SM 43] at the end\n\
         stop; `new`, `start`, `reference`, {step}. Allocation- and panic-free.{}",
        compensation_doc(input.model, "(U_MIN, U_MAX)")
    ));
    let plan = plan_items(
        input.model,
        design,
        float,
        "This module's design (limits, timing, guards, tables; the law [PT 50] of\n`law!`) as the runtime's soft-landing logic reads it.",
        adapted,
    )?;
    let (calibration, theta) = if adapted > 0 {
        let predictor = replays(input).then(|| quote!(predictor!(#ty);));
        (quote!(calibration!(#ty); #predictor), quote!(, &self.theta))
    } else {
        (quote!(), quote!())
    };
    let tokens = quote! {
        #[doc = " The controller in this float type."]
        pub mod #module {
            use reldesign_runtime::control;

            params!(#ty);
            #calibration
            law!(#ty);

            #gains

            #plan

            impl control::Law<#ty> for Design {
                #[inline(always)]
                fn law(&self, #pattern: [#ty; 4], [zr, vr, ar, jr]: [#ty; 4]) -> #ty {
                    law_terms(#args, zr, vr, ar, jr #theta).u
                }
            }

            #controller_doc
            pub type Controller = control::SoftLanding<Design, #ty>;
        }
    };
    splice_tables(&space_items(&format_items(tokens)?), design, float)
}
