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
//! | `graph.rs` | nodes, ids, hash-consing, symbols, traversal |
//! | `build.rs` | smart constructors = simplification rules |
//! | `expr.rs` | expression handles with operators, over the constructors |
//! | `parse.rs` | infix text to nodes (tests) |
//! | `diff.rs` | differentiation, substitution |
//! | `cse.rs` | common-subexpression elimination |
//! | `factor.rs` | common factors out of sums |
//! | `print.rs` | deterministic infix printing |
//! | `tape.rs` | compilation to a flat tape, fast evaluation |

mod build;
mod cse;
mod diff;
mod expr;
mod factor;
mod graph;
mod parse;
mod print;
mod tape;

pub use build::pow_value;
pub use cse::Cse;
pub use expr::{Operand, Scope, E};
pub use graph::{sign, Func, Graph, Id, Node, SymbolTaken};
pub use parse::ParseError;
pub use tape::{Instr, Tape, UnboundSymbol};
