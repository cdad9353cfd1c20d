//! The tabulated gap model: a piecewise cubic through (z_k, r_k), built as a
//! symbolic piecewise polynomial (nested `select`s of Horner forms).
//!
//! - With `r_prime`: the cubic Hermite interpolant of the given slopes (C¹).
//! - Without: the not-a-knot cubic spline (C², as scipy's `CubicSpline`)
//!   when its derivative stays positive over the table (the force must keep
//!   pulling towards z_min); otherwise the monotone PCHIP of Fritsch–Carlson
//!   (C¹, as scipy's `PchipInterpolator`).
//!
//! Outside the table the end polynomials extend (validation requires the table
//! to cover [z_min, z_max]).
//!
//! The C¹ interpolants have a discontinuous R_gap″, which enters the costate
//! equations of the energy-optimal design; [`Spline::c2_twin`] gives the C²
//! quintic Hermite through the same values and slopes for that design.

use crate::sym::{Graph, Id};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplineKind {
    Hermite,
    NotAKnot,
    Pchip,
    /// C² quintic Hermite through the values and slopes of a C¹ interpolant.
    QuinticTwin,
}

impl SplineKind {
    pub fn describe(self) -> &'static str {
        match self {
            SplineKind::Hermite => "cubic Hermite through the given r_prime (C¹)",
            SplineKind::NotAKnot => "not-a-knot cubic spline (C²)",
            SplineKind::Pchip => "monotone PCHIP (C¹; the C² spline was not monotone)",
            SplineKind::QuinticTwin => "quintic Hermite through the same values and slopes (C²)",
        }
    }
}

/// Piecewise polynomial of degree ≤ 5: on segment k,
/// p(z) = Σ c[k][j]·(z − knots[k])^j (cubics have c₄ = c₅ = 0).
#[derive(Debug, Clone, PartialEq)]
pub struct Spline {
    pub kind: SplineKind,
    pub knots: Vec<f64>,
    pub coeffs: Vec<[f64; 6]>,
}

impl Spline {
    /// Interpolates validated data (strictly increasing z, ≥ 4 points).
    pub fn fit(z: &[f64], r: &[f64], r_prime: Option<&[f64]>) -> Spline {
        if let Some(m) = r_prime {
            return Spline::hermite(SplineKind::Hermite, z, r, m);
        }
        let spline = Spline::hermite(SplineKind::NotAKnot, z, r, &not_a_knot_slopes(z, r));
        if spline.is_increasing() {
            spline
        } else {
            Spline::hermite(SplineKind::Pchip, z, r, &pchip_slopes(z, r))
        }
    }

    fn hermite(kind: SplineKind, z: &[f64], r: &[f64], m: &[f64]) -> Spline {
        let coeffs = (0..z.len() - 1)
            .map(|k| {
                let h = z[k + 1] - z[k];
                let delta = (r[k + 1] - r[k]) / h;
                let c2 = (3.0 * delta - 2.0 * m[k] - m[k + 1]) / h;
                let c3 = (m[k] + m[k + 1] - 2.0 * delta) / (h * h);
                [r[k], m[k], c2, c3, 0.0, 0.0]
            })
            .collect();
        Spline {
            kind,
            knots: z.to_vec(),
            coeffs,
        }
    }

    fn segment(&self, z: f64) -> usize {
        let n = self.coeffs.len();
        self.knots[1..n].iter().take_while(|&&k| z >= k).count()
    }

    /// Numeric value and derivative (for tests and reports).
    pub fn eval(&self, z: f64) -> (f64, f64) {
        let k = self.segment(z);
        poly_eval(&self.coeffs[k], z - self.knots[k])
    }

    /// Second derivative (for tests and reports).
    pub fn second_derivative(&self, z: f64) -> f64 {
        let k = self.segment(z);
        let c = &self.coeffs[k];
        let t = z - self.knots[k];
        2.0 * c[2] + t * (6.0 * c[3] + t * (12.0 * c[4] + t * 20.0 * c[5]))
    }

