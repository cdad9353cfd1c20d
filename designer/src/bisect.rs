//! Bisection to the last bit: the scalar roots the designer solves once per
//! description (a settling constant, a static flux, an anhysteretic field),
//! where a bracket is known and 200 halvings cost nothing.

/// Halvings of the bracket: far past f64's resolution for any finite one.
const HALVINGS: usize = 200;

/// The midpoint of [lo, hi] after [`HALVINGS`] halvings, each keeping the
/// half the root lies in: `below(mid)` says it lies above `mid`.
pub fn bisect(mut lo: f64, mut hi: f64, below: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..HALVINGS {
        let mid = 0.5 * (lo + hi);
        if below(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_root_to_the_last_bit() {
        // within one ulp: the bracket ends as two neighbouring floats
        let root = bisect(0.0, 2.0, |x| x * x < 2.0);
        let ulp = f64::EPSILON * std::f64::consts::SQRT_2;
        assert!((root - std::f64::consts::SQRT_2).abs() <= ulp, "{root}");
        // a decreasing function: the root lies above x where it is still positive
        let root = bisect(0.0, 10.0, |x| 3.0 - x > 0.0);
        assert_eq!(root, 3.0);
    }
}
