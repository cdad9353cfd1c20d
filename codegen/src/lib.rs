//! Code generation: turns designed laws (symbolic expressions from the
//! designer) into formatted, deterministic, `no_std`, panic-free Rust.
//!
//! Populated by the soft-landing pipeline (issue 3); the foundation only
//! fixes its place in the workspace (see ARCHITECTURE.md).
