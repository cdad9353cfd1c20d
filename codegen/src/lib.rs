//! Code generation: turns designed laws (symbolic expressions from the
//! designer) into formatted, deterministic, `no_std`, panic-free Rust.
//!
//! The foundation is the expression emitter: [`emit_params`] writes the
//! parameters as named consts (one per line, values in shortest round-trip
//! form) and [`params_macro`] the file's one `params!` macro of them,
//! [`emit_function`] writes a set of named outputs as one plain `fn` over
//! `f32` or `f64` scalars returning a struct. Parameters stay symbolic
//! (changing one value changes one line), physical constants and the
//! model's named subexpressions keep their names, shared subexpressions
//! become `let`s in the deterministic CSE order, math goes through
//! `reldesign_runtime::math::Real` (libm, no `std`), and nothing emitted
//! allocates, indexes, unwraps or casts. The design is `designer`'s
//! (`designer::design::Design`); this crate only renders it.
//!
//! | module | concept |
//! | --- | --- |
//! | `emit.rs` | the public emitters: [`FunctionSpec`], [`emit_params`], [`params_macro`], [`emit_function`] |
//! | `param.rs` | [`Param`]: one parameter (name, symbol, value) |
//! | `physical.rs` | μ0 and Z_EPS by name instead of folded into coefficients |
//! | `plan.rs` | which nodes become `let`s, in which order, under which names |
//! | `lower.rs` | one expression → Rust tokens (subtractions, divisions, powers, `if`) |
//! | `names.rs` | name validation, parameter const names, readable temporaries |
//! | `fold.rs` | parameter-only subexpressions that need a math call, evaluated when generated |
//! | `float.rs` | [`Float`], shortest round-trip literals, and the `$f` of macros written once for every float type |
//! | `format.rs` | `prettyplease` formatting, `//` comments and `macro_rules!` bodies |
//! | `error.rs` | [`EmitError`], [`ControllerError`] |
//! | `build.rs` | a description → the emitted file ([`build_file`], [`compile`], [`emit`]) |
//! | `operations.rs` | what every controller module states: its input, the plan's consts, tables, `Operation`, `Design` with `control::Plan` |
//! | `controller.rs` | the tracking-law controller (feedback linearization, and the model-based sliding mode [JA 89] which is it with other gains): the `law!` macro and the float modules (over `reldesign_runtime::control`) |
//! | `backstepping.rs` | the backstepping position controller [SB 19]: the `law!` macro of its stages and the float modules (over `reldesign_runtime::backstepping`) |
//! | `hold.rs` | the position hold of the model-based sliding mode: the float modules (over `reldesign_runtime::hold`) |
//! | `sliding.rs` | the model-free sliding-mode controller: λ₁, λ₂ and the float modules (over `reldesign_runtime::sliding`) |
//! | `semera.rs` | the SEMERA and integral estimator modules |
//! | `observer/` | the EKF and UKF: `model!` macros and float modules |
//! | `calibration.rs` | the self-calibration: the `calibration!` macro and θ as the law's and the filter model's argument |

mod backstepping;
mod build;
mod calibration;
mod controller;
mod emit;
mod error;
mod float;
mod fold;
mod format;
mod header;
mod hold;
mod lower;
mod names;
mod observer;
mod operations;
mod param;
mod physical;
mod plan;
mod replay;
mod semera;
mod sliding;

pub use backstepping::{emit_backstepping, BacksteppingInput};
pub use build::{build_file, compile, emit, write_if_changed, BuildError};
pub use controller::emit_controller;
pub use emit::{
    emit_function, emit_params, function_tokens, params_macro, params_tokens, FunctionSpec,
};
pub use error::ControllerError;
pub use error::EmitError;
pub use float::Float;
pub use format::format_items;
pub use header::{sha256_hex, Header};
pub use hold::{emit_hold, HoldInput};
pub use names::const_name;
pub use observer::*;
pub use operations::ControllerInput;
pub use param::Param;
pub use semera::*;
pub use sliding::emit_sliding_mode;
