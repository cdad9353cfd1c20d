//! The collocation BVP solver against problems with known solutions.

use designer::design::{
    jacobian_discrepancy, solve_bvp, solve_collocation, BvpError, BvpOptions, BvpProblem,
};
use std::f64::consts::FRAC_PI_2;

/// Dirichlet conditions: (component, value) pairs.
type Pins<const K: usize> = [(usize, f64); K];

fn linspace(a: f64, b: f64, m: usize) -> Vec<f64> {
    (0..m)
        .map(|i| a + (b - a) * i as f64 / (m - 1) as f64)
        .collect()
}

/// Dirichlet conditions y_k(a) = ya[k] for k in `left`, y_k(b) = yb[k] for k in `right`.
fn dirichlet(left: &[(usize, f64)], right: &[(usize, f64)], ya: &[f64], yb: &[f64], r: &mut [f64]) {
    for (q, &(k, v)) in left.iter().enumerate() {
        r[q] = ya[k] - v;
    }
    for (q, &(k, v)) in right.iter().enumerate() {
        r[left.len() + q] = yb[k] - v;
    }
}

fn dirichlet_jac(
    n: usize,
    left: &[(usize, f64)],
    right: &[(usize, f64)],
    ja: &mut [f64],
    jb: &mut [f64],
) {
    ja.iter_mut().for_each(|v| *v = 0.0);
    jb.iter_mut().for_each(|v| *v = 0.0);
    for (q, &(k, _)) in left.iter().enumerate() {
        ja[q * n + k] = 1.0;
    }
    for (q, &(k, _)) in right.iter().enumerate() {
        jb[(left.len() + q) * n + k] = 1.0;
    }
}

// --- y'' = −y, y(0) = 0, y(π/2) = 1: y = sin t -----------------------------

struct Harmonic;

impl BvpProblem for Harmonic {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = -y[0];
    }
    fn jacobian(&self, _t: f64, _y: &[f64], j: &mut [f64]) {
        j.copy_from_slice(&[0.0, 1.0, -1.0, 0.0]);
    }
    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]) {
        dirichlet(&[(0, 0.0)], &[(0, 1.0)], ya, yb, r);
    }
    fn bc_jacobian(&self, _ya: &[f64], _yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        dirichlet_jac(2, &[(0, 0.0)], &[(0, 1.0)], ja, jb);
    }
}

fn sin_error(t: &[f64], y: &[Vec<f64>]) -> f64 {
    t.iter()
        .zip(y)
        .map(|(t, y)| (y[0] - t.sin()).abs().max((y[1] - t.cos()).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn linear_problem_matches_sine_within_tolerance() {
    let t = linspace(0.0, FRAC_PI_2, 5);
    let guess = vec![vec![0.0, 0.0]; 5];
    for tol in [1e-3, 1e-6] {
        let opts = BvpOptions {
            tol,
            ..BvpOptions::default()
        };
        let sol = solve_bvp(&Harmonic, &t, &guess, &opts).unwrap();
        assert!(sol.max_residual <= tol, "{sol:?}");
        assert!(sol.bc_residual <= tol);
        let err = sin_error(&sol.t, &sol.y);
        assert!(err < tol, "tol {tol}: nodal error {err}");
        // The interpolant, between the nodes, too.
        for s in linspace(0.0, FRAC_PI_2, 97) {
            let (y, dy) = sol.eval_with(s);
            assert!((y[0] - s.sin()).abs() < 2.0 * tol, "S({s})");
            assert!((dy[0] - s.cos()).abs() < 10.0 * tol, "S'({s})");
        }
    }
}

#[test]
fn collocation_is_fourth_order_under_uniform_refinement() {
    let mut errs = vec![];
    for m in [5, 9, 17, 33, 65] {
        let t = linspace(0.0, FRAC_PI_2, m);
        let guess = vec![vec![0.0, 0.0]; m];
        let opts = BvpOptions {
            tol: 1e-12,
            ..BvpOptions::default()
        };
        let sol = solve_collocation(&Harmonic, &t, &guess, &opts).unwrap();
        assert_eq!(sol.t, t, "fixed mesh");
        errs.push(sin_error(&sol.t, &sol.y));
    }
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(
            (3.7..4.4).contains(&order),
            "errors {errs:?}: order {order}"
        );
    }
}

// --- Bratu: y'' + λ eʸ = 0, y(0) = y(1) = 0 ----------------------------------

struct Bratu {
    lambda: f64,
}

impl BvpProblem for Bratu {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = -self.lambda * y[0].exp();
    }
    fn jacobian(&self, _t: f64, y: &[f64], j: &mut [f64]) {
        j.copy_from_slice(&[0.0, 1.0, -self.lambda * y[0].exp(), 0.0]);
    }
    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]) {
        dirichlet(&[(0, 0.0)], &[(0, 0.0)], ya, yb, r);
    }
    fn bc_jacobian(&self, _ya: &[f64], _yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        dirichlet_jac(2, &[(0, 0.0)], &[(0, 0.0)], ja, jb);
    }
}

