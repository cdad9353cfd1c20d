//! The probability-based energy-optimal reference (`[trajectory]
//! contact_uncertainty`; Moya-Lasheras, Ramirez-Laboreo, Sagues, IEEE TCST
//! 2020) on the perfect-tracking valve, closing and opening in [1 ms, 6 ms]
//! with stops spread σ = 10 µm (1 % of the stroke) into the stroke:
//! - σ = 0, written or not, is the deterministic reference bit for bit;
//! - the robust optimum: converged, at rest at both ends, within the bounds,
//!   H constant (Pontryagin, autonomous model), its cost J = ∫u² + W·E[v_c²]
//!   below the deterministic reference's J (it minimises J), its expected and
//!   worst contact speeds below the deterministic reference's, at the price of
//!   more energy;
//! - the contact figures of a reference against a closed form.
//!
//! The scipy oracle of the optimum's J: `tests/oracle/check_robust.py`
//! (`cli/tests/oracles.rs`).

use designer::description::{parse_file, parse_str, Operation};
use designer::design::{
    contact_figures, design_reference, energy_optimal, Linearization, OptimalSpec, Polynomial,
};
use designer::model::Model;
use support::example_path;

const T0: f64 = 1e-3;
const TF: f64 = 6e-3;
const SIGMA: f64 = 10e-6;

#[test]
fn zero_uncertainty_is_the_deterministic_reference_bit_for_bit() {
    let path = example_path("perfect-tracking-valve.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let zero = text.replace(
        "u_bound = 20.0\n",
        "u_bound = 20.0\ncontact_uncertainty = 0.0\n",
    );
    assert_ne!(zero, text);
    let a = parse_file(&path).unwrap();
    let b = parse_str(&zero, "zero.toml").unwrap_or_else(|e| panic!("{e}"));
    let (mut ma, mut mb) = (Model::build(&a), Model::build(&b));
    let (la, lb) = (
        Linearization::derive(&mut ma).unwrap(),
        Linearization::derive(&mut mb).unwrap(),
    );
    let (_, oa) = design_reference(&a, &mut ma, &la, Operation::Closing).unwrap();
    let (_, ob) = design_reference(&b, &mut mb, &lb, Operation::Closing).unwrap();
    let (oa, ob) = (oa.unwrap(), ob.unwrap());
    assert!(oa.contact.is_none() && ob.contact.is_none());
    assert_eq!(oa.summary_json(), ob.summary_json());
    assert_eq!(oa.states, ob.states);
    assert_eq!(oa.costates, ob.costates);
    assert_eq!(oa.t, ob.t);
}

fn robust((z0, zf): (f64, f64)) {
    let d = parse_file(&example_path("uncertain-stop-valve.toml")).unwrap();
    let mut m = Model::build(&d);
    let lin = Linearization::derive(&mut m).unwrap();
    let spec = OptimalSpec {
        contact_uncertainty: SIGMA,
        ..OptimalSpec::new(z0, zf, T0, TF, -20.0, 20.0)
    };
    let traj = energy_optimal(&mut m, &lin, &spec).unwrap_or_else(|e| panic!("{e}"));
    let c = traj.contact.clone().expect("the contact design");
    assert!(traj.max_residual <= spec.tol, "{}", traj.max_residual);
    let last = *traj.states.last().unwrap();
    assert!((last[0] - traj.xf[0]).abs() <= 1e-12 && last[1].abs() <= 1e-9);
    assert!(traj.max_abs_input <= 20.0 * (1.0 + 1e-9));
    // Pontryagin: H = u² + W·ρ|v|³ + pᵀf is constant along the arc
    let h = &traj.hamiltonian;
    let (lo, hi) = h
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let scale = h.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!((hi - lo) <= 1e-3 * scale, "H spread {} of {scale}", hi - lo);
    // the robust reference minimises J: the deterministic one costs more
    assert!(c.cost < c.deterministic_cost, "{c:?}");
    // and it pays for it in energy
    assert!(traj.cost > c.deterministic_energy, "{c:?}");
    let (r, q) = (c.robust, c.deterministic);
    assert!(r.expected_speed < 0.75 * q.expected_speed, "{c:?}");
    assert!(
        r.rms_speed < q.rms_speed && r.worst_speed < q.worst_speed,
        "{c:?}"
    );
    assert!(r.speed_at[0] < 0.6 * q.speed_at[0], "{c:?}");
    assert!(r.speed_at[1] < q.speed_at[1], "{c:?}");
    println!("{}", traj.summary_json());
}

#[test]
fn robust_closing_lands_softer_over_the_stops() {
    robust((1e-3, 0.0));
}

#[test]
fn robust_opening_lands_softer_over_the_stops() {
    robust((0.0, 1e-3));
}

/// The quintic polynomial: z = z₀ + (z_f − z₀)·s(τ), v = (z_f − z₀)/T·30τ²(1 − τ)²:
/// the speed where the motion is d from the stop, at 1 − s(τ) = d/stroke.
#[test]
fn contact_figures_of_the_polynomial_match_the_closed_form() {
    let p = Polynomial {
        z0: 1e-3,
        zf: 0.0,
        t0: T0,
        tf: TF,
    };
    let (f, e2) = contact_figures(&p, p.z0, p.zf, SIGMA);
    let stroke = 1e-3;
    // the speed where 1 − s(τ) = d/stroke, τ by bisection
    let at = |d: f64| {
        let s = |t: f64| t * t * t * (10.0 + t * (-15.0 + 6.0 * t));
        let (mut a, mut b) = (0.5, 1.0);
        for _ in 0..100 {
            let m = 0.5 * (a + b);
            if 1.0 - s(m) > d / stroke {
                a = m;
            } else {
                b = m;
            }
        }
        let t = 0.5 * (a + b);
        30.0 / (TF - T0) * stroke * t * t * (1.0 - t) * (1.0 - t)
    };
    for k in 0..3 {
        let d = (k + 1) as f64 * SIGMA;
        let rel = (f.speed_at[k] - at(d)).abs() / at(d);
        assert!(rel < 1e-6, "at {d:e}: {} vs {}", f.speed_at[k], at(d));
    }
    assert!((f.worst_speed - f.speed_at[2]).abs() <= 1e-3 * f.worst_speed);
    // E[v²] ≥ E[v]² (Jensen), both positive
    assert!(e2 >= f.expected_speed.powi(2) && f.expected_speed > 0.0);
}
