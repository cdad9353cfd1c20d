//! Dopri5 against ODEs with known solutions.

use designer::sim::{Dopri5, RkError};

fn always(_: &[f64; 2]) -> bool {
    true
}

/// Integrates `f` from 0 to `t_end` and returns the error at the end against `exact`.
fn end_error<F>(
    mut f: F,
    exact: impl Fn(f64) -> [f64; 2],
    t_end: f64,
    rtol: f64,
) -> (f64, Dopri5<2>)
where
    F: FnMut(f64, &[f64; 2], &mut [f64; 2]),
{
    let mut rk = Dopri5::<2>::new(2, rtol, [rtol; 2]);
    rk.init(0.0, &exact(0.0), &mut f, &mut always);
    rk.integrate_to(&mut f, &mut always, t_end).unwrap();
    assert_eq!(rk.t(), t_end, "must land exactly on t_end");
    let e = exact(t_end);
    let err = (rk.x()[0] - e[0]).abs().max((rk.x()[1] - e[1]).abs());
    (err, rk)
}

fn decay(_t: f64, x: &[f64; 2], dx: &mut [f64; 2]) {
    dx[0] = -x[0];
    dx[1] = -3.0 * x[1];
}
fn decay_exact(t: f64) -> [f64; 2] {
    [(-t).exp(), 2.0 * (-3.0 * t).exp()]
}

fn oscillator(_t: f64, x: &[f64; 2], dx: &mut [f64; 2]) {
    dx[0] = x[1];
    dx[1] = -x[0];
}
fn oscillator_exact(t: f64) -> [f64; 2] {
    [t.cos(), -t.sin()]
}

/// x1' = −x1 + x2, x2' = −100·x2 (eigenvalues −1, −100).
fn stiffish(_t: f64, x: &[f64; 2], dx: &mut [f64; 2]) {
    dx[0] = -x[0] + x[1];
    dx[1] = -100.0 * x[1];
}
fn stiffish_exact(t: f64) -> [f64; 2] {
    let (x10, x20) = (1.0, 1.0);
    let b = -x20 / 99.0;
    let a = x10 - b;
    [
        a * (-t).exp() + b * (-100.0 * t).exp(),
        x20 * (-100.0 * t).exp(),
    ]
}

#[test]
fn exponential_decay_error_scales_with_tolerance() {
    let mut prev = f64::INFINITY;
    for rtol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
        let (err, _) = end_error(decay, decay_exact, 5.0, rtol);
        assert!(err < 20.0 * rtol, "rtol {rtol}: error {err}");
        assert!(err < prev, "error must shrink with the tolerance");
        prev = err;
    }
}

#[test]
fn harmonic_oscillator_over_many_periods() {
    let t_end = 100.0 * std::f64::consts::TAU;
    let (e6, rk6) = end_error(oscillator, oscillator_exact, t_end, 1e-6);
    let (e10, rk10) = end_error(oscillator, oscillator_exact, t_end, 1e-10);
    assert!(e10 < 1e-7, "rtol 1e-10: error {e10} after 100 periods");
    // Global error of a 5th-order method scales roughly like tol^(5/6)…tol.
    assert!(e6 / e10 > 1e2, "error ratio {} too small", e6 / e10);
    // Tighter tolerance needs more steps, and no step was rejected wildly.
    assert!(rk10.stats().accepted > 3 * rk6.stats().accepted);
    let s = rk10.stats();
    assert!(s.rejected < s.accepted / 10, "{s:?}");
    // FSAL: 6 evaluations per attempted step plus the start-up ones.
    assert_eq!(s.evaluations, 6 * (s.accepted + s.rejected) + 2);
}

#[test]
fn stiffish_linear_system() {
    for rtol in [1e-6, 1e-9] {
        let (err, rk) = end_error(stiffish, stiffish_exact, 2.0, rtol);
        assert!(err < 10.0 * rtol, "rtol {rtol}: error {err}");
        // Explicit method: the step is bounded by stability (|hλ| ≲ 3.3).
        assert!(rk.stats().accepted < 400, "{:?}", rk.stats());
    }
}