/// Exact Bratu solution y = −2 ln(cosh((t − ½)θ/2)/cosh(θ/4)) with
/// θ = √(2λ) cosh(θ/4), the root near `theta0`.
fn bratu_exact(lambda: f64, theta0: f64) -> impl Fn(f64) -> f64 {
    let mut th = theta0;
    for _ in 0..100 {
        let g = th - (2.0 * lambda).sqrt() * (th / 4.0).cosh();
        let dg = 1.0 - (2.0 * lambda).sqrt() * (th / 4.0).sinh() / 4.0;
        th -= g / dg;
    }
    move |t| -2.0 * (((t - 0.5) * th / 2.0).cosh() / (th / 4.0).cosh()).ln()
}

#[test]
fn bratu_has_two_solutions_from_two_guesses() {
    let bratu = Bratu { lambda: 1.0 };
    let t = linspace(0.0, 1.0, 5);
    let opts = BvpOptions {
        tol: 1e-6,
        ..BvpOptions::default()
    };
    for (guess0, slope, theta0) in [(0.0, 0.549352, 1.5), (3.0, 10.8469, 11.0)] {
        let guess: Vec<Vec<f64>> = t.iter().map(|_| vec![guess0, 0.0]).collect();
        let sol = solve_bvp(&bratu, &t, &guess, &opts).unwrap();
        let dy0 = sol.y[0][1];
        assert!(
            ((dy0 - slope) / slope).abs() < 2e-5,
            "guess {guess0}: y'(0) = {dy0}, literature {slope}"
        );
        let exact = bratu_exact(1.0, theta0);
        for (t, y) in sol.t.iter().zip(&sol.y) {
            assert!((y[0] - exact(*t)).abs() < 1e-5 * (1.0 + exact(0.5)));
        }
    }
}

// --- Boundary layer: ε y'' = y', y(0) = 0, y(1) = 1 --------------------------

struct Layer {
    eps: f64,
}

impl BvpProblem for Layer {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = y[1] / self.eps;
    }
    fn jacobian(&self, _t: f64, _y: &[f64], j: &mut [f64]) {
        j.copy_from_slice(&[0.0, 1.0, 0.0, 1.0 / self.eps]);
    }
    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]) {
        dirichlet(&[(0, 0.0)], &[(0, 1.0)], ya, yb, r);
    }
    fn bc_jacobian(&self, _ya: &[f64], _yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        dirichlet_jac(2, &[(0, 0.0)], &[(0, 1.0)], ja, jb);
    }
}

