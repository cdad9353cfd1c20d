//! The symbolic core: a hash-consed expression DAG with canonicalising
//! constructors, differentiation, substitution, deterministic CSE, printing,
//! and compilation to a flat f64 tape.
//!
//! It knows nothing of actuators: symbols are just names. Models, controllers
//! and observers are built on top of it (`reldesign-designer`'s `model`). It
//! is its own crate so that the compiler holds that invariant: it depends on
//! nothing of reldesign.
//!
//! | file | concept |
//! | --- | --- |
//! | `graph.rs` | nodes, ids, hash-consing, traversal |
//! | `build.rs` | smart constructors = simplification rules |
//! | `diff.rs` | differentiation, substitution |
//! | `cse.rs` | common-subexpression elimination |
//! | `factor.rs` | common factors out of sums |
//! | `print.rs` | deterministic infix printing |
//! | `tape.rs` | compilation to a flat tape, fast evaluation |

mod build;
mod cse;
mod diff;
mod factor;
mod graph;
mod print;
mod tape;

pub use build::pow_value;
pub use cse::Cse;
pub use graph::{sign, Func, Graph, Id, Node};
pub use tape::{Instr, Tape, UnboundSymbol};
