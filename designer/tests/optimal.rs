//! Energy-optimal trajectory (perfect-tracking-soft-landing §4, eqs. 58–66) on
//! the paper's valve, closing (1 → 0 mm) and opening (0 → 1 mm) in
//! [1 ms, 6 ms]:
//! - convergence, boundary conditions, bounds on u;
//! - the state re-integrated by RK4 with u*(t) from the interpolant reaches x(t_f);
//! - Pontryagin: H(x*, p*, u*) is constant (autonomous model);
//! - optimality: J ≤ ∫u_r² of the polynomial whenever the polynomial is
//!   feasible; with loose bounds there is no saturation;
//! - the scipy/CasADi oracle's figures (tests/oracle/check_optimal.py).

use designer::description::parse_file;
use designer::design::{
    energy_optimal, Linearization, OptimalError, OptimalSpec, OptimalTrajectory, Reference,
};
use designer::model::Model;
use support::{assert_close, example_path, Tol};

fn model(file: &str) -> Model {
    Model::build(&parse_file(&example_path(file)).unwrap_or_else(|e| panic!("{e}")))
}

/// Agreement with the oracle's figures.
const ORACLE: Tol = Tol::rel(1e-6);

const T0: f64 = 1e-3;
const TF: f64 = 6e-3;
const CLOSING: (f64, f64) = (1e-3, 0.0);
const OPENING: (f64, f64) = (0.0, 1e-3);

fn solve((z0, zf): (f64, f64), bound: f64) -> (Model, OptimalTrajectory) {
    let mut m = model("perfect-tracking-valve.toml");
    let lin = Linearization::derive(&mut m).unwrap();
    let spec = OptimalSpec::new(z0, zf, T0, TF, -bound, bound);
    let traj = energy_optimal(&mut m, &lin, &spec).unwrap_or_else(|e| panic!("{e}"));
    (m, traj)
}

/// Every check that does not depend on the figures.
fn check_solution(m: &mut Model, traj: &OptimalTrajectory, bound: f64) {
    let spec = &traj.spec;
    assert!(traj.max_residual <= spec.tol, "{}", traj.max_residual);
    // boundary conditions (x0, xf from T⁻¹: rest with a = 0)
    let (first, last) = (traj.states[0], *traj.states.last().unwrap());
    let scale = [1e-3, 0.4, 1e-5];
    for k in 0..3 {
        assert!(
            (first[k] - traj.x0[k]).abs() <= 1e-9 * scale[k],
            "x(t0) {first:?}"
        );
        assert!(
            (last[k] - traj.xf[k]).abs() <= 1e-9 * scale[k],
            "x(tf) {last:?}"
        );
    }
    assert_eq!((traj.x0[0], traj.xf[0]), (spec.z0, spec.zf));
    assert_eq!((traj.x0[1], traj.xf[1]), (0.0, 0.0));
    // rest: the acceleration vanishes at the ends
    for r in [traj.reference[0], *traj.reference.last().unwrap()] {
        assert!(r.a.abs() < 1e-6, "{r:?}");
    }
    // bounds, also between nodes
    assert!(traj.max_abs_input <= bound * (1.0 + 1e-12));
    for k in 0..=1000 {
        let u = traj.input_at(T0 + (TF - T0) * k as f64 / 1000.0);
        assert!(u >= spec.u_min - 1e-12 && u <= spec.u_max + 1e-12, "{u}");
    }
    // Pontryagin: H constant along the solution (nodes and interpolant)
    let h0 = traj.hamiltonian[0];
    let spread = traj
        .hamiltonian
        .iter()
        .map(|h| (h - h0).abs())
        .fold(0.0, f64::max);
    assert!(spread <= 1e-7 * h0.abs(), "H spread {spread:e} of {h0:e}");
    for k in 0..200 {
        let h = traj.hamiltonian_at(T0 + (TF - T0) * (k as f64 + 0.5) / 200.0);
        assert_close(h, h0, Tol::rel(1e-5), "H");
    }
    // ẋ = f(x, u*): RK4 with u*(t) from the interpolant, from x0
    let f = m.compile(&m.f.clone());
    let mut s = f.scratch();
    let mut rate = |t: f64, x: [f64; 3]| {
        let mut o = [0.0; 3];
        f.eval(&[x[0], x[1], x[2], traj.input_at(t), t], &mut s, &mut o);
        o
    };
    let n = 20000;
    let h = (TF - T0) / n as f64;
    let mut x = traj.x0;
    let mut worst = [0.0f64; 3];
    for i in 0..n {
        let t = T0 + i as f64 * h;
        let k1 = rate(t, x);
        let at = |k: [f64; 3], c: f64| [x[0] + c * k[0], x[1] + c * k[1], x[2] + c * k[2]];
        let k2 = rate(t + h / 2.0, at(k1, h / 2.0));
        let k3 = rate(t + h / 2.0, at(k2, h / 2.0));
        let k4 = rate(t + h, at(k3, h));
        for q in 0..3 {
            x[q] += h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q]);
        }
        if i % 100 == 99 {
            let y = traj.y_at(t + h);
            for q in 0..3 {
                worst[q] = worst[q].max((x[q] - y[q]).abs() / scale[q]);
            }
        }
    }
    assert!(
        worst.iter().all(|&w| w < 1e-5),
        "RK4 vs collocation {worst:?}"
    );
    // the reference: z, v from the state, a = T₃(x) = v̇ and jerk = ȧ
    for k in 1..50 {
        let t = T0 + (TF - T0) * k as f64 / 50.0;
        let d = 1e-7;
        let (rm, r0, rp) = (traj.at(t - d), traj.at(t), traj.at(t + d));
        assert!(
            ((rp.v - rm.v) / (2.0 * d) - r0.a).abs() < 1e-4 * 100.0,
            "a at {t}"
        );
        let jd = (rp.a - rm.a) / (2.0 * d);
        assert!(
            (jd - r0.jerk).abs() < 1e-3 * r0.jerk.abs().max(1e5),
            "jerk at {t}: {jd} vs {}",
            r0.jerk
        );
    }
}

