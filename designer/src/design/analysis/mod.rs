//! Analyses of a finished design, beside the pipeline: the sliding-mode
//! law's supply along a reference [SM 48–52] (`robustness.rs`, which the
//! pipeline also checks), and that bound over a whole design, nominal and
//! Monte Carlo over parameter bounds (`monte_carlo.rs`; its draws run in
//! parallel with the `parallel` feature).

pub(super) mod monte_carlo;
pub(super) mod robustness;
