//! The model quantities the energy-optimal design needs outside the
//! Hamiltonian system: rest states and rest inputs, and the initial guess of
//! one motion arc from the 5th-degree polynomial (flat parametrisation).
//!
//! **Guess.** z_r is the polynomial of the arc, x_r = T⁻¹(z_r, ż_r, z̈_r)
//! [PT 42], u_r = α(x_r) + β(x_r)·z_r⁽³⁾ ([PT 50] with perfect tracking); the costate
//! is the minimum-norm p with pᵀg = −2u_r (H stationary in u, [PT 65]),
//! completed with [`CostateGuess::Chain`]: the costate equations [PT 66] solved
//! backwards along the integrator chain (the φ row gives p₂, the v row p₁,
//! with ṗ by finite differences on the mesh), or zero ([`CostateGuess::Zero`]).
//!
//! **Rest.** T⁻¹([z, 0, 0]) is the state at rest at z [PT 61–62]; α there is the
//! input that holds it (jerk 0), whose square is the cost rate of resting.

// `!(x > 0)` is deliberate: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use crate::model::Model;
use crate::sym::Tape;

use super::problem::{CostateGuess, OptimalError};
use crate::design::derive::linearization::Linearization;
use crate::design::trajectory::reference::{Polynomial, Reference};

/// Compiled α, β, ∂f/∂x, g over (z, v, φ, u, t) and T⁻¹, φ² over ξ.
pub(crate) struct GuessTapes {
    model: Tape,
    inverse: Tape,
}

/// The initial guess of one arc: mesh, [x; p] per node, ∫u_r² dt, max|u_r|.
pub(crate) struct Guess {
    pub t: Vec<f64>,
    pub y: Vec<Vec<f64>>,
    /// Costates of the chain construction (for scaling even when not used).
    pub chain: Vec<[f64; 3]>,
    pub cost: f64,
    pub max_abs_u: f64,
}

/// Polynomial reference state at t: (x_r, u_r, ∂f/∂x row-major and g).
struct Point {
    x: [f64; 3],
    u: f64,
    jac: Vec<f64>,
}

impl GuessTapes {
    pub fn new(model: &mut Model, lin: &Linearization) -> Result<GuessTapes, OptimalError> {
        let a = model.jacobian();
        let mut outs = vec![lin.alpha, lin.beta];
        outs.extend(a.into_iter().flatten());
        outs.extend(lin.system.input_field.iter().copied());
        let model_tape = model.compile(&outs);
        let mut inv = lin.inverse.to_vec();
        inv.push(lin.flux_squared);
        let inv = model.bind_params(&inv);
        let inverse = Tape::compile(&model.graph, &lin.xi, &inv)
            .map_err(|e| OptimalError::InvalidSpec(format!("T⁻¹ is not closed: {e}")))?;
        Ok(GuessTapes {
            model: model_tape,
            inverse,
        })
    }

    /// T⁻¹(ξ) and φ² (the radicand).
    fn inverse(&self, xi: [f64; 3]) -> [f64; 4] {
        let mut x = [0.0; 4];
        self.inverse.eval(&xi, &mut self.inverse.scratch(), &mut x);
        x
    }

    /// Rest state T⁻¹([z, 0, 0]) [PT 61–62].
    pub fn rest_state(&self, z: f64, which: &'static str) -> Result<[f64; 3], OptimalError> {
        let x = self.inverse([z, 0.0, 0.0]);
        if !(x[3] > 0.0) || !x[3].is_finite() {
            return Err(OptimalError::InfeasibleBoundary {
                which,
                z,
                flux_squared: x[3],
            });
        }
        Ok([x[0], x[1], x[2]])
    }

    /// The input that holds the rest state x at time t: α(x) (jerk 0).
    pub fn rest_input(&self, x: [f64; 3], t: f64) -> f64 {
        let mut o = vec![0.0; self.model.n_outputs()];
        self.model.eval(
            &[x[0], x[1], x[2], 0.0, t],
            &mut self.model.scratch(),
            &mut o,
        );
        o[0]
    }

    fn point(&self, poly: &Polynomial, t: f64) -> Result<Point, OptimalError> {
        let eps = 1e-9 * (poly.tf - poly.t0);
        let r = poly.at(t);
        // the polynomial's jerk at the ends is its one-sided limit
        let jerk = poly.at(t.clamp(poly.t0 + eps, poly.tf - eps)).jerk;
        let xr = self.inverse([r.z, r.v, r.a]);
        if !(xr[3] > 0.0) || !xr[2].is_finite() {
            return Err(OptimalError::Guess {
                t, what: "φ² ≤ 0"
            });
        }
        let mut o = vec![0.0; self.model.n_outputs()];
        let mut scratch = self.model.scratch();
        self.model
            .eval(&[xr[0], xr[1], xr[2], 0.0, t], &mut scratch, &mut o);
        let u = o[0] + o[1] * jerk;
        if !u.is_finite() {
            return Err(OptimalError::Guess { t, what: "u_r" });
        }
        // ∂f/∂x at u_r: f is affine in u, so recompute with u
        self.model
            .eval(&[xr[0], xr[1], xr[2], u, t], &mut scratch, &mut o);
        Ok(Point {
            x: [xr[0], xr[1], xr[2]],
            u,
            jac: o[2..].to_vec(),
        })
    }

