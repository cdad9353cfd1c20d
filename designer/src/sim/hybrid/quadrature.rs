//! Extra integrals computed with the plant (e.g. the terms of an energy
//! balance), and the extended state the integrator runs on.
//!
//! [`super::simulate_with`] integrates `Q ≤ MAX_QUAD` quadratures
//! `q̇ = integrand(t, x, ẋ, u, mode)` together with the plant (they take part
//! in the error control). Internally the integrator is const-generic and runs
//! on `[f64; MAX_DIM + MAX_QUAD]`, so the plant interface keeps
//! `State = [f64; MAX_DIM]`.

use crate::sim::{Mode, State, MAX_DIM};

/// Largest number of extra integrals (quadratures) of [`simulate_with`](super::simulate_with).
pub const MAX_QUAD: usize = 8;
/// Values of the quadratures (the first `Quadrature::len` are used).
pub type QuadState = [f64; MAX_QUAD];

pub(super) const EXT: usize = MAX_DIM + MAX_QUAD;
/// Plant states followed by quadratures, packed: `[x_0..x_pd, q_0..q_nq, 0…]`.
pub(super) type Ext = [f64; EXT];

/// Extra integrals computed along the trajectory: `q̇ = integrand(…)`, `q(t0) = 0`.
pub trait Quadrature {
    /// Number of integrals (≤ [`MAX_QUAD`]).
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Writes the `len()` integrands at `(t, x, ẋ, u, mode)`; `ẋ` is the
    /// derivative actually integrated (`ż = v̇ = 0` when stuck).
    fn integrand(&self, t: f64, x: &State, dx: &State, u: f64, mode: Mode, out: &mut QuadState);
    /// Typical magnitude of each integral (absolute tolerance = rtol × scale).
    fn scale(&self) -> QuadState {
        [1.0; MAX_QUAD]
    }
}

/// No extra integrals.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoQuadrature;

impl Quadrature for NoQuadrature {
    fn len(&self) -> usize {
        0
    }
    fn integrand(&self, _: f64, _: &State, _: &State, _: f64, _: Mode, _: &mut QuadState) {}
}

/// The plant's states of an extended state (unused entries 0). Element by
/// element over the fixed size: a `memcpy` call would cost more (hot path).
#[inline]
pub(super) fn plant_state(x: &Ext, pd: usize) -> State {
    std::array::from_fn(|i| if i < pd { x[i] } else { 0.0 })
}

/// The plant's states of the head of an extended state (unused entries 0).
#[inline]
pub(super) fn head_state(x: State, pd: usize) -> State {
    std::array::from_fn(|i| if i < pd { x[i] } else { 0.0 })
}

/// The quadratures of an extended state (unused entries 0).
pub(super) fn quad_state(x: &Ext, pd: usize, nq: usize) -> QuadState {
    let mut q = [0.0; MAX_QUAD];
    q[..nq].copy_from_slice(&x[pd..pd + nq]);
    q
}