#[test]
fn dense_output_matches_exact_solution_inside_steps() {
    for (f, exact, t_end) in [
        (
            oscillator as fn(f64, &[f64; 2], &mut [f64; 2]),
            oscillator_exact as fn(f64) -> [f64; 2],
            20.0,
        ),
        (stiffish, stiffish_exact, 1.0),
        (decay, decay_exact, 5.0),
    ] {
        let mut f = f;
        let tol = 1e-8;
        let mut rk = Dopri5::<2>::new(2, tol, [tol; 2]);
        rk.init(0.0, &exact(0.0), &mut f, &mut always);
        let mut worst: f64 = 0.0;
        let mut steps = 0;
        while rk.t() < t_end {
            rk.step(&mut f, &mut always, t_end).unwrap();
            steps += 1;
            let (a, b) = (rk.t_prev(), rk.t());
            let mut x = [0.0; 2];
            rk.dense(a, &mut x);
            for j in 1..10 {
                let t = a + (b - a) * j as f64 / 10.0;
                rk.dense(t, &mut x);
                let e = exact(t);
                worst = worst.max((x[0] - e[0]).abs()).max((x[1] - e[1]).abs());
                assert_eq!(rk.dense_component(1, t), x[1]);
            }
            rk.dense(b, &mut x);
            assert_eq!(&x, rk.x(), "dense output must end exactly on the step end");
        }
        assert!(steps > 5);
        assert!(worst < 20.0 * tol, "dense error {worst}");
    }
}

#[test]
fn dense_output_is_fourth_order_exact_for_polynomials() {
    // x'' = 6t → x = t³: the continuous extension reproduces cubics exactly.
    let mut f = |t: f64, x: &[f64; 2], dx: &mut [f64; 2]| {
        dx[0] = x[1];
        dx[1] = 6.0 * t;
    };
    let mut rk = Dopri5::<2>::new(2, 1e-3, [1e-3; 2]).with_first_step(Some(0.7));
    rk.init(0.0, &[0.0, 0.0], &mut f, &mut always);
    rk.step(&mut f, &mut always, 10.0).unwrap();
    assert_eq!(rk.t(), 0.7);
    for j in 0..=20 {
        let t = 0.7 * j as f64 / 20.0;
        let mut x = [0.0; 2];
        rk.dense(t, &mut x);
        assert!((x[0] - t.powi(3)).abs() < 1e-15, "t {t}: {}", x[0]);
        assert!((x[1] - 3.0 * t * t).abs() < 1e-14);
    }
}

#[test]
fn steps_respect_limit_and_max_step() {
    let mut f = decay;
    let mut rk = Dopri5::<2>::new(2, 1e-6, [1e-6; 2]).with_max_step(0.05);
    rk.init(0.0, &decay_exact(0.0), &mut f, &mut always);
    let mut t_prev = 0.0;
    for limit in [0.123, 0.5, 0.5000001, 1.0] {
        while rk.t() < limit {
            let h = rk.step(&mut f, &mut always, limit).unwrap();
            assert!(h <= 0.05 && rk.t() <= limit);
            assert!(rk.t() > t_prev);
            t_prev = rk.t();
        }
        assert_eq!(rk.t(), limit);
    }
}

#[test]
fn a_shortened_step_keeps_the_proposal_except_towards_a_breakpoint() {
    let run = |to_breakpoint: bool| {
        let mut rk = Dopri5::<2>::new(2, 1e-6, [1e-6; 2]);
        let mut f = decay;
        rk.init(0.0, &decay_exact(0.0), &mut f, &mut always);
        rk.integrate_to(&mut f, &mut always, 1.0).unwrap();
        let (proposed, t) = (rk.step_size(), rk.t());
        let limit = t + 0.01 * proposed;
        let h = if to_breakpoint {
            rk.step_to_breakpoint(&mut f, &mut always, limit)
        } else {
            rk.step(&mut f, &mut always, limit)
        };
        assert_eq!(h.unwrap(), limit - t);
        assert_eq!(rk.t(), limit);
        (proposed, rk.step_size())
    };
    let (proposed, after) = run(false);
    assert_eq!(after, proposed, "the earlier proposal stands");
    let (proposed, after) = run(true);
    // The short step's own proposal: at most 10 times its size.
    assert!(
        after <= 10.0 * 0.01 * proposed * (1.0 + 1e-12),
        "{after} vs {proposed}"
    );
}

