//! The `no_std` runtime of reldesign-generated code.
//!
//! Generated controllers and observers depend on this crate only: it holds the
//! math they call (through `libm`, so it works without `std`) and the small
//! NaN-safe helpers every emitted law uses. Nothing here allocates or panics.
#![no_std]
#![forbid(unsafe_code)]
// the emitted code's panic-free gate (codegen/tests: clippy with these denied),
// here where the algorithms the emitted code calls live
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic,
    clippy::as_conversions
)]

pub mod backstepping;
pub mod calibrate;
pub mod control;
pub mod hold;
pub mod integral;
pub mod linalg;
// bit-level f64 logarithm: its index and exponent arithmetic is `as` by nature
#[allow(clippy::as_conversions)]
mod ln;
pub mod observe;
pub mod resistance;
pub mod semera;
pub mod sliding;

/// Scalar math for generated code, through `libm` (no `std`).
///
/// Generated functions call these with the trait path, e.g.
/// `Real::sqrt(x)`, `Real::powi(x, 4)`, so the same expressions compile for
/// `f32` and `f64` without generics and without relying on the (std-only)
/// inherent float methods. Every function is total: no panics, NaN in → NaN
/// out (`min`/`max` return the other operand, like `f64::min`).
pub mod math {
    /// The floating-point operations emitted expressions use.
    pub trait Real: Copy {
        /// √x (NaN for x < 0).
        fn sqrt(x: Self) -> Self;
        /// eˣ.
        fn exp(x: Self) -> Self;
        /// Natural logarithm.
        fn ln(x: Self) -> Self;
        /// Hyperbolic tangent.
        fn tanh(x: Self) -> Self;
        /// Hyperbolic cotangent, 1/tanh x.
        fn coth(x: Self) -> Self;
        /// xʸ for a real exponent.
        fn powf(x: Self, y: Self) -> Self;
        /// xⁿ by binary exponentiation (the algorithm of `f64::powi`).
        fn powi(x: Self, n: i32) -> Self;
        /// |x|.
        fn abs(x: Self) -> Self;
        /// Sign with sign(±0) = 0 and sign(NaN) = NaN.
        fn signum0(x: Self) -> Self;
        /// The smaller operand; a NaN operand yields the other one.
        fn min(a: Self, b: Self) -> Self;
        /// The larger operand; a NaN operand yields the other one.
        fn max(a: Self, b: Self) -> Self;
    }

    macro_rules! real_impl {
        ($t:ty, $sqrt:ident, $exp:ident, $ln:ident, $tanh:ident, $pow:ident, $abs:ident) => {
            impl Real for $t {
                #[inline]
                fn sqrt(x: $t) -> $t {
                    libm::$sqrt(x)
                }
                #[inline]
                fn exp(x: $t) -> $t {
                    libm::$exp(x)
                }
                // always: `ln` (f64) is inlined whole, see ln.rs
                #[inline(always)]
                fn ln(x: $t) -> $t {
                    crate::ln::$ln(x)
                }
                #[inline]
                fn tanh(x: $t) -> $t {
                    libm::$tanh(x)
                }
                #[inline]
                fn coth(x: $t) -> $t {
                    1.0 / libm::$tanh(x)
                }
                #[inline]
                fn powf(x: $t, y: $t) -> $t {
                    libm::$pow(x, y)
                }
                #[inline]
                fn powi(x: $t, n: i32) -> $t {
                    let mut base = x;
                    let mut e = n.unsigned_abs();
                    let mut acc: $t = 1.0;
                    loop {
                        if e & 1 == 1 {
                            acc *= base;
                        }
                        e >>= 1;
                        if e == 0 {
                            break;
                        }
                        base *= base;
                    }
                    if n < 0 {
                        1.0 / acc
                    } else {
                        acc
                    }
                }
                #[inline]
                fn abs(x: $t) -> $t {
                    libm::$abs(x)
                }
                #[inline]
                fn signum0(x: $t) -> $t {
                    if x > 0.0 {
                        1.0
                    } else if x < 0.0 {
                        -1.0
                    } else {
                        // ±0 → 0, NaN → NaN
                        x * 0.0
                    }
                }
                // comparisons, not libm's fmin/fmax: those stay out-of-line
                // calls (≈ 500 instructions per UKF step); the NaN rule is
                // written out
                #[inline]
                fn min(a: $t, b: $t) -> $t {
                    if a < b || b.is_nan() {
                        a
                    } else {
                        b
                    }
                }
                #[inline]
                fn max(a: $t, b: $t) -> $t {
                    if a > b || b.is_nan() {
                        a
                    } else {
                        b
                    }
                }
            }
        };
    }

    real_impl!(f64, sqrt, exp, ln, tanh, pow, fabs);
    real_impl!(f32, sqrtf, expf, logf, tanhf, powf, fabsf);
}

macro_rules! saturate_impl {
    ($name:ident, $t:ty) => {
        /// Clamps `u` to `[lo, hi]` (lo ≤ hi); a NaN input gives the bound
        /// closest to zero (0 when lo ≤ 0 ≤ hi), so a numerical failure never
        /// commands full voltage. Without branches: NaN → 0, then the clamp,
        /// which takes that 0 to the bound nearest zero (on x86-64 a compare-and-mask,
        /// `max` and `min`).
        #[inline]
        pub fn $name(u: $t, lo: $t, hi: $t) -> $t {
            let u = if u.is_nan() { 0.0 } else { u };
            let u = if u > lo { u } else { lo };
            if u < hi {
                u
            } else {
                hi
            }
        }
    };
}

