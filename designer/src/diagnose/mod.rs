//! Model-discrepancy diagnosis (`reldesign diagnose`): replay, localise the
//! residual, fit each extension of the vocabulary, rank, extend the model.

pub mod cause;
pub mod localise;

pub use cause::Cause;
