//! Controller design: derivations on top of the model.
//!
//! - `lie.rs`: input-affine systems, Lie derivatives, relative degree (generic);
//! - `linearization.rs`: exact feedback linearization for y = z: α, β, T, T⁻¹,
//!   the jerk terms.

mod lie;
mod linearization;

pub use lie::{lie, vanishing_factors, AffineSystem, OutputDerivatives};
pub use linearization::{DesignError, Linearization};