// Oracle figures: `python3 tests/oracle/check_optimal.py
// examples/perfect-tracking-valve.toml` (scipy 1.17.1 solve_bvp + CasADi 3.8.2
// Jacobians, tol 1e-6, same guess construction, written independently):
//   closing ±20 V:   J = 1.00442170647,  max|u| = 20,          switch 3.051155813 ms (leaves +20 V), 559 nodes
//   closing ±1000 V: J = 0.810542876669, max|u| = 33.32169025, no switch,                             421 nodes
//   opening ±20 V:   J = 0.926455240668, max|u| = 20,          switches 4.15341775 ms (enters +20 V),
//                                                              5.680241231 ms (leaves),                582 nodes
//   opening ±1000 V: J = 0.903729726194, max|u| = 24.15732834, no switch,                             421 nodes
//   polynomial guess: closing ∫u_r² = 0.8473778041 (max|u_r| 24.5548 V),
//                     opening ∫u_r² = 0.9410590795 (max|u_r| 21.1608 V).

#[test]
fn closing_with_20_volt_bounds_saturates_at_the_start() {
    let (mut m, traj) = solve(CLOSING, 20.0);
    check_solution(&mut m, &traj, 20.0);
    assert_close(traj.cost, 1.00442170647, ORACLE, "J");
    assert_close(traj.guess_cost, 0.8473778041, ORACLE, "J of the polynomial");
    // the polynomial violates ±20 V (24.55 V), so it is no competitor here
    assert!(traj.guess_max_abs_input > 20.0);
    assert_eq!(traj.max_abs_input, 20.0);
    assert_eq!(traj.switches.len(), 1, "{:?}", traj.switches);
    let s = traj.switches[0];
    assert!((s.t - 3.051155813e-3).abs() < 1e-9 && s.bound == 20.0 && !s.entering);
    assert_eq!(traj.input[0], 20.0);
}

#[test]
fn opening_with_20_volt_bounds_has_one_saturated_arc() {
    let (mut m, traj) = solve(OPENING, 20.0);
    check_solution(&mut m, &traj, 20.0);
    assert_close(traj.cost, 0.926455240668, ORACLE, "J");
    assert!(traj.cost < traj.guess_cost);
    assert_eq!(traj.max_abs_input, 20.0);
    let t: Vec<(f64, bool)> = traj.switches.iter().map(|s| (s.t, s.entering)).collect();
    assert_eq!(t.len(), 2, "{t:?}");
    assert!((t[0].0 - 4.15341775e-3).abs() < 1e-9 && t[0].1);
    assert!((t[1].0 - 5.680241231e-3).abs() < 1e-9 && !t[1].1);
}

