//! What reldesign's tests share, written once: where the workspace and its
//! examples are ([`paths`]), directories removed on drop ([`temp`]), the
//! `reldesign` binary run as a user runs it ([`cli`]), one meaning of "close"
//! for floats ([`close`]) and scratch crates that compile emitted code
//! ([`scratch`]).
//!
//! It depends on no reldesign crate, so that every crate (designer included)
//! can dev-depend on it without a cycle; helpers that parse a description
//! belong to the tests of the crate that owns the parser.

pub mod cli;
pub mod close;
pub mod lines;
pub mod paths;
pub mod physics;
pub mod scratch;
pub mod temp;

pub use cli::{assert_no_panic, squeeze, Cli, Run};
pub use close::{assert_close, close, Tol};
pub use lines::{changed_lines, code_only, replaced_once};
pub use paths::{example_path, example_paths, root, toml_files};
pub use physics::{example_physics, without_design_sections};
pub use scratch::{ScratchCrate, ODD_FLOATS};
pub use temp::{files_in, TempDir};
