//! Backstepping through the force for y = z (switched-force-backstepping):
//!
//! - `derivation.rs`: F_d from V₁, Ḟ = f_F + g_F·u, the law [SB 19];
//! - `lmi.rs`: small SDPs of 2×2 LMIs as second-order cone programs (generic);
//! - `region.rs`: the certified region [SB lemma 1], [SB Theorem 3];
//! - `design.rs`: the controller as plain data, [`BacksteppingDesign`](crate::design::BacksteppingDesign).

pub(in crate::design) mod derivation;
pub(in crate::design) mod design;
pub(in crate::design) mod lmi;
pub(in crate::design) mod region;