#[test]
fn loose_bounds_do_not_saturate_and_beat_the_polynomial() {
    for (case, j, umax) in [
        (CLOSING, 0.810542876669, 33.32169025),
        (OPENING, 0.903729726194, 24.15732834),
    ] {
        let (mut m, traj) = solve(case, 1000.0);
        check_solution(&mut m, &traj, 1000.0);
        assert!(traj.switches.is_empty());
        assert!(
            traj.cost < traj.guess_cost,
            "{} vs {}",
            traj.cost,
            traj.guess_cost
        );
        assert_close(traj.cost, j, ORACLE, "J");
        assert_close(traj.max_abs_input, umax, ORACLE, "max |u|");
    }
}

#[test]
fn beats_the_polynomial_when_the_polynomial_is_feasible() {
    // ±25 V admits the polynomial (max|u_r| = 24.55 / 21.16 V)
    for case in [CLOSING, OPENING] {
        let (_, traj) = solve(case, 25.0);
        assert!(traj.guess_max_abs_input <= 25.0);
        assert!(
            traj.cost < traj.guess_cost,
            "{} vs {}",
            traj.cost,
            traj.guess_cost
        );
        assert!(traj.max_abs_input <= 25.0);
    }
}

#[test]
fn infeasible_boundary_and_invalid_spec_are_reported() {
    let mut m = model("perfect-tracking-valve.toml");
    let lin = Linearization::derive(&mut m).unwrap();
    // beyond z = −2·F0/k_s = 15 mm the spring cannot be held by any flux
    let spec = OptimalSpec::new(1e-3, 0.02, T0, TF, -20.0, 20.0);
    match energy_optimal(&mut m, &lin, &spec) {
        Err(OptimalError::InfeasibleBoundary { which: "final", .. }) => {}
        other => panic!("{other:?}"),
    }
    let spec = OptimalSpec::new(1e-3, 0.0, TF, T0, -20.0, 20.0);
    assert!(matches!(
        energy_optimal(&mut m, &lin, &spec),
        Err(OptimalError::InvalidSpec(_))
    ));
    let spec = OptimalSpec::new(1e-3, 0.0, T0, TF, 20.0, -20.0);
    assert!(matches!(
        energy_optimal(&mut m, &lin, &spec),
        Err(OptimalError::InvalidSpec(_))
    ));
}

/// Prints reldesign's summaries for tests/oracle/check_optimal.py --rust.
#[test]
#[ignore]
fn export_optimal_json() {
    for (name, case) in [("closing", CLOSING), ("opening", OPENING)] {
        for bound in [20.0, 1000.0] {
            let start = std::time::Instant::now();
            let (_, traj) = solve(case, bound);
            let mut j = traj.summary_json();
            j["case"] = name.into();
            j["bound"] = bound.into();
            j["seconds"] = start.elapsed().as_secs_f64().into();
            println!("OPTIMAL_JSON {j}");
        }
    }
}

/// Discretisation study (not a check): J at tol 1e-6 vs 1e-7.
#[test]
#[ignore]
fn tol_study() {
    for case in [CLOSING, OPENING] {
        let mut m = model("perfect-tracking-valve.toml");
        let lin = Linearization::derive(&mut m).unwrap();
        let mut spec = OptimalSpec::new(case.0, case.1, T0, TF, -20.0, 20.0);
        let a = energy_optimal(&mut m, &lin, &spec).unwrap();
        spec.tol = 1e-7;
        spec.max_nodes = 50000;
        let b = match energy_optimal(&mut m, &lin, &spec) {
            Ok(b) => b,
            Err(e) => {
                println!("tol 1e-7: {e}");
                continue;
            }
        };
        println!(
            "tol 1e-6 J {} nodes {}; tol 1e-7 J {} nodes {} rel {:e}",
            a.cost,
            a.nodes(),
            b.cost,
            b.nodes(),
            (a.cost - b.cost).abs() / b.cost
        );
    }
}
