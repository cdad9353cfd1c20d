//! Piecewise-linear inputs: values, jumps, breakpoints and builders.

use designer::random::SplitMix64;
use designer::sim::{Input, InputError, PiecewiseLinear};

fn pl(t: &[f64], u: &[f64]) -> PiecewiseLinear {
    PiecewiseLinear::new(t.to_vec(), u.to_vec()).unwrap()
}

#[test]
fn linear_between_samples_constant_beyond() {
    let s = pl(&[0.0, 1.0, 3.0], &[1.0, 3.0, -1.0]);
    assert_eq!(s.value(-5.0), 1.0);
    assert_eq!(s.value(0.0), 1.0);
    assert_eq!(s.value(0.5), 2.0);
    assert_eq!(s.value(1.0), 3.0);
    assert_eq!(s.value(2.0), 1.0);
    assert_eq!(s.value(3.0), -1.0);
    assert_eq!(s.value(1e9), -1.0);
}

#[test]
fn equal_times_are_right_continuous_jumps() {
    let s = pl(&[0.0, 1.0, 1.0, 2.0], &[0.0, 0.0, 5.0, 5.0]);
    assert_eq!(s.value(1.0 - 1e-12), 0.0);
    assert_eq!(s.value(1.0), 5.0);
    assert_eq!(s.breakpoints(), &[1.0]);
    // The piece in force at the jump is the one after it.
    let p = s.piece(1.0);
    assert_eq!(p.value(1.5), 5.0);
    // The piece before the jump, evaluated at the jump, gives the left limit.
    assert_eq!(s.piece(0.5).value(1.0), 0.0);
    // Triple sample: the last one wins.
    let s = pl(&[0.0, 1.0, 1.0, 1.0], &[0.0, 2.0, 7.0, 3.0]);
    assert_eq!(s.value(1.0), 3.0);
}

#[test]
fn breakpoints_are_exactly_the_slope_or_value_changes() {
    // Ramp up (kink at 0 and 1), flat, straight line sampled at several
    // points (2, 3, 4 with equal slopes: only 2 and 4 are kinks), jump at 5.
    let s = pl(
        &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 5.0, 6.0],
        &[0.0, 1.0, 1.0, 3.0, 5.0, 5.0, 0.0, 0.0],
    );
    assert_eq!(s.breakpoints(), &[0.0, 1.0, 2.0, 4.0, 5.0]);
    assert_eq!(s.next_breakpoint(-1.0), 0.0);
    assert_eq!(s.next_breakpoint(0.0), 1.0);
    assert_eq!(s.next_breakpoint(2.5), 4.0);
    assert_eq!(s.next_breakpoint(5.0), f64::INFINITY);
    // Flat ends are not breakpoints.
    let s = pl(&[0.0, 1.0, 2.0], &[4.0, 4.0, 4.0]);
    assert!(s.breakpoints().is_empty());
    // Rounding in computed slopes does not create breakpoints.
    let ts: Vec<f64> = (0..=10).map(|k| 0.1 * k as f64).collect();
    let us: Vec<f64> = ts.iter().map(|t| 0.3 * t + 0.7).collect();
    let s = PiecewiseLinear::new(ts, us).unwrap();
    assert_eq!(s.breakpoints(), &[0.0, 1.0]);
}

#[test]
fn piece_is_the_affine_function_in_force() {
    let s = pl(&[0.0, 2.0, 4.0], &[0.0, 4.0, 0.0]);
    let p = s.piece(0.5);
    assert_eq!(p.slope, 2.0);
    assert_eq!(p.value(2.0), 4.0);
    let p = s.piece(2.0);
    assert_eq!(p.slope, -2.0);
    assert_eq!(p.value(3.0), 2.0);
    assert_eq!(s.piece(10.0).value(20.0), 0.0);
    assert_eq!(s.piece(-1.0).slope, 0.0);
}

#[test]
fn validation() {
    let e = |t: &[f64], u: &[f64]| PiecewiseLinear::new(t.to_vec(), u.to_vec()).unwrap_err();
    assert_eq!(e(&[], &[]), InputError::Empty);
    assert_eq!(
        e(&[0.0], &[1.0, 2.0]),
        InputError::LengthMismatch { t: 1, u: 2 }
    );
    assert_eq!(
        e(&[0.0, f64::NAN], &[1.0, 2.0]),
        InputError::NonFinite { index: 1 }
    );
    assert_eq!(
        e(&[0.0, 1.0], &[1.0, f64::INFINITY]),
        InputError::NonFinite { index: 1 }
    );
    assert_eq!(
        e(&[0.0, 1.0, 0.5], &[1.0, 2.0, 3.0]),
        InputError::Decreasing { index: 2 }
    );
}

#[test]
fn steps_builder() {
    let s = PiecewiseLinear::steps(&[(0.0, 1.0), (1.0, 3.0), (2.0, 3.0), (2.5, -2.0)]).unwrap();
    assert_eq!(s.value(-1.0), 1.0);
    assert_eq!(s.value(0.99), 1.0);
    assert_eq!(s.value(1.0), 3.0);
    assert_eq!(s.value(2.2), 3.0);
    assert_eq!(s.value(2.5), -2.0);
    assert_eq!(s.value(100.0), -2.0);
    assert_eq!(s.breakpoints(), &[1.0, 2.5]);
    assert!(PiecewiseLinear::steps(&[(1.0, 0.0), (0.0, 1.0)]).is_err());
    assert!(PiecewiseLinear::steps(&[]).is_err());
}

