//! Reference tables fitted by `fit_segments` (adaptive knots, knot values
//! from the source):
//! - the quintic polynomial reference is one exact segment;
//! - the energy-optimal closing and opening of the perfect-tracking valve at
//!   ±20 V (saturated arcs; the switching times as forced breaks): compact
//!   tables within tolerance on 10000 uniform points independent of the
//!   fitting samples, z and v continuous across knots to within tolerance;
//! - errors: an absurd tolerance (the worst time and error are named), a
//!   discontinuous source without a break there, invalid input.
//!
//! Measured (default tolerance: z ≤ 0.1 nm, v ≤ 1e-5, a and jerk ≤ 1e-4 of
//! their maxima; max |table − source| on the independent 10000 points;
//! `cargo test --test segments -- --nocapture` prints the current figures):
//!
//! | reference              | segments | Δz [m]  | Δv [m/s] | Δa [m/s²] | Δjerk [m/s³] |
//! |------------------------|----------|---------|----------|-----------|--------------|
//! | polynomial (1 → 0 mm)  | 1        | 6.1e-18 | 3.7e-15  | 1.4e-12   | 1.2e-9       |
//! | closing ±20 V          | 36       | 7.2e-11 | 8.0e-7   | 8.1e-3    | 140 (of 1.6e6) |
//! | opening ±20 V          | 39       | 4.3e-11 | 4.3e-7   | 4.1e-3    | 77 (of 1.0e6)  |
//!
//! Without the switching times as breaks: 46 and 58 segments. Jumps at the
//! knots: z ≤ 7.2e-11 m, v ≤ 8.0e-7 m/s (the end-of-segment errors), a and
//! jerk ~1e-9 relative (one-sided extrapolation at the switches).

use designer::description::parse_file;
use designer::design::{
    energy_optimal, fit_segments, knot_jumps, table_errors, FitError, Flat, Linearization,
    OptimalSpec, OptimalTrajectory, Polynomial, Reference, SegmentFit, SegmentTolerance, Signal,
};
use designer::model::Model;
use support::example_path;

const T0: f64 = 1e-3;
const TF: f64 = 6e-3;
const CLOSING: (f64, f64) = (1e-3, 0.0);
const OPENING: (f64, f64) = (0.0, 1e-3);

fn optimal((z0, zf): (f64, f64), bound: f64) -> OptimalTrajectory {
    let path = example_path("perfect-tracking-valve.toml");
    let mut m = Model::build(&parse_file(&path).unwrap_or_else(|e| panic!("{e}")));
    let lin = Linearization::derive(&mut m).unwrap();
    let spec = OptimalSpec::new(z0, zf, T0, TF, -bound, bound);
    energy_optimal(&mut m, &lin, &spec).unwrap_or_else(|e| panic!("{e}"))
}

fn report(name: &str, source: &dyn Reference, fit: &SegmentFit) {
    let e = table_errors(source, &fit.table, 10000);
    println!(
        "{name}: {} segments ({} passes)\n  independent max |Δ| {:?}\n  at {:?}\n  on fit samples {:?}\n  allowed {:?}\n  scales {:?}\n  knot jumps {:?}",
        fit.table.segments.len(),
        fit.passes,
        e.max,
        e.at,
        fit.errors.max,
        fit.allowed,
        fit.scales,
        fit.jumps
    );
}