#[test]
fn boundary_layer_gets_the_nodes() {
    let eps = 1e-3;
    let t = linspace(0.0, 1.0, 11);
    let guess: Vec<Vec<f64>> = t.iter().map(|&t| vec![t, 1.0]).collect();
    let opts = BvpOptions {
        tol: 1e-4,
        max_nodes: 5000,
        ..BvpOptions::default()
    };
    let sol = solve_bvp(&Layer { eps }, &t, &guess, &opts).unwrap();
    // y = (e^{(t−1)/ε} − e^{−1/ε})/(1 − e^{−1/ε})
    let exact =
        |t: f64| (((t - 1.0) / eps).exp() - (-1.0 / eps).exp()) / (1.0 - (-1.0 / eps).exp());
    let err = sol
        .t
        .iter()
        .zip(&sol.y)
        .map(|(&t, y)| (y[0] - exact(t)).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-3, "max nodal error {err}");
    let in_layer = sol.t.iter().filter(|&&t| t >= 1.0 - 10.0 * eps).count();
    let density_in = in_layer as f64 / (10.0 * eps);
    let density_out = (sol.t.len() - in_layer) as f64 / (1.0 - 10.0 * eps);
    assert!(
        density_in > 20.0 * density_out,
        "{in_layer} of {} nodes in the layer (1% of the interval)",
        sol.t.len()
    );
    // scipy's solve_bvp with the same data (tests/oracle/bvp_reference.py):
    // 210 nodes, 49 in the layer, 8 passes. Same algorithm, same mesh.
    assert!(sol.t.len().abs_diff(210) <= 10, "{} nodes", sol.t.len());
    assert!(sol.mesh_refinements > 1);
}

// --- min ∫u², x'' = u, |u| ≤ U: Pontryagin with a saturated input ------------

/// y = [x, v, p1, p2]; H = u² + p1 v + p2 u; u* = clamp(−p2/2, −U, U);
/// p1' = 0, p2' = −p1.
struct SaturatedDoubleIntegrator {
    umax: f64,
}

impl SaturatedDoubleIntegrator {
    fn u(&self, p2: f64) -> (f64, f64) {
        let u = -p2 / 2.0;
        if u > self.umax {
            (self.umax, 0.0)
        } else if u < -self.umax {
            (-self.umax, 0.0)
        } else {
            (u, -0.5)
        }
    }
}

const DI_BC: (Pins<2>, Pins<2>) = ([(0, 0.0), (1, 0.0)], [(0, 1.0), (1, 0.0)]);

impl BvpProblem for SaturatedDoubleIntegrator {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = self.u(y[3]).0;
        dy[2] = 0.0;
        dy[3] = -y[2];
    }
    fn jacobian(&self, _t: f64, y: &[f64], j: &mut [f64]) {
        j.iter_mut().for_each(|v| *v = 0.0);
        j[1] = 1.0;
        j[4 + 3] = self.u(y[3]).1;
        j[3 * 4 + 2] = -1.0;
    }
    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]) {
        dirichlet(&DI_BC.0, &DI_BC.1, ya, yb, r);
    }
    fn bc_jacobian(&self, _ya: &[f64], _yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        dirichlet_jac(4, &DI_BC.0, &DI_BC.1, ja, jb);
    }
}

#[test]
fn unsaturated_double_integrator_is_the_cubic() {
    let p = SaturatedDoubleIntegrator { umax: 100.0 };
    assert!(jacobian_discrepancy(&p, 0.3, &[0.1, 0.2, -3.0, 1.0]) < 1e-6);
    let t = linspace(0.0, 1.0, 11);
    let guess = vec![vec![0.0; 4]; 11];
    let sol = solve_bvp(&p, &t, &guess, &BvpOptions::default()).unwrap();
    for s in linspace(0.0, 1.0, 21) {
        let y = sol.eval(s);
        let x = 3.0 * s * s - 2.0 * s * s * s;
        assert!((y[0] - x).abs() < 1e-9, "x({s}) = {} vs {x}", y[0]);
        assert!((y[2] + 24.0).abs() < 1e-8, "p1 = {}", y[2]);
        let u = p.u(y[3]).0;
        assert!((u - (6.0 - 12.0 * s)).abs() < 1e-8, "u({s}) = {u}");
    }
}

