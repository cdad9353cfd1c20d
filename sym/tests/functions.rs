//! The unary functions' values against an independent oracle: coth against
//! 40-digit values (mpmath, `mp.coth` at `mp.dps = 40`), on both sides of
//! the point where its evaluation changes from `1/tanh` to `exp`
//! (2|x| = ln 2) and out to where it rounds to ±1; its odd symmetry and its
//! poles, which the Langevin function's closed form relies on.

use reldesign_sym::Func;

/// (x, coth x) from mpmath at 40 digits, rounded to 25.
const COTH: [(f64, f64); 16] = [
    (1e-300, 9.999999999999999749409082e+299),
    (1e-08, 100000000.0000000012410773),
    (0.001, 1000.000333333311090296553),
    (0.1, 10.03331113225398905688044),
    (0.3, 3.432738430321741709180852),
    (0.346_573_590_279_972_64, 3.000000000000000092761873),
    (0.346_573_590_279_972_7, 2.999999999999999648672663),
    (0.5, 2.163953413738652848770004),
    (0.7, 1.654621635802629481885837),
    (1.0, 1.313035285499331303636161),
    (2.5, 1.01356730981260846219204),
    (7.0, 1.000001663058821088307062),
    (18.0, 1.000000000000000463904566),
    (19.5, 1.000000000000000023096448),
    (40.0, 1.0),
    (700.0, 1.0),
];

fn ulps(a: f64, b: f64) -> u64 {
    a.to_bits().abs_diff(b.to_bits())
}

#[test]
fn coth_is_within_two_ulps_of_the_exact_value() {
    for (x, exact) in COTH {
        let got = Func::Coth.apply(x);
        assert!(
            ulps(got, exact) <= 2,
            "coth({x}) = {got:e}, exactly {exact:e}"
        );
    }
}

#[test]
fn coth_is_exactly_odd() {
    for (x, _) in COTH {
        assert_eq!(Func::Coth.apply(-x), -Func::Coth.apply(x), "x = {x}");
    }
    for k in 0..2000 {
        let x = 1e-4 * 1.01f64.powi(k);
        assert_eq!(
            Func::Coth.apply(-x).to_bits(),
            (-Func::Coth.apply(x)).to_bits()
        );
    }
}

#[test]
fn coth_has_its_poles_and_limits() {
    assert_eq!(Func::Coth.apply(0.0), f64::INFINITY);
    assert_eq!(Func::Coth.apply(-0.0), f64::NEG_INFINITY);
    assert_eq!(Func::Coth.apply(f64::INFINITY), 1.0);
    assert_eq!(Func::Coth.apply(f64::NEG_INFINITY), -1.0);
    assert!(Func::Coth.apply(f64::NAN).is_nan());
}

#[test]
fn coth_agrees_with_the_reciprocal_of_tanh_to_a_few_ulps() {
    // Both sides are approximations; a dense grid catches a wrong branch.
    for k in 0..4000 {
        let x = 1e-6 * 1.005f64.powi(k);
        let (got, other) = (Func::Coth.apply(x), 1.0 / x.tanh());
        assert!(
            ulps(got, other) <= 4,
            "coth({x}) = {got:e}, 1/tanh = {other:e}"
        );
    }
}
