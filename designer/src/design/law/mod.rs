//! The control laws' designs, as plain data code generation renders and the
//! runtime runs:
//!
//! - `decisions.rs`: the tracking laws (feedback linearization [PT 48],
//!   the model-free sliding mode [SM 17], the model-based sliding mode
//!   [JA 89]) and what they share (operations, reference tables, guard,
//!   landed band, press, creep), [`ControllerDesign`](super::ControllerDesign);
//! - `hold.rs`: the position hold of the model-based sliding mode;
//! - `backstepping/`: the switched force backstepping [SB §III], its
//!   derivation, its certified region and its design.
//!
//! A new law gets a file (or a folder) here; ARCHITECTURE.md lists the other
//! places it touches.

pub(super) mod backstepping;
pub(super) mod decisions;
pub(super) mod hold;