/// Analytic solution for 4 < U < 6 (derived by hand): by symmetry u is odd
/// about t = ½, u = clamp(c(½ − t), −U, U); x(1) = ∫(½ − t)u dt = U/4 − U a²/3
/// = 1 with a = U/c gives a² = 3/4 − 3/U; switches at ½ ∓ a, p1 = −2c.
#[test]
fn saturated_double_integrator_switches_where_the_analysis_says() {
    let umax = 4.5;
    let p = SaturatedDoubleIntegrator { umax };
    let a = (0.75 - 3.0 / umax).sqrt();
    let c = umax / a;
    let (tau1, tau2) = (0.5 - a, 0.5 + a);
    let t = linspace(0.0, 1.0, 11);
    let guess = vec![vec![0.0; 4]; 11];
    let opts = BvpOptions {
        tol: 1e-6,
        ..BvpOptions::default()
    };
    let sol = solve_bvp(&p, &t, &guess, &opts).unwrap();
    assert!(sol.max_residual <= 1e-6);
    // scipy's solve_bvp on the same problem (tests/oracle/bvp_reference.py):
    // 49 nodes, p1 = −31.17691453.
    assert!(sol.t.len().abs_diff(49) <= 3, "{} nodes", sol.t.len());
    // Switching times: where −p2/2 crosses ±U (bisection on the interpolant).
    let g = |s: f64, level: f64| -sol.eval(s)[3] / 2.0 - level;
    let root = |mut lo: f64, mut hi: f64, level: f64| {
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if g(lo, level).signum() == g(mid, level).signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let s1 = root(0.0, 0.5, umax);
    let s2 = root(0.5, 1.0, -umax);
    assert!((s1 - tau1).abs() < 1e-4, "τ1 = {s1}, analytic {tau1}");
    assert!((s2 - tau2).abs() < 1e-4, "τ2 = {s2}, analytic {tau2}");
    assert!(
        (sol.y[0][2] + 2.0 * c).abs() < 1e-4 * c,
        "p1 = {}",
        sol.y[0][2]
    );
    // State on the first saturated arc and at the centre.
    let y1 = sol.eval(tau1);
    assert!((y1[0] - umax * tau1 * tau1 / 2.0).abs() < 1e-6);
    assert!((y1[1] - umax * tau1).abs() < 1e-6);
    assert!((sol.eval(0.5)[0] - 0.5).abs() < 1e-6);
}

// --- 6 states of very different magnitudes -----------------------------------

/// z' = v, v' = k φ, φ' = u; min ∫u², |u| ≤ U; z: 0 → Z, v, φ zero at both ends.
/// Unsaturated, z is the quintic Z(10s³ − 15s⁴ + 6s⁵), s = t/T.
struct TripleIntegrator {
    k: f64,
    umax: f64,
    z_end: f64,
}

impl TripleIntegrator {
    fn u(&self, p3: f64) -> (f64, f64) {
        let u = -p3 / 2.0;
        if u.abs() > self.umax {
            (u.signum() * self.umax, 0.0)
        } else {
            (u, -0.5)
        }
    }
    fn bc_lists(&self) -> (Pins<3>, Pins<3>) {
        (
            [(0, 0.0), (1, 0.0), (2, 0.0)],
            [(0, self.z_end), (1, 0.0), (2, 0.0)],
        )
    }
}

impl BvpProblem for TripleIntegrator {
    fn dim(&self) -> usize {
        6
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = self.k * y[2];
        dy[2] = self.u(y[5]).0;
        dy[3] = 0.0;
        dy[4] = -y[3];
        dy[5] = -self.k * y[4];
    }
    fn jacobian(&self, _t: f64, y: &[f64], j: &mut [f64]) {
        j.iter_mut().for_each(|v| *v = 0.0);
        j[1] = 1.0;
        j[6 + 2] = self.k;
        j[2 * 6 + 5] = self.u(y[5]).1;
        j[4 * 6 + 3] = -1.0;
        j[5 * 6 + 4] = -self.k;
    }
    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]) {
        let (l, rr) = self.bc_lists();
        dirichlet(&l, &rr, ya, yb, r);
    }
    fn bc_jacobian(&self, _ya: &[f64], _yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        let (l, rr) = self.bc_lists();
        dirichlet_jac(6, &l, &rr, ja, jb);
    }
}

