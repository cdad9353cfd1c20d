//! One meaning of "close" for floats, Python's `math.isclose`:
//! `a == b` or `|a − b| ≤ max(rel · max(|a|, |b|), abs)`.
//!
//! Symmetric in `a` and `b`; `rel` bounds the error relative to the larger
//! magnitude, `abs` is the floor that lets values near zero compare. NaN is
//! close to nothing; an infinity only to itself.

use std::fmt::Display;

/// A tolerance: relative, absolute, or either (`Tol::rel(1e-9).or_abs(1e-12)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tol {
    pub rel: f64,
    pub abs: f64,
}

impl Tol {
    /// Relative only: zero is close to zero alone.
    pub const fn rel(rel: f64) -> Tol {
        Tol { rel, abs: 0.0 }
    }

    /// Absolute only.
    pub const fn abs(abs: f64) -> Tol {
        Tol { rel: 0.0, abs }
    }

    /// This relative tolerance, or the absolute `abs` where that is larger.
    pub const fn or_abs(self, abs: f64) -> Tol {
        Tol { rel: self.rel, abs }
    }

    /// The largest |a − b| allowed.
    pub fn allowed(self, a: f64, b: f64) -> f64 {
        (self.rel * a.abs().max(b.abs())).max(self.abs)
    }
}

/// `a == b` or, both finite, `|a − b| ≤ max(tol.rel · max(|a|, |b|), tol.abs)`.
pub fn close(a: f64, b: f64, tol: Tol) -> bool {
    a == b || (a.is_finite() && b.is_finite() && (a - b).abs() <= tol.allowed(a, b))
}

/// Fails unless `close(got, want, tol)`, naming `what` and the error.
#[track_caller]
pub fn assert_close(got: f64, want: f64, tol: Tol, what: impl Display) {
    assert!(
        close(got, want, tol),
        "{what}: got {got:e}, want {want:e} (|Δ| = {:e} > {:e})",
        (got - want).abs(),
        tol.allowed(got, want)
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_tolerance_scales_with_the_larger_magnitude() {
        assert!(close(1e6, 1e6 + 1.0, Tol::rel(1e-6)));
        assert!(!close(1e6, 1e6 + 2.0, Tol::rel(1e-6)));
        assert!(close(1.0, 1.0 + 1e-7, Tol::rel(1e-6)));
        // symmetric: the larger value sets the scale either way round
        assert_eq!(
            close(100.0, 110.0, Tol::rel(0.095)),
            close(110.0, 100.0, Tol::rel(0.095))
        );
        assert!(close(100.0, 110.0, Tol::rel(0.095)));
    }

    #[test]
    fn near_zero_only_the_absolute_floor_helps() {
        assert!(close(0.0, 0.0, Tol::rel(1e-12)));
        assert!(!close(0.0, 1e-300, Tol::rel(0.5)));
        assert!(close(0.0, 1e-13, Tol::rel(1e-9).or_abs(1e-12)));
        assert!(!close(0.0, 1e-11, Tol::rel(1e-9).or_abs(1e-12)));
        assert!(close(5.0, 5.5, Tol::abs(0.5)) && !close(5.0, 5.6, Tol::abs(0.5)));
    }

    #[test]
    fn nan_is_close_to_nothing_and_infinities_to_themselves() {
        assert!(!close(f64::NAN, f64::NAN, Tol::abs(f64::INFINITY)));
        assert!(!close(f64::NAN, 1.0, Tol::rel(1.0)));
        assert!(close(f64::INFINITY, f64::INFINITY, Tol::rel(0.0)));
        assert!(!close(f64::INFINITY, -f64::INFINITY, Tol::rel(1.0)));
        assert!(!close(f64::INFINITY, 1e308, Tol::rel(0.5)));
    }

    #[test]
    #[should_panic(expected = "R: got 2e0, want 1e0")]
    fn assert_close_names_what_and_the_values() {
        assert_close(2.0, 1.0, Tol::rel(0.1), "R");
    }
}
