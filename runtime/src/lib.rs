//! The `no_std` runtime of reldesign-generated code.
//!
//! Generated controllers and observers depend on this crate only: it holds the
//! math they call (through `libm`, so it works without `std`) and the small
//! NaN-safe helpers every emitted law uses. Nothing here allocates or panics.
#![no_std]
#![forbid(unsafe_code)]

/// Clamps `u` to `[lo, hi]`; a NaN input maps to `lo`'s side of zero-safe
/// behaviour: it returns the bound closest to zero, so a numerical failure
/// never commands full voltage.
#[inline]
pub fn saturate(u: f64, lo: f64, hi: f64) -> f64 {
    if u.is_nan() {
        return if lo <= 0.0 && hi >= 0.0 {
            0.0
        } else if lo > 0.0 {
            lo
        } else {
            hi
        };
    }
    if u < lo {
        lo
    } else if u > hi {
        hi
    } else {
        u
    }
}

/// f32 version of [`saturate`].
#[inline]
pub fn saturate_f32(u: f32, lo: f32, hi: f32) -> f32 {
    saturate(u as f64, lo as f64, hi as f64) as f32
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
    }
}