const T_END: f64 = 5e-3;
const SCALE: [f64; 6] = [1e-3, 0.3, 1e-5, 4e-3, 2e-5, 1.0];

fn triple_opts(tol: f64) -> BvpOptions {
    BvpOptions {
        tol,
        scale: Some(SCALE.to_vec()),
        bc_scale: Some(vec![1e-3, 0.3, 1e-5, 1e-3, 0.3, 1e-5]),
        max_nodes: 5000,
        ..BvpOptions::default()
    }
}

#[test]
fn scaled_six_state_problem_recovers_the_quintic() {
    let p = TripleIntegrator {
        k: 1e7,
        umax: 1.0,
        z_end: 1e-3,
    };
    let t = linspace(0.0, T_END, 21);
    let guess: Vec<Vec<f64>> = t
        .iter()
        .map(|&t| vec![1e-3 * t / T_END, 0.0, 0.0, 0.0, 0.0, 0.0])
        .collect();
    let sol = solve_bvp(&p, &t, &guess, &triple_opts(1e-6)).unwrap();
    for s in linspace(0.0, 1.0, 41) {
        let y = sol.eval(s * T_END);
        let z = 1e-3 * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
        let acc = 1e-3 / (T_END * T_END) * (60.0 * s - 180.0 * s * s + 120.0 * s * s * s);
        assert!((y[0] - z).abs() < 1e-6 * 1e-3, "z({s}) = {} vs {z}", y[0]);
        assert!(
            (y[2] - acc / p.k).abs() < 1e-5 * 1e-5,
            "φ({s}) = {} vs {}",
            y[2],
            acc / p.k
        );
    }
}

#[test]
fn scaled_six_state_saturated_problem_on_hundreds_of_nodes() {
    // Unconstrained max |u| is 60 Z/(k T³) = 0.048.
    let p = TripleIntegrator {
        k: 1e7,
        umax: 0.04,
        z_end: 1e-3,
    };
    let m = 500;
    let t = linspace(0.0, T_END, m);
    let guess: Vec<Vec<f64>> = t
        .iter()
        .map(|&t| vec![1e-3 * t / T_END, 0.0, 0.0, 0.0, 0.0, 0.0])
        .collect();
    let start = std::time::Instant::now();
    let sol = solve_bvp(&p, &t, &guess, &triple_opts(1e-6)).unwrap();
    let elapsed = start.elapsed();
    eprintln!(
        "6 states, {} → {} nodes: {:?}, {} Newton iterations, {} Jacobians, {} passes, {} f evaluations",
        m,
        sol.t.len(),
        elapsed,
        sol.newton_iterations,
        sol.jacobian_evaluations,
        sol.mesh_refinements,
        sol.rhs_evaluations
    );
    assert!(sol.max_residual <= 1e-6 && sol.bc_residual <= 1e-6);
    let y_end = sol.y.last().unwrap();
    assert!((y_end[0] - 1e-3).abs() < 1e-12);
    // The jerk of the quintic is largest (and positive) at both ends: u saturates
    // at +U there and never exceeds the bound.
    let u: Vec<f64> = sol.y.iter().map(|y| p.u(y[5]).0).collect();
    assert!((u[0] - 0.04).abs() < 1e-12 && (u.last().unwrap() - 0.04).abs() < 1e-12);
    assert!(u.iter().all(|u| u.abs() <= 0.04));
    // The cost can only grow when the bound is active.
    let cost = |sol: &designer::design::BvpSolution, p: &TripleIntegrator| {
        sol.t
            .windows(2)
            .zip(sol.y.windows(2))
            .map(|(t, y)| {
                let (u0, u1) = (p.u(y[0][5]).0, p.u(y[1][5]).0);
                0.5 * (t[1] - t[0]) * (u0 * u0 + u1 * u1)
            })
            .sum::<f64>()
    };
    let free = TripleIntegrator { umax: 1.0, ..p };
    let sol_free = solve_bvp(&free, &t, &guess, &triple_opts(1e-6)).unwrap();
    assert!(cost(&sol, &p) > cost(&sol_free, &free) * (1.0 + 1e-4));
}