    /// Whether the derivative is positive on every segment: for a cubic at
    /// the end points and the interior extremum of the quadratic p′, for a
    /// quintic at 64 points per segment, ends included.
    fn is_increasing(&self) -> bool {
        self.coeffs.iter().enumerate().all(|(k, c)| {
            let h = self.knots[k + 1] - self.knots[k];
            let dp = |t: f64| poly_eval(c, t).1;
            if c[4] != 0.0 || c[5] != 0.0 {
                return (0..=64).all(|j| dp(h * j as f64 / 64.0) > 0.0);
            }
            let vertex = if c[3] != 0.0 {
                -c[2] / (3.0 * c[3])
            } else {
                -1.0
            };
            dp(0.0) > 0.0 && dp(h) > 0.0 && (!(0.0..=h).contains(&vertex) || dp(vertex) > 0.0)
        })
    }

    /// The C² twin of a C¹ interpolant (Hermite, PCHIP): the quintic Hermite
    /// with the same values and slopes at the knots and, as second
    /// derivatives, the mean of the C¹ one's two one-sided values. `None` when
    /// the interpolant is already C².
    pub fn c2_twin(&self) -> Option<Spline> {
        if matches!(self.kind, SplineKind::NotAKnot | SplineKind::QuinticTwin) {
            return None;
        }
        let n = self.knots.len();
        let h = |k: usize| self.knots[k + 1] - self.knots[k];
        let left = |k: usize| {
            let c = &self.coeffs[k - 1];
            2.0 * c[2] + 6.0 * c[3] * h(k - 1)
        };
        let right = |k: usize| 2.0 * self.coeffs[k][2];
        let second: Vec<f64> = (0..n)
            .map(|k| match k {
                0 => right(0),
                k if k == n - 1 => left(k),
                k => 0.5 * (left(k) + right(k)),
            })
            .collect();
        let value = |k: usize| {
            if k < n - 1 {
                (self.coeffs[k][0], self.coeffs[k][1])
            } else {
                poly_eval(&self.coeffs[k - 1], h(k - 1))
            }
        };
        let coeffs = (0..n - 1)
            .map(|k| {
                let ((p0, m0), (p1, m1)) = (value(k), value(k + 1));
                quintic_hermite(h(k), [p0, m0, second[k]], [p1, m1, second[k + 1]])
            })
            .collect();
        Some(Spline {
            kind: SplineKind::QuinticTwin,
            knots: self.knots.clone(),
            coeffs,
        })
    }

    /// Whether the derivative stays positive (for the twin's report).
    pub fn increasing(&self) -> bool {
        self.is_increasing()
    }

    /// The interpolant as a symbolic piecewise polynomial of `z`.
    pub fn expression(&self, g: &mut Graph, z: Id) -> Id {
        let pieces: Vec<Id> = self
            .coeffs
            .iter()
            .zip(&self.knots)
            .map(|(c, &zk)| {
                let shift = g.constant(-zk);
                let t = g.add(z, shift);
                let degree = if c[4] == 0.0 && c[5] == 0.0 { 3 } else { 5 };
                let start = g.constant(c[degree]);
                c[..degree].iter().rev().fold(start, |acc, &coef| {
                    let prod = g.mul(acc, t);
                    let coef = g.constant(coef);
                    g.add(prod, coef)
                })
            })
            .collect();
        let n = self.coeffs.len();
        g.piecewise(z, &self.knots[1..n], &pieces)
    }
}

/// Value and derivative of Σ c_j·t^j.
fn poly_eval(c: &[f64; 6], t: f64) -> (f64, f64) {
    let v = c.iter().rev().fold(0.0, |acc, &cj| acc * t + cj);
    let d = (1..6).rev().fold(0.0, |acc, j| acc * t + j as f64 * c[j]);
    (v, d)
}