/// The table within tolerance on 10000 uniform points, continuous in z and v,
/// resting outside the motion, its knots including the forced breaks.
fn check_fit(source: &dyn Reference, breaks: &[f64], fit: &SegmentFit, tol: &SegmentTolerance) {
    let table = &fit.table;
    let (t0, tf) = source.motion();
    assert_eq!(table.motion(), (t0, tf));
    assert_eq!(table.z_start, source.at(t0).z);
    assert_eq!(table.z_end, source.at(tf).z);
    assert!(table.segments.windows(2).all(|w| w[0][0] < w[1][0]));
    for b in breaks {
        assert!(
            table.segments.iter().any(|s| s[0] == *b),
            "break {b} is not a knot"
        );
    }
    // independent of the fitting samples
    let e = table_errors(source, table, 10000);
    assert!(e.max.z <= tol.z, "z {e:?}");
    assert!(e.max.v <= tol.v * fit.scales.v, "v {e:?}");
    assert!(e.max.a <= tol.a * fit.scales.a, "a {e:?}");
    assert!(e.max.jerk <= tol.jerk * fit.scales.jerk, "jerk {e:?}");
    // continuity: z, v within tolerance at the knots; a and jerk continuous
    // (so is the source, also at the switches, where only the jerk has kinks)
    let jumps = knot_jumps(table);
    assert_eq!(jumps, fit.jumps);
    assert!(
        jumps.z <= tol.z && jumps.v <= tol.v * fit.scales.v,
        "{jumps:?}"
    );
    assert!(jumps.a <= 1e-9 * fit.scales.a, "{jumps:?}");
    assert!(jumps.jerk <= 1e-9 * fit.scales.jerk, "{jumps:?}");
    // rest outside the motion
    let rest = |z: f64| Flat {
        z,
        v: 0.0,
        a: 0.0,
        jerk: 0.0,
    };
    assert_eq!(table.at(t0 - 1e-4), rest(table.z_start));
    assert_eq!(table.at(tf + 1e-4), rest(table.z_end));
    // the ends of the table meet the rest (soft landing)
    let (a, b) = (table.at(t0), table.at(tf));
    assert!((a.z - table.z_start).abs() <= 1e-18 && a.v == 0.0 && a.a.abs() <= 1e-9 * fit.scales.a);
    assert!((b.z - table.z_end).abs() <= tol.z && b.v.abs() <= tol.v * fit.scales.v);
    assert!(b.a.abs() <= tol.a * fit.scales.a);
}

#[test]
fn the_quintic_polynomial_is_one_exact_segment() {
    let tol = SegmentTolerance::default();
    for (z0, zf) in [CLOSING, OPENING] {
        let p = Polynomial {
            z0,
            zf,
            t0: T0,
            tf: TF,
        };
        let fit = fit_segments(&p, &[], &tol).unwrap();
        report("polynomial", &p, &fit);
        check_fit(&p, &[], &fit, &tol);
        assert_eq!(fit.table.segments.len(), 1);
        let e = table_errors(&p, &fit.table, 10000);
        assert!(e.max.z <= 1e-13 * fit.scales.z, "{e:?}");
        assert!(e.max.v <= 1e-13 * fit.scales.v, "{e:?}");
        assert!(e.max.a <= 1e-13 * fit.scales.a, "{e:?}");
        assert!(e.max.jerk <= 1e-13 * fit.scales.jerk, "{e:?}");
        // a forced break splits it into two exact segments
        let fit = fit_segments(&p, &[2.5e-3], &tol).unwrap();
        assert_eq!(fit.table.segments.len(), 2);
        check_fit(&p, &[2.5e-3], &fit, &tol);
    }
}

fn optimal_case(name: &str, case: (f64, f64), switches: usize, max_segments: usize) {
    let traj = optimal(case, 20.0);
    assert_eq!(traj.switches.len(), switches);
    let breaks: Vec<f64> = traj.switches.iter().map(|s| s.t).collect();
    let tol = SegmentTolerance::default();
    let fit = fit_segments(&traj, &breaks, &tol).unwrap_or_else(|e| panic!("{e}"));
    report(name, &traj, &fit);
    check_fit(&traj, &breaks, &fit, &tol);
    assert!(
        fit.table.segments.len() <= max_segments,
        "{} segments",
        fit.table.segments.len()
    );
    // without the breaks it still converges (the kinks cost a few bisections)
    let plain = fit_segments(&traj, &[], &tol).unwrap_or_else(|e| panic!("{e}"));
    report(&format!("{name} without breaks"), &traj, &plain);
    check_fit(&traj, &[], &plain, &tol);
}

#[test]
fn energy_optimal_closing_at_20_volts() {
    optimal_case("closing ±20 V", CLOSING, 1, 80);
}

#[test]
fn energy_optimal_opening_at_20_volts() {
    optimal_case("opening ±20 V", OPENING, 2, 80);
}