// --- Errors ------------------------------------------------------------------

struct NanAfter {
    t_bad: f64,
}

impl BvpProblem for NanAfter {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        Harmonic.rhs(t, y, dy);
        if t > self.t_bad {
            dy[1] = f64::NAN;
        }
    }
    fn jacobian(&self, t: f64, y: &[f64], j: &mut [f64]) {
        Harmonic.jacobian(t, y, j);
    }
    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]) {
        Harmonic.bc(ya, yb, r);
    }
    fn bc_jacobian(&self, ya: &[f64], yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        Harmonic.bc_jacobian(ya, yb, ja, jb);
    }
}

/// Both conditions at t = a on y₀: the linearized BVP is singular.
struct BadBc;

impl BvpProblem for BadBc {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        Harmonic.rhs(t, y, dy);
    }
    fn jacobian(&self, t: f64, y: &[f64], j: &mut [f64]) {
        Harmonic.jacobian(t, y, j);
    }
    fn bc(&self, ya: &[f64], _yb: &[f64], r: &mut [f64]) {
        r[0] = ya[0];
        r[1] = 2.0 * ya[0] - 1.0;
    }
    fn bc_jacobian(&self, _ya: &[f64], _yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        ja.copy_from_slice(&[1.0, 0.0, 2.0, 0.0]);
        jb.iter_mut().for_each(|v| *v = 0.0);
    }
}

#[test]
fn errors_are_reported_not_panicked() {
    let t = linspace(0.0, FRAC_PI_2, 5);
    let guess = vec![vec![0.0, 0.0]; 5];
    let opts = BvpOptions::default();

    match solve_bvp(&NanAfter { t_bad: 1.0 }, &t, &guess, &opts) {
        Err(BvpError::NonFinite { t, .. }) => assert!(t > 1.0 && t <= FRAC_PI_2, "t = {t}"),
        other => panic!("expected NonFinite, got {other:?}"),
    }
    let e = solve_bvp(&NanAfter { t_bad: 1.0 }, &t, &guess, &opts).unwrap_err();
    assert!(e.to_string().contains("right-hand side"), "{e}");

    assert!(matches!(
        solve_bvp(&BadBc, &t, &guess, &opts),
        Err(BvpError::SingularJacobian { .. })
    ));

    let mut bad_mesh = t.clone();
    bad_mesh.swap(1, 2);
    assert!(matches!(
        solve_bvp(&Harmonic, &bad_mesh, &guess, &opts),
        Err(BvpError::InvalidInput(_))
    ));
    assert!(matches!(
        solve_bvp(&Harmonic, &t, &guess[..4], &opts),
        Err(BvpError::InvalidInput(_))
    ));
    let mut nan_guess = guess.clone();
    nan_guess[2][1] = f64::NAN;
    assert!(matches!(
        solve_bvp(&Harmonic, &t, &nan_guess, &opts),
        Err(BvpError::InvalidInput(_))
    ));

    // Too few nodes for the tolerance: the best solution comes back with the error.
    let tight = BvpOptions {
        tol: 1e-10,
        max_nodes: 20,
        ..BvpOptions::default()
    };
    match solve_bvp(&Harmonic, &t, &guess, &tight) {
        Err(BvpError::MaxNodesExceeded {
            max_residual, best, ..
        }) => {
            assert!(max_residual > 1e-10);
            assert!(best.t.len() <= 20);
            assert!(sin_error(&best.t, &best.y) < 1e-4);
        }
        other => panic!("expected MaxNodesExceeded, got {other:?}"),
    }
}