/// The quintic on [0, h] with value, slope and second derivative `a` at 0 and
/// `b` at h.
fn quintic_hermite(h: f64, a: [f64; 3], b: [f64; 3]) -> [f64; 6] {
    let [p0, m0, s0] = a;
    let [p1, m1, s1] = b;
    let (h2, h3) = (h * h, h * h * h);
    [
        p0,
        m0,
        0.5 * s0,
        (20.0 * (p1 - p0) - (8.0 * m1 + 12.0 * m0) * h - (3.0 * s0 - s1) * h2) / (2.0 * h3),
        (30.0 * (p0 - p1) + (14.0 * m1 + 16.0 * m0) * h + (3.0 * s0 - 2.0 * s1) * h2)
            / (2.0 * h3 * h),
        (12.0 * (p1 - p0) - 6.0 * (m1 + m0) * h - (s0 - s1) * h2) / (2.0 * h3 * h2),
    ]
}

/// Slopes of the not-a-knot cubic spline (third derivative continuous at the
/// second and the second-to-last knots), via second derivatives M.
fn not_a_knot_slopes(z: &[f64], r: &[f64]) -> Vec<f64> {
    let n = z.len();
    let h: Vec<f64> = z.windows(2).map(|w| w[1] - w[0]).collect();
    let delta: Vec<f64> = (0..n - 1).map(|k| (r[k + 1] - r[k]) / h[k]).collect();
    let mut a = vec![vec![0.0; n]; n];
    let mut rhs = vec![0.0; n];
    // not-a-knot at z_1: h1·M0 − (h0 + h1)·M1 + h0·M2 = 0
    a[0][0] = h[1];
    a[0][1] = -(h[0] + h[1]);
    a[0][2] = h[0];
    for i in 1..n - 1 {
        a[i][i - 1] = h[i - 1];
        a[i][i] = 2.0 * (h[i - 1] + h[i]);
        a[i][i + 1] = h[i];
        rhs[i] = 6.0 * (delta[i] - delta[i - 1]);
    }
    let (p, q) = (h[n - 3], h[n - 2]);
    a[n - 1][n - 3] = q;
    a[n - 1][n - 2] = -(p + q);
    a[n - 1][n - 1] = p;
    let m = solve_dense(a, rhs);
    let mut slopes: Vec<f64> = (0..n - 1)
        .map(|k| delta[k] - h[k] * (2.0 * m[k] + m[k + 1]) / 6.0)
        .collect();
    slopes.push(delta[n - 2] + h[n - 2] * (m[n - 2] + 2.0 * m[n - 1]) / 6.0);
    slopes
}

/// Fritsch–Carlson slopes with scipy's end conditions.
fn pchip_slopes(z: &[f64], r: &[f64]) -> Vec<f64> {
    let n = z.len();
    let h: Vec<f64> = z.windows(2).map(|w| w[1] - w[0]).collect();
    let delta: Vec<f64> = (0..n - 1).map(|k| (r[k + 1] - r[k]) / h[k]).collect();
    let mut m = vec![0.0; n];
    for k in 1..n - 1 {
        if delta[k - 1] * delta[k] > 0.0 {
            let w1 = 2.0 * h[k] + h[k - 1];
            let w2 = h[k] + 2.0 * h[k - 1];
            m[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k]);
        }
    }
    m[0] = pchip_end(h[0], h[1], delta[0], delta[1]);
    m[n - 1] = pchip_end(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
    m
}

fn pchip_end(h0: f64, h1: f64, d0: f64, d1: f64) -> f64 {
    let m = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if m.signum() != d0.signum() {
        0.0
    } else if d0.signum() != d1.signum() && m.abs() > 3.0 * d0.abs() {
        3.0 * d0
    } else {
        m
    }
}