#[test]
fn restart_keeps_step_size_and_init_does_not() {
    let mut f = oscillator;
    let mut rk = Dopri5::<2>::new(2, 1e-8, [1e-8; 2]);
    rk.init(0.0, &oscillator_exact(0.0), &mut f, &mut always);
    rk.integrate_to(&mut f, &mut always, 3.0).unwrap();
    let h = rk.step_size();
    let x = *rk.x();
    rk.restart(3.0, &x, &mut f, &mut always);
    assert_eq!(rk.step_size(), h);
    assert_eq!(rk.t_prev(), 3.0);
    rk.integrate_to(&mut f, &mut always, 6.0).unwrap();
    let e = oscillator_exact(6.0);
    assert!((rk.x()[0] - e[0]).abs() < 1e-7);
}

#[test]
fn domain_rejections_are_retried() {
    // x' = −√x from 1: x = (1 − t/2)², reaches 0 at t = 2; √ of a negative
    // stage value is NaN, and the predicate also forbids x < 0.
    let mut f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| {
        dx[0] = -x[0].sqrt();
        dx[1] = 0.0;
    };
    let mut dom = |x: &[f64; 2]| x[0] >= 0.0;
    let mut rk = Dopri5::<2>::new(2, 1e-9, [1e-12; 2]).with_first_step(Some(1.5));
    rk.init(0.0, &[1.0, 0.0], &mut f, &mut dom);
    rk.integrate_to(&mut f, &mut dom, 1.9).unwrap();
    assert!(rk.stats().rejected > 0);
    let exact = (1.0f64 - 0.95).powi(2);
    assert!((rk.x()[0] - exact).abs() < 1e-9, "{} vs {exact}", rk.x()[0]);
}

#[test]
fn leaving_the_domain_is_a_clean_error() {
    let mut f = |_t: f64, _x: &[f64; 2], dx: &mut [f64; 2]| {
        dx[0] = 1.0;
        dx[1] = 0.0;
    };
    let mut dom = |x: &[f64; 2]| x[0] < 0.9;
    let mut rk = Dopri5::<2>::new(2, 1e-8, [1e-8; 2]);
    rk.init(0.0, &[0.0, 0.0], &mut f, &mut dom);
    match rk.integrate_to(&mut f, &mut dom, 2.0) {
        Err(RkError::LeftDomain { t, .. }) => assert!(t > 0.89 && t < 0.9, "t = {t}"),
        other => panic!("expected LeftDomain, got {other:?}"),
    }
}

#[test]
fn blow_up_is_a_clean_error() {
    // x' = x² from 1 blows up at t = 1.
    let mut f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| {
        dx[0] = x[0] * x[0];
        dx[1] = 0.0;
    };
    let mut rk = Dopri5::<2>::new(2, 1e-8, [1e-8; 2]).with_min_step(1e-12);
    rk.init(0.0, &[1.0, 0.0], &mut f, &mut always);
    match rk.integrate_to(&mut f, &mut always, 2.0) {
        Err(RkError::StepTooSmall { t, .. } | RkError::LeftDomain { t, .. }) => {
            assert!((t - 1.0).abs() < 1e-3, "t = {t}")
        }
        Ok(()) => panic!("integrated through a blow-up"),
    }
}

#[test]
fn unused_components_are_ignored() {
    // dim 1 inside [f64; 4]: garbage in the unused entries must not matter.
    let mut f = |_t: f64, x: &[f64; 4], dx: &mut [f64; 4]| {
        dx[0] = -x[0];
        dx[1] = f64::NAN;
    };
    let mut dom = |_: &[f64; 4]| true;
    let mut rk = Dopri5::<4>::new(1, 1e-10, [1e-12, 0.0, 0.0, 0.0]);
    rk.init(0.0, &[1.0, f64::NAN, 0.0, 0.0], &mut f, &mut dom);
    rk.integrate_to(&mut f, &mut dom, 1.0).unwrap();
    assert!((rk.x()[0] - (-1.0f64).exp()).abs() < 1e-10);
}
