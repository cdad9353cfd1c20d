//! The backstepping position controller as emitted Rust
//! (switched-force-backstepping [SB]): a rendering of
//! `designer::design::BacksteppingDesign`.
//!
//! `macro_rules! law { ($f:ty) => { … } }` holds the model's part, written
//! once over the float type: `law_terms` (the law's stages z₁, z₂, F, F_d,
//! Ḟ_d, f_F, g_F, u [SB 9], [SB Theorem 1], [SB 19] through the
//! expression emitter), `law` and `force_terms`/`desired_force` (F_d alone,
//! for the switching). Per float type a module holds `params!`, `law!`, the
//! gains α₁, α₂, α₃, the decay α, P and the level C of each target
//! [SB Theorem 3], the reference, the limits and guard, `Design` with the
//! runtime's `backstepping::Backstepping`, and
//! `Controller = backstepping::SwitchedBackstepping<Design, f…>`, whose
//! switching state is the token M [SB 31–33]. The switching rules, the
//! guard at φ → 0 and the saturation are `reldesign_runtime::backstepping`,
//! written once. No `unwrap`, indexing, `panic`, `as` or allocation.

use designer::description::{SetPoint, Switching};
use designer::design::BacksteppingDesign;
use designer::model::Model;
use designer::sym::{Graph, Id};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use crate::controller::{runtime_state_pattern, state_args};
use crate::emit::{function_tokens_as, FunctionSpec, Inline};
use crate::error::ControllerError;
use crate::float::{Float, Scalar, MACRO_LITERALS};
use crate::format::{comment_lets, format_items, macro_rules, space_items};
use crate::operations::{documented_consts, unique_floats};
use crate::param::Param;
use crate::physical::{in_scope, of_model};

/// Everything [`emit_backstepping`] needs.
#[derive(Clone)]
pub struct BacksteppingInput<'a> {
    pub model: &'a Model,
    pub design: &'a BacksteppingDesign,
    /// Emitted float types, in this order (duplicates ignored).
    pub floats: Vec<Float>,
}

/// The module's own constants (no model parameter may take their names).
const CONSTS: &[&str] = &[
    "GAIN_A1",
    "GAIN_A2",
    "GAIN_A3",
    "DECAY",
    "REGION_P11",
    "REGION_P12",
    "REGION_P22",
    "POSITION",
    "REGION_C",
    "POSITION_LOW",
    "POSITION_HIGH",
    "REGION_C_LOW",
    "REGION_C_HIGH",
    "PERIOD",
    "U_MIN",
    "U_MAX",
    "SAMPLE_PERIOD",
    "PHI_GUARD",
];

/// The `law!` macro and the float modules, formatted and deterministic;
/// each module invokes the file's `params!` macro too.
pub fn emit_backstepping(input: &BacksteppingInput) -> Result<String, ControllerError> {
    let floats = unique_floats(input.model, &input.floats, &[CONSTS])?;
    let mut out = law_macro(input, floats.contains(&Float::F32))?;
    for float in floats {
        out.push('\n');
        out.push_str(&float_module(input, float)?);
    }
    Ok(out)
}