#[test]
fn pulses_builder() {
    let s = PiecewiseLinear::pulses(0.5, &[(1.0, 0.5, 4.0), (1.5, 1.0, -4.0), (3.0, 0.0, 9.0)])
        .unwrap();
    assert_eq!(s.value(0.0), 0.5);
    assert_eq!(s.value(1.0), 4.0);
    assert_eq!(s.value(1.49), 4.0);
    assert_eq!(s.value(1.5), -4.0);
    assert_eq!(s.value(2.5), 0.5);
    assert_eq!(s.value(3.0), 0.5, "a zero-width pulse has no effect");
    assert_eq!(s.breakpoints(), &[1.0, 1.5, 2.5]);
    assert!(PiecewiseLinear::pulses(0.0, &[(1.0, 1.0, 1.0), (1.5, 1.0, 1.0)]).is_err());
    assert!(PiecewiseLinear::pulses(0.0, &[(1.0, -1.0, 1.0)]).is_err());
    assert_eq!(PiecewiseLinear::pulses(2.0, &[]).unwrap().value(1.0), 2.0);
}

#[test]
fn square_wave_builder() {
    let s = PiecewiseLinear::square_wave(10.0, -1.0, 2.0, 0.25, 7.0).unwrap();
    for (t, u) in [
        (-1.0, 10.0),
        (0.0, 10.0),
        (0.49, 10.0),
        (0.5, -1.0),
        (1.99, -1.0),
        (2.0, 10.0),
        (4.5, -1.0),
        (6.2, 10.0),
        (6.5, -1.0),
        (50.0, -1.0),
    ] {
        assert_eq!(s.value(t), u, "t = {t}");
    }
    assert_eq!(s.breakpoints(), &[0.5, 2.0, 2.5, 4.0, 4.5, 6.0, 6.5]);
    assert!(PiecewiseLinear::square_wave(1.0, 0.0, 0.0, 0.5, 1.0).is_err());
    assert!(PiecewiseLinear::square_wave(1.0, 0.0, 1.0, 1.5, 1.0).is_err());
    let full = PiecewiseLinear::square_wave(1.0, 0.0, 1.0, 1.0, 5.0).unwrap();
    assert!(full.breakpoints().is_empty());
    assert_eq!(full.value(3.3), 1.0);
}

#[test]
fn cursor_agrees_with_lookup() {
    let s = PiecewiseLinear::square_wave(1.0, -2.0, 0.1, 0.3, 10.0).unwrap();
    let mut c = s.cursor();
    let mut t = -0.5;
    while t < 11.0 {
        assert_eq!(c.value(t), s.value(t), "t = {t}");
        t += 0.0123;
    }
    // Going backwards works too.
    assert_eq!(c.value(0.05), s.value(0.05));
    assert_eq!(c.value(0.2), s.value(0.2));
}

#[test]
fn constant_inputs() {
    assert_eq!(Input::value(&2.5, 7.0), 2.5);
    assert_eq!(2.5f64.next_breakpoint(0.0), f64::INFINITY);
    let s = PiecewiseLinear::constant(3.0).unwrap();
    assert_eq!(s.value(-4.0), 3.0);
    assert!(s.breakpoints().is_empty());
}

/// Lookups remember where the last one ended (a hint tried before a binary
/// search): the answers must be those of a fresh signal, whatever the order
/// of the times (forward, backward, jumps, repeated, outside, NaN).
#[test]
fn lookups_do_not_depend_on_the_previous_ones() {
    let t = [0.0, 1.0, 1.0, 2.0, 3.0, 3.0, 3.0, 4.5, 6.0, 7.0];
    let u = [0.0, 1.0, 5.0, 5.0, 2.0, 7.0, 1.0, 1.0, -3.0, 4.0];
    let s = pl(&t, &u);
    let mut times: Vec<f64> = (-4..=32).map(|k| k as f64 * 0.25).collect();
    let backward: Vec<f64> = times.iter().rev().copied().collect();
    times.extend(backward);
    times.extend([3.0, 3.0, 1.0, 6.0, -1.0, 9.0, 1.0, 2.0]);
    // a pseudo-random walk over the range
    let mut rng = SplitMix64::new(12345);
    times.extend((0..200).map(|_| -1.0 + 9.0 * rng.uniform()));
    times.extend([f64::NAN, 0.5, f64::INFINITY, 2.5, f64::NEG_INFINITY, 4.0]);
    for &at in &times {
        let fresh = pl(&t, &u);
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits();
        assert!(same(s.value(at), fresh.value(at)), "value at {at}");
        let (got, want) = (s.next_breakpoint(at), fresh.next_breakpoint(at));
        assert!(same(got, want), "next breakpoint after {at}");
        assert_eq!(s.piece(at), fresh.piece(at), "piece at {at}");
    }
}
