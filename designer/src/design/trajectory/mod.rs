//! The references a law tracks, and what they ask of the actuator:
//!
//! - `reference.rs`: soft-landing references (polynomial [PT 51–53]);
//! - `approach.rs`: a move that stops short of the stop, then a slow approach;
//! - `optimal.rs` (and `optimal/`): the energy-optimal reference (Pontryagin,
//!   [PT 58–66]) on the collocation solver `bvp.rs` (and `bvp/`, generic);
//! - `feasibility.rs`: conditions [PT 54], [PT 56], [PT 57] along a reference;
//! - `limits.rs`: the shortest motion and J against the motion time;
//! - `takeoff.rs`: the shortest pre-movement stage the supply allows;
//! - `segments.rs`, `fit_segments.rs`: a reference as the table of
//!   polynomial segments generated code stores, and its knots.

pub(super) mod approach;
pub(super) mod bvp;
pub(super) mod feasibility;
pub(super) mod fit_segments;
pub(super) mod limits;
pub(super) mod optimal;
pub(super) mod reference;
pub(super) mod segments;
pub(super) mod takeoff;
