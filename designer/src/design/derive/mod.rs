//! The derivations on the model that every law and trajectory builds on:
//! Lie derivatives and relative degree (`lie.rs`, generic), and the chain of
//! feedback linearization for y = z (`linearization.rs`: α, β, T, T⁻¹, the
//! jerk terms).

pub(super) mod lie;
pub(super) mod linearization;
