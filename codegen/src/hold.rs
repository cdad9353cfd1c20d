//! The position hold of the model-based sliding mode as emitted Rust
//! (jiles-atherton-actuator-model [JA §6.2]): a rendering of
//! `designer::design::HoldDesign`.
//!
//! The law [JA 89] is the tracking law [PT 50] with K = [K·p², p² + 2pK,
//! 2p + K], so it is emitted as the feedback-linearizing law is: the file's
//! `law!` macro (`law_terms`, `law`; with H_c an input on a Jiles–Atherton
//! core). Per float type a module holds `params!`, `law!`, p, K, the gains,
//! the position, the limits, `Design` with the runtime's `hold::Hold`, and
//! `Controller = hold::PositionHold<Design, f…>`; the mode rules [JA 94], the
//! guard at φ → 0 and the saturation to [0, u_max] are
//! `reldesign_runtime::hold`, written once. No `unwrap`, indexing, `panic`,
//! `as` or allocation.

use designer::design::HoldDesign;
use designer::model::Model;
use quote::{format_ident, quote};

use crate::controller::{compensation_doc, law_macro_text, runtime_state_pattern, LawSource};
use crate::error::ControllerError;
use crate::float::Float;
use crate::format::{format_items, space_items};
use crate::operations::{documented_consts, unique_floats};

/// Everything [`emit_hold`] needs.
#[derive(Clone)]
pub struct HoldInput<'a> {
    pub model: &'a Model,
    pub design: &'a HoldDesign,
    /// Emitted float types, in this order (duplicates ignored).
    pub floats: Vec<Float>,
}

/// The hold's own constants (no model parameter may take their names).
const HOLD_CONSTS: &[&str] = &[
    "SURFACE_P",
    "REACHING_K",
    "GAIN_K1",
    "GAIN_K2",
    "GAIN_K3",
    "POSITION",
    "U_MAX",
    "SAMPLE_PERIOD",
    "PHI_GUARD",
    "LANDED_BAND",
];

/// The `law!` macro and the hold's float modules, formatted and
/// deterministic; each module invokes the file's `params!` macro too.
pub fn emit_hold(input: &HoldInput) -> Result<String, ControllerError> {
    let floats = unique_floats(input.model, &input.floats, &[HOLD_CONSTS])?;
    let source = LawSource {
        model: input.model,
        linearization: &input.design.linearization,
        gains: input.design.gains(),
        guarded: false,
        theta: &[],
    };
    let mut out = law_macro_text(&source, floats.contains(&Float::F32))?;
    for float in floats {
        out.push('\n');
        out.push_str(&float_module(input, float)?);
    }
    Ok(out)
}

/// One `pub mod f64 { … }` / `pub mod f32 { … }`, formatted.
fn float_module(input: &HoldInput, float: Float) -> Result<String, ControllerError> {
    let d = input.design;
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let [k1, k2, k3] = d.gains();
    let consts = documented_consts(
        float,
        &[
            ("SURFACE_P", d.p, "p [1/s] of the sliding surface s = (p + d/dt)²(z − z_ref) [JA 88]."),
            ("REACHING_K", d.k, "K [1/s] of the reaching law ṡ = −K·s [JA 93]."),
            ("GAIN_K1", k1, "k1 = K·p² of K = [k1, k2, k3] [PT 48]: [JA 89] is [PT 50] with these gains (the error\ndynamics (d/dt + p)²(d/dt + K))."),
            ("GAIN_K2", k2, "k2 = p² + 2p·K [PT 48]."),
            ("GAIN_K3", k3, "k3 = 2p + K [PT 48]."),
            ("POSITION", d.position, "z_ref [m]: the position held [JA §6.3]."),
            ("U_MAX", d.u_max, "Supply limit: every output lies in [0, U_MAX] [JA 94]."),
            ("SAMPLE_PERIOD", d.sample_period, "T_s [s]: call `Controller::step` once per sample period, with the observer's\nestimate."),
            ("PHI_GUARD", d.phi_guard, "Guard at φ → 0 [Wb]: where φ̂ ≤ PHI_GUARD the law is not evaluated and u = U_MAX\n(builds the flux). 10⁻³ of the holding flux, rounded down."),
            ("LANDED_BAND", d.landed_band, "Distance [m] to a stop within which the armature is at it (the modes [JA 86])."),
        ],
    )?;
    let (pattern, args) = runtime_state_pattern(input.model);
    let step_doc = if input.model.states.len() == 4 {
        "The armature held at `POSITION` (`reldesign_runtime::hold::PositionHold`): the mode\nrules [JA 94] at the stops, else u₂ of [JA 89], saturated to [0, U_MAX]; `new`,\n`step(z, v, phi, hc)` with the observer's ẑ, v̂, φ̂, Ĥ_c. Allocation- and panic-free."
    } else {
        "The armature held at `POSITION` (`reldesign_runtime::hold::PositionHold`): the mode\nrules [JA 94] at the stops, else u₂ of [JA 89], saturated to [0, U_MAX]; `new`,\n`step(z, v, phi, 0.0)` (the core has no field state). Allocation- and panic-free."
    };
    let step_doc = format!(
        "{step_doc}{}",
        compensation_doc(input.model, "(0.0, U_MAX)")
    );
    let step_doc = crate::emit::doc_attrs(&step_doc);
    let tokens = quote! {
        #[doc = " The hold in this float type."]
        pub mod #module {
            use reldesign_runtime::{control, hold};

            params!(#ty);
            law!(#ty);

            #consts

            /// This module's design (the position, limits, guard; the law [JA 89] of `law!`)
            /// as the runtime's hold reads it.
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
            pub struct Design;

            impl control::ConstPlan for Design {
                const PLAN: Self = Design;
            }

            impl hold::Hold<#ty> for Design {
                #[inline(always)]
                fn settings(&self) -> hold::HoldSettings<#ty> {
                    hold::HoldSettings {
                        position: POSITION,
                        z_min: Z_MIN,
                        z_max: Z_MAX,
                        u_max: U_MAX,
                        phi_guard: PHI_GUARD,
                        landed_band: LANDED_BAND,
                    }
                }

                #[inline(always)]
                fn law(&self, #pattern: [#ty; 4], [zr, vr, ar, jr]: [#ty; 4]) -> #ty {
                    law_terms(#args, zr, vr, ar, jr).u
                }
            }

            #step_doc
            pub type Controller = hold::PositionHold<Design, #ty>;
        }
    };
    Ok(space_items(&format_items(tokens)?))
}