    /// The polynomial guess of the arc `poly` on `nodes` uniform nodes.
    pub fn polynomial(
        &self,
        poly: &Polynomial,
        nodes: usize,
        costates: CostateGuess,
    ) -> Result<Guess, OptimalError> {
        let duration = poly.tf - poly.t0;
        let m = nodes.max(5);
        let t: Vec<f64> = (0..m)
            .map(|i| poly.t0 + duration * i as f64 / (m - 1) as f64)
            .collect();
        let points = t
            .iter()
            .map(|&ti| self.point(poly, ti))
            .collect::<Result<Vec<_>, _>>()?;
        let (cost, max_abs_u) = self.input_cost(poly)?;
        let p_from_u: Vec<[f64; 3]> = points.iter().map(stationary_costate).collect();
        let chain = chain_costates(&t, &points, &p_from_u);
        let y = (0..m)
            .map(|i| {
                let p = match costates {
                    CostateGuess::Chain => chain[i],
                    CostateGuess::Zero => p_from_u[i],
                };
                let x = points[i].x;
                vec![x[0], x[1], x[2], p[0], p[1], p[2]]
            })
            .collect();
        Ok(Guess {
            t,
            y,
            chain,
            cost,
            max_abs_u,
        })
    }

    /// ∫u_r² dt by composite Simpson on a fine grid (u_r is smooth), and max|u_r|.
    fn input_cost(&self, poly: &Polynomial) -> Result<(f64, f64), OptimalError> {
        let fine = 2000;
        let duration = poly.tf - poly.t0;
        let mut cost = 0.0;
        let mut max_abs_u: f64 = 0.0;
        for k in 0..=fine {
            let tk = poly.t0 + duration * k as f64 / fine as f64;
            let w = if k == 0 || k == fine {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let u = self.point(poly, tk)?.u;
            max_abs_u = max_abs_u.max(u.abs());
            cost += w * u * u;
        }
        Ok((cost * duration / fine as f64 / 3.0, max_abs_u))
    }
}

/// p = −2u_r·g/|g|² (H stationary in u).
fn stationary_costate(p: &Point) -> [f64; 3] {
    let g = [p.jac[9], p.jac[10], p.jac[11]];
    let g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    [
        -2.0 * p.u * g[0] / g2,
        -2.0 * p.u * g[1] / g2,
        -2.0 * p.u * g[2] / g2,
    ]
}

/// p₃ from pᵀg = −2u_r, then [PT 66] along the chain: the φ row gives p₂, the v
/// row p₁. Falls back to the stationary costate where the chain breaks.
fn chain_costates(t: &[f64], points: &[Point], p_from_u: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let m = t.len();
    let p3: Vec<f64> = p_from_u.iter().map(|p| p[2]).collect();
    let dp3 = gradient(t, &p3);
    // ṗ₃ = −(A₀₂p₁ + A₁₂p₂ + A₂₂p₃) with A₀₂ = ∂ż/∂φ = 0
    let p2: Vec<f64> = (0..m)
        .map(|i| {
            let a = &points[i].jac;
            -(dp3[i] + a[2 * 3 + 2] * p3[i]) / a[3 + 2]
        })
        .collect();
    let dp2 = gradient(t, &p2);
    // ṗ₂ = −(A₀₁p₁ + A₁₁p₂ + A₂₁p₃)
    let p1: Vec<f64> = (0..m)
        .map(|i| {
            let a = &points[i].jac;
            -(dp2[i] + a[3 + 1] * p2[i] + a[2 * 3 + 1] * p3[i]) / a[1]
        })
        .collect();
    let chain_ok = points
        .iter()
        .all(|p| p.jac[2] == 0.0 && p.jac[5] != 0.0 && p.jac[1] != 0.0)
        && p1.iter().chain(&p2).all(|v| v.is_finite());
    (0..m)
        .map(|i| {
            if chain_ok {
                [p1[i], p2[i], p3[i]]
            } else {
                p_from_u[i]
            }
        })
        .collect()
}

/// Derivative of samples on a (uniform or not) mesh: central differences
/// inside, second-order one-sided at the ends.
fn gradient(t: &[f64], y: &[f64]) -> Vec<f64> {
    let m = t.len();
    let mut d = vec![0.0; m];
    for i in 1..m - 1 {
        let (h0, h1) = (t[i] - t[i - 1], t[i + 1] - t[i]);
        d[i] = (h0 * h0 * y[i + 1] - h1 * h1 * y[i - 1] + (h1 * h1 - h0 * h0) * y[i])
            / (h0 * h1 * (h0 + h1));
    }
    let h = t[1] - t[0];
    d[0] = (-3.0 * y[0] + 4.0 * y[1] - y[2]) / (2.0 * h);
    let h = t[m - 1] - t[m - 2];
    d[m - 1] = (3.0 * y[m - 1] - 4.0 * y[m - 2] + y[m - 3]) / (2.0 * h);
    d
}