saturate_impl!(saturate, f64);
saturate_impl!(saturate_f32, f32);

/// One sample of the measured state of a single-coil actuator: position z
/// [m], velocity v [m/s] and magnetic flux φ [Wb] (the state of the
/// reluctance model; perfect-tracking-soft-landing assumes all three are
/// measured).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measurement<F> {
    pub z: F,
    pub v: F,
    pub phi: F,
}

/// A discrete-time controller as emitted by reldesign: called once per
/// sample period with the time `t` [s] and the measurement, it returns the
/// input u (coil voltage or current), already saturated to the supply limits.
///
/// Implementations are allocation-free and panic-free; non-finite
/// measurements give a finite, saturated input.
pub trait Controller<F> {
    /// The input to apply from `t` until the next sample.
    fn step(&mut self, t: F, y: &Measurement<F>) -> F;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturate_clamps_and_is_nan_safe() {
        assert_eq!(saturate(30.0, -24.0, 24.0), 24.0);
        assert_eq!(saturate(-30.0, -24.0, 24.0), -24.0);
        assert_eq!(saturate(3.5, -24.0, 24.0), 3.5);
        assert_eq!(saturate(f64::NAN, -24.0, 24.0), 0.0);
        assert_eq!(saturate(f64::NAN, 1.0, 24.0), 1.0);
        assert_eq!(saturate(f64::NAN, -24.0, -1.0), -1.0);
        assert_eq!(saturate_f32(f32::NAN, -24.0, 24.0), 0.0);
        assert_eq!(saturate_f32(f32::NAN, 1.0, 24.0), 1.0);
        assert_eq!(saturate_f32(f32::NAN, -24.0, -1.0), -1.0);
        assert_eq!(saturate_f32(-30.0, -24.0, 24.0), -24.0);
        assert_eq!(saturate(f64::INFINITY, -24.0, 24.0), 24.0);
        assert_eq!(saturate(f64::NEG_INFINITY, -24.0, 24.0), -24.0);
        assert_eq!(saturate(-24.0, -24.0, 24.0), -24.0);
        assert_eq!(saturate(24.0, -24.0, 24.0), 24.0);
    }

    /// min/max: the smaller/larger operand, a NaN operand yields the other
    /// one (both NaN: NaN), as libm's fmin/fmax and `f64::min`/`max`.
    #[test]
    fn min_and_max_skip_a_nan_operand() {
        use math::Real;
        macro_rules! check {
            ($t:ty) => {
                let nan = <$t>::NAN;
                for (a, b, lo, hi) in [
                    (1.0, 2.0, 1.0, 2.0),
                    (2.0, 1.0, 1.0, 2.0),
                    (-3.0, -3.0, -3.0, -3.0),
                    (nan, 2.0, 2.0, 2.0),
                    (2.0, nan, 2.0, 2.0),
                    (
                        <$t>::NEG_INFINITY,
                        nan,
                        <$t>::NEG_INFINITY,
                        <$t>::NEG_INFINITY,
                    ),
                    (nan, <$t>::INFINITY, <$t>::INFINITY, <$t>::INFINITY),
                ] {
                    let (a, b, lo, hi): ($t, $t, $t, $t) = (a, b, lo, hi);
                    assert_eq!(<$t as Real>::min(a, b), lo, "min({a}, {b})");
                    assert_eq!(<$t as Real>::max(a, b), hi, "max({a}, {b})");
                    let (lo64, hi64): (f64, f64) = (lo.into(), hi.into());
                    assert_eq!(libm::fmin(a.into(), b.into()), lo64, "libm fmin({a}, {b})");
                    assert_eq!(libm::fmax(a.into(), b.into()), hi64, "libm fmax({a}, {b})");
                }
                assert!(<$t as Real>::min(nan, nan).is_nan());
                assert!(<$t as Real>::max(nan, nan).is_nan());
            };
        }
        check!(f64);
        check!(f32);
    }

    #[test]
    fn math_is_total_and_matches_the_definitions() {
        use math::Real;
        assert_eq!(<f64 as Real>::signum0(0.0), 0.0);
        assert_eq!(<f64 as Real>::signum0(-0.0), 0.0);
        assert_eq!(<f64 as Real>::signum0(-3.0), -1.0);
        assert_eq!(<f32 as Real>::signum0(2.0), 1.0);
        assert!(<f64 as Real>::signum0(f64::NAN).is_nan());
        assert_eq!(<f64 as Real>::powi(2.0, 10), 1024.0);
        assert_eq!(<f64 as Real>::powi(2.0, -2), 0.25);
        assert_eq!(<f64 as Real>::powi(3.0, 0), 1.0);
        assert_eq!(<f64 as Real>::powi(1.0, i32::MIN), 1.0);
        assert_eq!(<f32 as Real>::powi(1.5, 3), 3.375);
        assert_eq!(<f64 as Real>::max(1.0, 2.0), 2.0);
        assert_eq!(<f64 as Real>::sqrt(2.25), 1.5);
        assert!((<f64 as Real>::coth(0.5) - 1.0 / 0.5f64.tanh()).abs() < 1e-15);
        assert!((<f64 as Real>::ln(<f64 as Real>::exp(0.3)) - 0.3).abs() < 1e-15);
        assert!((<f64 as Real>::powf(2.0, 0.5) - 2f64.sqrt()).abs() < 1e-15);
        assert!((<f32 as Real>::tanh(0.5) - 0.5f32.tanh()).abs() < 1e-6);
    }
}
