//! The reference trajectory as a compact table, as generated code stores it.
//!
//! Between knots t_k < t_{k+1} (h = t_{k+1} − t_k, τ = t − t_k) the
//! acceleration is the cubic Hermite interpolant of the knot accelerations
//! and jerks, and velocity and position are its exact integrals from the knot
//! values:
//!
//! ```text
//! a(τ) = c0 + c1·τ + c2·τ² + c3·τ³          c0 = a_k, c1 = j_k,
//! c2 = (3·(a_{k+1} − a_k)/h − 2·j_k − j_{k+1})/h,
//! c3 = (j_k + j_{k+1} − 2·(a_{k+1} − a_k)/h)/h²
//! j(τ) = c1 + 2·c2·τ + 3·c3·τ²
//! v(τ) = v_k + c0·τ + c1·τ²/2 + c2·τ³/3 + c3·τ⁴/4
//! z(τ) = z_k + v_k·τ + c0·τ²/2 + c1·τ³/6 + c2·τ⁴/12 + c3·τ⁵/20
//! ```
//!
//! So one segment is seven numbers [t_k, z_k, v_k, c0, c1, c2, c3], the four
//! signals are mutually consistent derivatives inside a segment, and the jerk
//! at every knot is the exact jerk of the source (for the energy-optimal
//! reference: computed from the optimal state and input). Before the first
//! knot the reference rests at its first position; after the last, at its
//! last position.

use super::reference::{Flat, Reference};

/// One segment: [t_k, z_k, v_k, c0, c1, c2, c3].
pub type Segment = [f64; 7];

/// A piecewise reference table; `end` closes the last segment.
#[derive(Debug, Clone, PartialEq)]
pub struct Segments {
    pub segments: Vec<Segment>,
    /// The last knot time t_N.
    pub end: f64,
    /// Rest positions before the first and after the last knot.
    pub z_start: f64,
    pub z_end: f64,
}

impl Segments {
    /// The segment from knot values (z, v, a, jerk) at t_k and (a, jerk) at t_{k+1}.
    pub fn segment(t_k: f64, h: f64, at_k: Flat, a_next: f64, j_next: f64) -> Segment {
        let slope = (a_next - at_k.a) / h;
        let c2 = (3.0 * slope - 2.0 * at_k.jerk - j_next) / h;
        let c3 = (at_k.jerk + j_next - 2.0 * slope) / (h * h);
        [t_k, at_k.z, at_k.v, at_k.a, at_k.jerk, c2, c3]
    }

    /// Evaluates one segment at τ = t − t_k (the generated controller's own
    /// code, `reldesign_runtime::control::eval_segment`).
    pub fn eval_segment(s: &Segment, tau: f64) -> Flat {
        let [z, v, a, jerk] = reldesign_runtime::control::eval_segment(s, tau);
        Flat { z, v, a, jerk }
    }

    /// Index of the segment holding t (None before the first or after the end).
    pub fn locate(&self, t: f64) -> Option<usize> {
        let first = self.segments.first()?;
        if t < first[0] || t > self.end {
            return None;
        }
        Some(
            self.segments
                .partition_point(|s| s[0] <= t)
                .saturating_sub(1),
        )
    }
}

impl Reference for Segments {
    fn at(&self, t: f64) -> Flat {
        match self.locate(t) {
            Some(k) => Segments::eval_segment(&self.segments[k], t - self.segments[k][0]),
            None => {
                let z = if self.segments.first().is_some_and(|s| t < s[0]) {
                    self.z_start
                } else {
                    self.z_end
                };
                Flat {
                    z,
                    v: 0.0,
                    a: 0.0,
                    jerk: 0.0,
                }
            }
        }
    }

    fn motion(&self) -> (f64, f64) {
        (self.segments.first().map_or(self.end, |s| s[0]), self.end)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_segment_reproduces_a_quintic_exactly() {
        // z = t⁵ on [0, 1]: a = 20t³, j = 60t² — a cubic a is represented exactly.
        let at0 = Flat {
            z: 0.0,
            v: 0.0,
            a: 0.0,
            jerk: 0.0,
        };
        let seg = Segments::segment(0.0, 1.0, at0, 20.0, 60.0);
        for tau in [0.0, 0.3, 0.7, 1.0] {
            let f = Segments::eval_segment(&seg, tau);
            let expected = [
                tau.powi(5),
                5.0 * tau.powi(4),
                20.0 * tau.powi(3),
                60.0 * tau.powi(2),
            ];
            for (got, want) in [f.z, f.v, f.a, f.jerk].into_iter().zip(expected) {
                assert!((got - want).abs() < 1e-12, "τ = {tau}: {got} vs {want}");
            }
        }
    }
}
