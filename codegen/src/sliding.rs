//! The model-free sliding-mode soft-landing controller as emitted Rust
//! (model-free-sliding-mode-soft-landing [SM §3]): a rendering of
//! `designer::design::ControllerDesign` with `LawDesign::SlidingMode`.
//!
//! The law evaluates no model function, so nothing of it is emitted but
//! numbers: per float type a module with the file's `params!` (the model it
//! was designed on, documented), λ₁ and λ₂ of the surface [SM 17], the
//! plan's constants and tables (`operations.rs`), `Design` with the runtime's
//! `sliding::Surface` and `Controller = sliding::SlidingMode<Design, f…>`.
//! The law itself (the surface, sgn* [SM 35], the switch [SM 34], the
//! expert rules [SM 43], saturation) is `reldesign_runtime::sliding`, written
//! once. No `unwrap`, indexing, `panic`, `as` or allocation.

use designer::design::LawDesign;
use quote::{format_ident, quote};

use crate::error::ControllerError;
use crate::float::Float;
use crate::format::{format_items, space_items};
use crate::operations::{
    checked_floats, documented_consts, plan_items, splice_tables, ControllerInput,
};

/// Names of the law's own constants.
const SURFACE_CONSTS: &[&str] = &["LAMBDA1", "LAMBDA2", "NONNEGATIVE_CURRENT"];

/// The sliding-mode controller's float modules, formatted and deterministic;
/// each invokes the file's `params!` macro (which must precede them).
pub fn emit_sliding_mode(input: &ControllerInput) -> Result<String, ControllerError> {
    let floats = checked_floats(input, SURFACE_CONSTS)?;
    let mut out = String::new();
    for (k, float) in floats.into_iter().enumerate() {
        if k > 0 {
            out.push('\n');
        }
        out.push_str(&float_module(input, float)?);
    }
    Ok(out)
}

/// One `pub mod f64 { … }` / `pub mod f32 { … }`, formatted.
fn float_module(input: &ControllerInput, float: Float) -> Result<String, ControllerError> {
    let LawDesign::SlidingMode {
        lambda1,
        lambda2,
        nonnegative_current,
    } = input.design.law
    else {
        return Err(ControllerError::NotSlidingMode);
    };
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let surface = documented_consts(
        float,
        &[
            (
                "LAMBDA1",
                lambda1,
                "λ₁ [1/s] of the sliding surface s = (λ₁ + d/dt)(λ₂ + d/dt)(z − z_r) [SM 17].",
            ),
            (
                "LAMBDA2",
                lambda2,
                "λ₂ [1/s] of the sliding surface [SM 17].",
            ),
        ],
    )?;
    let plan = plan_items(
        input.model,
        input.design,
        float,
        "This module's design (limits, timing, tables, the surface's λ₁, λ₂) as the\nruntime's sliding-mode law reads it.",
        0,
    )?;
    let current_doc = if nonnegative_current {
        " The step reads the coil current, takes sgn φ = +1 and never drives the current\n below 0 ([SM §5])."
    } else {
        " The step reads φ (measured or estimated); only its sign enters the law [SM 34]."
    };
    let tokens = quote! {
        #[doc = " The controller in this float type."]
        pub mod #module {
            use reldesign_runtime::{control, sliding};

            params!(#ty);

            #surface

            #[doc = #current_doc]
            pub const NONNEGATIVE_CURRENT: bool = #nonnegative_current;

            #plan

            impl sliding::Surface<#ty> for Design {
                #[inline(always)]
                fn surface(&self) -> sliding::SurfaceSettings<#ty> {
                    sliding::SurfaceSettings {
                        lambda1: LAMBDA1,
                        lambda2: LAMBDA2,
                        nonnegative_current: NONNEGATIVE_CURRENT,
                    }
                }
            }

            /// One operation of the actuator under the model-free sliding-mode law
            /// (`reldesign_runtime::sliding::SlidingMode`): the expert rules [SM 43] at the
            /// end stop, else u = u_max·sgn(φ)·sgn*(s) [SM 34–35] on the surface [SM 17]
            /// against the table's reference; `new`, `start`, `reference`,
            /// `step(t, z, v, a, phi)`. Allocation- and panic-free.
            pub type Controller = sliding::SlidingMode<Design, #ty>;
        }
    };
    splice_tables(&space_items(&format_items(tokens)?), input.design, float)
}