/// `macro_rules! law`: `law_terms`, `law`, `force_terms`, `desired_force`.
fn law_macro(input: &BacksteppingInput, f32: bool) -> Result<String, ControllerError> {
    let model = input.model;
    let law = &input.design.law;
    let mut graph: Graph = model.graph.clone();
    let physical = in_scope(&mut graph, &of_model(model));
    let mut params: Vec<Param> = model.params.iter().map(Param::from).collect();
    params.extend_from_slice(&physical);
    for (name, id, value) in input.design.bound_symbols() {
        params.push(Param::from((name, id, value)));
    }
    let scalar = Scalar::Macro { f32 };
    let mut inputs = state_args(model);
    inputs.push(("y_ref", law.target));
    let field = if model.states.len() == 4 {
        ", H_c (which enters f_F through dφ/dt)"
    } else {
        ""
    };
    let doc = format!(
        "The backstepping law [SB 19] at the state x = [z, v, φ]{field} and the reference\n\
         y_r, in its stages (not saturated, not guarded: g_F ∝ φ, so φ = 0 makes u infinite)."
    );
    let outputs: Vec<(&str, Id, &str)> = law
        .stages
        .iter()
        .map(|s| (s.name, s.expr, s.equation))
        .collect();
    let comments: Vec<(&str, &str)> = outputs.iter().map(|&(n, _, d)| (n, d)).collect();
    let staged: Vec<(&str, Id)> = law.stages.iter().map(|s| (s.name, s.symbol)).collect();
    let terms = FunctionSpec {
        name: "law_terms",
        doc: &doc,
        inputs: inputs.clone(),
        outputs,
        named: model.named.clone(),
        output_symbols: staged,
        float: Float::F64,
    };
    let terms = function_tokens_as(&graph, &terms, &params, Inline::Always, scalar, &[])?;
    // only the named subexpressions F_d reaches (the others' folded
    // parameter consts would be unused)
    let reached = graph.postorder(&[law.desired_force]);
    let force_named: Vec<(&'static str, Id)> = (model.named.iter())
        .filter(|(_, id)| reached.contains(id))
        .copied()
        .collect();
    let force_doc = "F_d [N] at (z, v) for y_r [SB Theorem 1]: the force that makes\nż₂ = −z₁ − α₂·z₂ [SB 14]; the switching reads its sign.";
    let force = FunctionSpec {
        name: "force_terms",
        doc: force_doc,
        inputs: vec![
            ("z", model.states[0]),
            ("v", model.states[1]),
            ("y_ref", law.target),
        ],
        outputs: vec![("desired_force", law.desired_force, "[SB Theorem 1] F_d")],
        named: force_named,
        output_symbols: Vec::new(),
        float: Float::F64,
    };
    let force = function_tokens_as(&graph, &force, &params, Inline::Always, scalar, &[])?;
    let ty = scalar.ty();
    let state: Vec<_> = state_args(model)
        .into_iter()
        .map(|(name, _)| format_ident!("{name}"))
        .collect();
    let tokens = quote! {
        #terms

        /// u of the backstepping law [SB 19], not saturated and not guarded.
        #[must_use]
        pub fn law(#(#state: #ty,)* y_ref: #ty) -> #ty {
            law_terms(#(#state,)* y_ref).u
        }

        #force

        /// F_d [N] [SB Theorem 1].
        #[must_use]
        pub fn desired_force(z: #ty, v: #ty, y_ref: #ty) -> #ty {
            force_terms(z, v, y_ref).desired_force
        }
    };
    let text = comment_lets(&space_items(&format_items(tokens)?), "law_terms", &comments);
    let doc = format!(
        "The backstepping law [SB 19] of `{}` over the float type `$f`, written once:\n\
         `law_terms`, `law`, `force_terms` and `desired_force`, declared in each float\n\
         module as `law!(f64)` / `law!(f32)` beside the module's `params!`, gains and\n\
         `Design`.\n{MACRO_LITERALS}",
        model.description.name
    );
    Ok(macro_rules("law", &doc, &text))
}

/// The reference's consts and the runtime's `SetPoint` over them.
fn reference_items(
    d: &BacksteppingDesign,
    float: Float,
) -> Result<(TokenStream, TokenStream), ControllerError> {
    let level = |i: usize| d.region.levels.get(i).map_or(f64::NAN, |l| l.c);
    match d.reference {
        SetPoint::Position(z) => Ok((
            documented_consts(
                float,
                &[
                    ("POSITION", z, "y_r [m]: the position held."),
                    ("REGION_C", level(0), "C of the certified region D = {ZᵀPZ ≤ C} at POSITION [SB lemma 1]: the\nlargest level set of V inside F_d ≥ 0, C = g²/(kᵀP⁻¹k)."),
                ],
            )?,
            quote!(backstepping::SetPoint::Position(backstepping::Target {
                position: POSITION,
                level: REGION_C,
            })),
        )),
        SetPoint::Square { low, high, period } => Ok((
            documented_consts(
                float,
                &[
                    ("POSITION_LOW", low, "y_r [m] for the first half of each period."),
                    ("POSITION_HIGH", high, "y_r [m] for the second half of each period."),
                    ("PERIOD", period, "The square reference's period [s]."),
                    ("REGION_C_LOW", level(0), "C of D = {ZᵀPZ ≤ C} at POSITION_LOW [SB lemma 1]: C = g²/(kᵀP⁻¹k)."),
                    ("REGION_C_HIGH", level(1), "C of D at POSITION_HIGH [SB lemma 1]."),
                ],
            )?,
            quote!(backstepping::SetPoint::Square {
                low: backstepping::Target {
                    position: POSITION_LOW,
                    level: REGION_C_LOW,
                },
                high: backstepping::Target {
                    position: POSITION_HIGH,
                    level: REGION_C_HIGH,
                },
                period: PERIOD,
            }),
        )),
    }
}

/// One `pub mod f64 { … }` / `pub mod f32 { … }`, formatted.
fn float_module(input: &BacksteppingInput, float: Float) -> Result<String, ControllerError> {
    let d = input.design;
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let [a1, a2, a3] = d.gains;
    let [p11, p12, p22] = d.region.p;
    let consts = documented_consts(
        float,
        &[
            ("GAIN_A1", a1, "α₁ [1/s]: z₂ = v + α₁·(z − y_r) [SB 9]."),
            ("GAIN_A2", a2, "α₂ [1/s]: F_d makes ż₂ = −z₁ − α₂·z₂ [SB 14]."),
            ("GAIN_A3", a3, "α₃ [1/s]: F − F_d decays at α₃ [SB 18]."),
            ("DECAY", d.region.decay, "α [1/s] of the region's LMI AᵀP + PA ⪯ −α·P [SB Theorem 3] (not read by the\nstep; the certificate P was solved for it)."),
            ("REGION_P11", p11, "P of V = ZᵀPZ [SB 21], min tr P s.t. AᵀP + PA ⪯ −α·P, P ⪰ I [SB Theorem 3]\n(with the spring's rest inside D where the paper's program leaves it out): p₁₁."),
            ("REGION_P12", p12, "p₁₂ of P."),
            ("REGION_P22", p22, "p₂₂ of P."),
            ("U_MIN", d.u_min, "Supply limits: every output lies in [U_MIN, U_MAX]."),
            ("U_MAX", d.u_max, "Upper supply limit."),
            ("SAMPLE_PERIOD", d.sample_period, "T_s [s]: call `Controller::step` once per sample period."),
            ("PHI_GUARD", d.phi_guard, "Guard at φ → 0 [Wb]: where φ ≤ PHI_GUARD the law is not evaluated (g_F ∝ φ)\nand u = U_MAX builds the flux. 10⁻³ of the smallest holding flux, rounded down."),
        ],
    )?;
    let (reference_consts, set_point) = reference_items(d, float)?;
    let switching = match d.switching {
        Switching::None => quote!(backstepping::Switching::None),
        Switching::Intuitive => quote!(backstepping::Switching::Intuitive),
        Switching::Hybrid => quote!(backstepping::Switching::Hybrid),
    };
    let (pattern, args) = runtime_state_pattern(input.model);
    let step = if input.model.states.len() == 4 {
        "`step(t, z, v, phi, hc)` with the observer's H_c"
    } else {
        "`step(t, z, v, phi, 0.0)` (the core has no field state)"
    };
    let controller_doc = crate::emit::doc_attrs(&format!(
        "The armature positioned at the reference (`reldesign_runtime::backstepping::\n\
         SwitchedBackstepping`): the law [SB 19] in the certified region D, u = 0 where the\n\
         switching strategy waits for the spring [SB 28], [SB 31–33]; the switching state\n\
         is the token M. `new`, `start`, `mode`,\n{step}. Allocation- and panic-free."
    ));
    let tokens = quote! {
        #[doc = " The controller in this float type."]
        pub mod #module {
            use reldesign_runtime::{backstepping, control};

            params!(#ty);
            law!(#ty);

            #consts

            #reference_consts

            /// This module's design (gains, P, C, reference, limits; F_d and the law of
            /// `law!`) as the runtime's backstepping reads it.
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
            pub struct Design;

            impl control::ConstPlan for Design {
                const PLAN: Self = Design;
            }

            impl backstepping::Backstepping<#ty> for Design {
                #[inline(always)]
                fn settings(&self) -> backstepping::BacksteppingSettings<#ty> {
                    backstepping::BacksteppingSettings {
                        u_min: U_MIN,
                        u_max: U_MAX,
                        phi_guard: PHI_GUARD,
                        alpha1: GAIN_A1,
                        p: [REGION_P11, REGION_P12, REGION_P22],
                        switching: #switching,
                        reference: #set_point,
                    }
                }

                #[inline(always)]
                fn desired_force(&self, z: #ty, v: #ty, y_r: #ty) -> #ty {
                    desired_force(z, v, y_r)
                }

                #[inline(always)]
                fn law(&self, #pattern: [#ty; 4], y_r: #ty) -> #ty {
                    law(#args, y_r)
                }
            }

            #controller_doc
            pub type Controller = backstepping::SwitchedBackstepping<Design, #ty>;
        }
    };
    Ok(space_items(&format_items(tokens)?))
}