/// Gaussian elimination with partial pivoting (small dense systems).
fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..n {
            let f = a[row][col] / a[col][col];
            if f != 0.0 {
                for k in col..n {
                    a[row][k] -= f * a[col][k];
                }
                b[row] -= f * b[col];
            }
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn not_a_knot_reproduces_cubics_exactly() {
        let f = |z: f64| 1.0 + 2.0 * z + 0.5 * z * z + 0.25 * z * z * z;
        let z = [0.0, 0.3, 1.0, 1.4, 2.2, 3.0];
        let r: Vec<f64> = z.iter().map(|&z| f(z)).collect();
        let s = Spline::fit(&z, &r, None);
        assert_eq!(s.kind, SplineKind::NotAKnot);
        for zq in [0.1, 0.77, 1.9, 2.95] {
            assert!((s.eval(zq).0 - f(zq)).abs() < 1e-12, "{zq}");
        }
    }

    #[test]
    fn pchip_is_used_when_the_spline_would_turn_back() {
        // Steep step: the C² spline overshoots and its slope turns negative.
        let z = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let r = [0.0, 0.01, 0.02, 10.0, 10.01, 10.02];
        let s = Spline::fit(&z, &r, None);
        assert_eq!(s.kind, SplineKind::Pchip);
        let mut last = f64::NEG_INFINITY;
        for k in 0..=500 {
            let (v, _) = s.eval(5.0 * k as f64 / 500.0);
            assert!(v >= last - 1e-15);
            last = v;
        }
    }

    #[test]
    fn c2_twin_keeps_values_and_slopes_and_is_c2() {
        let z = [0.0, 0.5, 1.0, 2.0, 3.0];
        let r: Vec<f64> = z
            .iter()
            .map(|&z: &f64| z + 0.3 * z * z - 0.02 * z.powi(4))
            .collect();
        let m: Vec<f64> = z
            .iter()
            .map(|&z: &f64| 1.0 + 0.6 * z - 0.08 * z.powi(3))
            .collect();
        let s = Spline::fit(&z, &r, Some(&m));
        let twin = s.c2_twin().expect("Hermite is C¹");
        assert_eq!(twin.kind, SplineKind::QuinticTwin);
        assert!(twin.c2_twin().is_none());
        for k in 0..z.len() {
            let (v, d) = twin.eval(z[k]);
            assert!((v - r[k]).abs() < 1e-12 && (d - m[k]).abs() < 1e-12, "{k}");
        }
        for &zk in &z[1..z.len() - 1] {
            let (below, above) = (
                twin.second_derivative(zk - 1e-9),
                twin.second_derivative(zk + 1e-9),
            );
            assert!(
                (below - above).abs() < 1e-6,
                "R″ jumps at {zk}: {below} vs {above}"
            );
            let (cb, ca) = (
                s.second_derivative(zk - 1e-9),
                s.second_derivative(zk + 1e-9),
            );
            assert!((0.5 * (cb + ca) - above).abs() < 1e-6);
        }
        // a quintic through a quintic's data reproduces it
        let q = |z: f64| 1.0 + z - 0.5 * z * z + 0.1 * z.powi(5);
        let c = quintic_hermite(
            2.0,
            [q(0.0), 1.0, -1.0],
            [q(2.0), 1.0 - 2.0 + 0.5 * 16.0, -1.0 + 2.0 * 8.0],
        );
        assert!((poly_eval(&c, 1.3).0 - q(1.3)).abs() < 1e-12);
    }

    #[test]
    fn hermite_matches_values_and_slopes_at_knots() {
        let z = [0.0, 1.0, 2.0, 3.0];
        let r = [0.0, 1.0, 4.0, 9.0];
        let m = [0.0, 2.0, 4.0, 6.0];
        let s = Spline::fit(&z, &r, Some(&m));
        for k in 0..4 {
            let (v, d) = s.eval(z[k]);
            assert!((v - r[k]).abs() < 1e-12 && (d - m[k]).abs() < 1e-12);
        }
        assert!((s.eval(1.5).0 - 2.25).abs() < 1e-12);
    }

    #[test]
    fn symbolic_expression_matches_numeric_evaluation() {
        let z = [0.0, 0.2, 0.5, 0.9, 1.0];
        let r = [1.0, 1.5, 1.9, 2.6, 2.7];
        let s = Spline::fit(&z, &r, None);
        let mut g = Graph::new();
        let zs = g.symbol("z");
        let e = s.expression(&mut g, zs);
        let de = g.diff(e, zs);
        for zq in [-0.1, 0.0, 0.1, 0.2, 0.44, 0.95, 1.0, 1.1] {
            let (v, d) = s.eval(zq);
            assert!((g.eval(e, &|_| zq) - v).abs() < 1e-12);
            assert!((g.eval(de, &|_| zq) - d).abs() < 1e-10);
        }
    }
}
