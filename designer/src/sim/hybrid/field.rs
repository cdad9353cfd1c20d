//! The vector field the integrator runs on in each mode: the plant's field
//! (on held branches of its switching functions), `ż = v̇ = 0` when stuck,
//! then the quadratures' integrands; and the free acceleration the lift-off
//! guard and the resets read.

use super::quadrature::{plant_state, Ext, Quadrature, MAX_QUAD};
use crate::sim::input::Affine;
use crate::sim::{Branches, Mode, Plant, State, MAX_DIM};

/// The plant's field, on the held `branch` or (`None`) with the live signs.
#[inline]
fn field<P: Plant>(plant: &P, branch: Option<Branches>, t: f64, x: &State, u: f64) -> State {
    let mut dx = [0.0; MAX_DIM];
    match branch {
        Some(b) => plant.deriv_branch(t, x, u, &b, &mut dx),
        None => plant.deriv(t, x, u, &mut dx),
    }
    dx
}

/// The vector field of `mode`: plant derivative (`ż = v̇ = 0` when stuck),
/// then the quadratures' integrands.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn rhs<P: Plant, Q: Quadrature>(
    plant: &P,
    quad: &Q,
    pd: usize,
    nq: usize,
    mode: Mode,
    branch: Option<Branches>,
    piece: Affine,
    t: f64,
    x: &Ext,
    out: &mut Ext,
) {
    let xs = plant_state(x, pd);
    let u = piece.value(t);
    let mut dx = match (mode, branch) {
        (Mode::Free, _) | (_, None) => field(plant, branch, t, &xs, u),
        (_, Some(b)) => {
            let mut dx = [0.0; MAX_DIM];
            plant.deriv_resting(t, &xs, u, &b, &mut dx);
            dx
        }
    };
    if mode != Mode::Free {
        dx[0] = 0.0;
        dx[1] = 0.0;
    }
    for (i, o) in out.iter_mut().enumerate().take(MAX_DIM) {
        if i < pd {
            *o = dx[i];
        }
    }
    if nq > 0 {
        let mut q = [0.0; MAX_QUAD];
        quad.integrand(t, &xs, &dx, u, mode, &mut q);
        out[pd..pd + nq].copy_from_slice(&q[..nq]);
    }
}

/// The acceleration `v̇` of free motion at `x`, whatever the mode.
pub(super) fn free_accel<P: Plant>(
    plant: &P,
    pd: usize,
    branch: Option<Branches>,
    t: f64,
    x: &Ext,
    piece: Affine,
) -> f64 {
    let (xs, u) = (plant_state(x, pd), piece.value(t));
    match branch {
        Some(b) => plant.accel_branch(t, &xs, u, &b),
        None => field(plant, None, t, &xs, u)[1],
    }
}