#[test]
fn an_absurd_tolerance_names_the_worst_time() {
    let p = Polynomial {
        z0: 1e-3,
        zf: 0.0,
        t0: T0,
        tf: TF,
    };
    // a sine is no quintic: 1e-30 m cannot be met in 50 segments
    struct Sine;
    impl Reference for Sine {
        fn at(&self, t: f64) -> Flat {
            let w = 2.0 * std::f64::consts::PI / (TF - T0);
            let s = w * (t - T0);
            Flat {
                z: 1e-3 * s.sin(),
                v: 1e-3 * w * s.cos(),
                a: -1e-3 * w * w * s.sin(),
                jerk: -1e-3 * w * w * w * s.cos(),
            }
        }
        fn motion(&self) -> (f64, f64) {
            (T0, TF)
        }
    }
    let tol = SegmentTolerance {
        z: 1e-30,
        max_segments: 50,
        ..SegmentTolerance::default()
    };
    match fit_segments(&Sine, &[], &tol) {
        Err(e @ FitError::TooManySegments { .. }) => {
            let FitError::TooManySegments {
                segments,
                max_segments,
                t,
                error,
                allowed,
                ..
            } = e.clone()
            else {
                unreachable!()
            };
            println!("{e}");
            assert!(segments > max_segments && max_segments == 50);
            assert!(t > T0 && t < TF, "{t}");
            assert!(error > allowed && allowed > 0.0);
            assert!(e.to_string().contains("at t = "));
        }
        other => panic!("{other:?}"),
    }
    // 1e-30 m is below rounding: even the exact one-segment polynomial fails
    assert!(matches!(
        fit_segments(&p, &[], &tol),
        Err(FitError::TooManySegments { .. })
    ));
}

/// A step in position at 3 ms (not a motion, but a source that no table
/// resolves without a knot there).
struct Step;
const STEP: f64 = 3e-3;
impl Reference for Step {
    fn at(&self, t: f64) -> Flat {
        Flat {
            z: if t < STEP { 1e-3 } else { 0.0 },
            v: 0.0,
            a: 0.0,
            jerk: 0.0,
        }
    }
    fn motion(&self) -> (f64, f64) {
        (T0, TF)
    }
}

#[test]
fn a_discontinuity_needs_a_forced_break() {
    let tol = SegmentTolerance::default();
    match fit_segments(&Step, &[], &tol) {
        Err(e @ FitError::Unresolved { .. }) => {
            println!("{e}");
            let FitError::Unresolved { t, signal, .. } = e else {
                unreachable!()
            };
            assert_eq!(signal, Signal::Z);
            assert!((t - STEP).abs() < 1e-12, "{t}");
        }
        other => panic!("{other:?}"),
    }
    // with a break at the step: two exact segments, the jump reported
    let fit = fit_segments(&Step, &[STEP], &tol).unwrap();
    assert_eq!(fit.table.segments.len(), 2);
    assert_eq!(fit.errors.max.z, 0.0);
}

#[test]
fn invalid_input_is_reported() {
    let p = Polynomial {
        z0: 1e-3,
        zf: 0.0,
        t0: T0,
        tf: TF,
    };
    let tol = SegmentTolerance::default();
    for (breaks, tol) in [
        (vec![7e-3], tol),
        (vec![f64::NAN], tol),
        (vec![], SegmentTolerance { a: 0.0, ..tol }),
        (vec![], SegmentTolerance { samples: 1, ..tol }),
        (
            vec![2e-3, 3e-3],
            SegmentTolerance {
                max_segments: 2,
                ..tol
            },
        ),
    ] {
        assert!(
            matches!(fit_segments(&p, &breaks, &tol), Err(FitError::Invalid(_))),
            "{breaks:?} {tol:?}"
        );
    }
    let empty = Polynomial { tf: T0, ..p };
    assert!(matches!(
        fit_segments(&empty, &[], &tol),
        Err(FitError::Invalid(_))
    ));
    // breaks at the ends or repeated are merged
    let fit = fit_segments(&p, &[T0, TF, 3e-3, 3e-3], &tol).unwrap();
    assert_eq!(fit.table.segments.len(), 2);
}
