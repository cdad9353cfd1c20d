//! Feedback linearization for y = z, checked against finite differences and
//! by construction:
//! - the jerk d a/dt along f(x, u), by central differences of a = T₃(x), equals
//!   L_f³h + L_g L_f²h·u (perfect-tracking-soft-landing eq. 30);
//! - u = α + β·w gives jerk w (eqs. 31–33);
//! - T⁻¹(T(x)) = x on D₀⁺ (eqs. 41–42);
//! - the relative degree is lost at φ = 0;
//! - on the Jiles–Atherton core the chain closes on (z, v, φ) with H_c exogenous,
//!   checked along the full hysteretic f, and keeps the core's symmetry [JA 46].

use designer::description::parse_file;
use designer::design::Linearization;
use designer::model::Model;
use designer::sym::Tape;
use support::example_path;

fn model(file: &str) -> Model {
    Model::build(&parse_file(&example_path(file)).unwrap_or_else(|e| panic!("{e}")))
}

const AFFINE_EXAMPLES: [&str; 4] = [
    "perfect-tracking-valve.toml",
    "semera-valve.toml",
    "sliding-mode-valve.toml",
    "table-gap-valve.toml",
];

fn run(tape: &Tape, x: [f64; 3], u: f64) -> Vec<f64> {
    let mut out = vec![0.0; tape.n_outputs()];
    tape.eval(&[x[0], x[1], x[2], u, 0.0], &mut tape.scratch(), &mut out);
    out
}

/// Deterministic states inside the stroke with φ > 0.
fn states(m: &Model) -> Vec<[f64; 3]> {
    let mech = &m.description.mechanics;
    (0..60)
        .map(|k| {
            let s = (k as f64 + 0.5) / 60.0;
            let z = mech.z_min + (0.05 + 0.9 * s) * (mech.z_max - mech.z_min);
            [
                z,
                (3.7 * s).sin(),
                2e-6 + 1.5e-5 * ((5.3 * s).cos() * 0.5 + 0.5),
            ]
        })
        .collect()
}

#[test]
fn jerk_and_linearizing_law_match_finite_differences() {
    for file in AFFINE_EXAMPLES {
        let mut m = model(file);
        let lin = Linearization::derive(&mut m).unwrap();
        let mut outs = m.f.clone();
        outs.extend([lin.transform[2], lin.lf3h, lin.lglf2h, lin.alpha, lin.beta]);
        let tape = m.compile(&outs);
        for x in states(&m) {
            for (u, w) in [(5.0, 3e5), (-2.0, -1e5)] {
                let o = run(&tape, x, u);
                let (f, (lf3h, lglf2h, alpha, beta)) = (&o[..3], (o[4], o[5], o[6], o[7]));
                // d a/dt along f(x, u) by central differences
                let h = 1e-7 * 1e-3 / f.iter().fold(1e-30f64, |a, v| a.max(v.abs())).max(1e-3);
                let step = |sign: f64| {
                    [
                        x[0] + sign * h * f[0],
                        x[1] + sign * h * f[1],
                        x[2] + sign * h * f[2],
                    ]
                };
                let jerk_fd =
                    (run(&tape, step(1.0), u)[3] - run(&tape, step(-1.0), u)[3]) / (2.0 * h);
                let jerk = lf3h + lglf2h * u;
                assert!(
                    (jerk - jerk_fd).abs() <= 1e-5 * jerk.abs().max(lf3h.abs()),
                    "{file} {x:?}: jerk {jerk} vs FD {jerk_fd}"
                );
                // u = α + β·w ⇒ z⁽³⁾ = w (33)
                let u_lin = alpha + beta * w;
                let o2 = run(&tape, x, u_lin);
                let jerk_lin = o2[4] + o2[5] * u_lin;
                assert!(
                    (jerk_lin - w).abs() <= 1e-8 * w.abs().max(lf3h.abs()),
                    "{file}: z''' = {jerk_lin}, wanted {w}"
                );
            }
        }
    }
}

#[test]
fn inverse_transform_undoes_the_transform_on_positive_flux() {
    for file in AFFINE_EXAMPLES {
        let mut m = model(file);
        let lin = Linearization::derive(&mut m).unwrap();
        let t_tape = m.compile(&lin.transform);
        let inverse = m.bind_params(&lin.inverse);
        let inv_tape = Tape::compile(&m.graph, &lin.xi, &inverse).unwrap();
        for x in states(&m) {
            let xi = run(&t_tape, x, 0.0);
            let mut back = [0.0; 3];
            inv_tape.eval(&xi, &mut inv_tape.scratch(), &mut back);
            for k in 0..3 {
                assert!(
                    (back[k] - x[k]).abs() <= 1e-9 * x[k].abs().max(1e-12),
                    "{file}: T⁻¹(T(x))[{k}] = {}, x = {:?}",
                    back[k],
                    x
                );
            }
        }
    }
}

#[test]
fn relative_degree_is_lost_at_zero_flux_and_said_so() {
    let mut m = model("perfect-tracking-valve.toml");
    let lin = Linearization::derive(&mut m).unwrap();
    let names: Vec<_> = lin
        .singular_at
        .iter()
        .map(|&s| m.graph.name_of(s).unwrap())
        .collect();
    assert_eq!(names, ["phi"]);
    let text = lin.singularity_text(&m.graph);
    assert!(
        text.contains("phi = 0") && text.contains("phi > 0"),
        "{text}"
    );
    let tape = m.compile(&[lin.lglf2h]);
    assert_eq!(run(&tape, [5e-4, 0.0, 0.0], 1.0)[0], 0.0);
}

#[test]
fn jiles_atherton_chain_closes_on_z_v_phi_with_the_field_exogenous() {
    let mut m = model("jiles-atherton-valve.toml");
    let lin = Linearization::derive(&mut m).unwrap();
    let hc = m.states[3];
    assert_eq!(lin.exogenous, [hc]);
    assert_eq!(lin.system.states.len(), 3);
    // a = L_f²z reads no H_c; L_f³z and L_g L_f²z do (through φ̇'s MMF)
    assert!(!m.graph.depends_on(lin.transform[2], hc));
    assert!(m.graph.depends_on(lin.lf3h, hc));
    assert!(m.graph.depends_on(lin.alpha, hc));
    // the jerk along the model's full f by central differences of a (the
    // H_c row moves too, which a does not read), against L_f³z + L_g L_f²z·u
    let mut outs = m.f.clone();
    outs.extend([lin.transform[2], lin.lf3h, lin.lglf2h, lin.alpha, lin.beta]);
    let tape = m.compile(&outs);
    let eval = |x: [f64; 4], u: f64| {
        let mut out = vec![0.0; tape.n_outputs()];
        tape.eval(
            &[x[0], x[1], x[2], x[3], u, 0.0],
            &mut tape.scratch(),
            &mut out,
        );
        out
    };
    let mut checked = 0;
    for x3 in states(&m) {
        for (hc_value, u, w) in [(250.0, 6.0, 3e5), (-400.0, -3.0, -1e5), (0.0, 12.0, 0.0)] {
            let x = [x3[0], x3[1], x3[2], hc_value];
            let o = eval(x, u);
            let (f, lf3h, lglf2h, alpha, beta) = (&o[..4], o[5], o[6], o[7], o[8]);
            // a time step moving z and φ by ~1e-6 of themselves
            let h = 1e-6 * (x[0] / f[0].abs().max(1e-30)).min(x[2] / f[2].abs().max(1e-30));
            let step = |sign: f64| std::array::from_fn(|k| x[k] + sign * h * f[k]);
            let jerk_fd = (eval(step(1.0), u)[4] - eval(step(-1.0), u)[4]) / (2.0 * h);
            let jerk = lf3h + lglf2h * u;
            assert!(
                (jerk - jerk_fd).abs() <= 1e-5 * jerk.abs().max(lf3h.abs()),
                "{x:?}, u = {u}: jerk {jerk} vs FD {jerk_fd}"
            );
            // [PT 33] u = α + β·w gives z⁽³⁾ = w, with H_c as it is
            let u_lin = alpha + beta * w;
            let o2 = eval(x, u_lin);
            assert!((o2[5] + o2[6] * u_lin - w).abs() <= 1e-8 * w.abs().max(lf3h.abs()));
            checked += 1;
        }
    }
    assert_eq!(checked, 180);
}

/// [JA 46] symmetry f(z, φ, H_c, u) = −f(z, −φ, −H_c, −u) of the flux row:
/// a is even in φ, L_f³z even in (φ, H_c) jointly, L_g L_f²z odd in φ.
#[test]
fn jiles_atherton_jerk_terms_are_odd_in_flux_and_field() {
    let mut m = model("jiles-atherton-valve.toml");
    let lin = Linearization::derive(&mut m).unwrap();
    let tape = m.compile(&[lin.transform[2], lin.lf3h, lin.lglf2h]);
    let eval = |x: [f64; 4]| {
        let mut out = [0.0; 3];
        tape.eval(
            &[x[0], x[1], x[2], x[3], 0.0, 0.0],
            &mut tape.scratch(),
            &mut out,
        );
        out
    };
    for x in states(&m) {
        let plus = eval([x[0], x[1], x[2], 300.0]);
        let minus = eval([x[0], x[1], -x[2], -300.0]);
        // a is even in φ; dφ/dt is odd in (φ, H_c, u), ∂a/∂φ odd in φ:
        // the drift's jerk part ∂a/∂φ·φ̇ is even, the gain ∂a/∂φ·∂φ̇/∂u odd
        assert_eq!(plus[0], minus[0]);
        assert!(
            (plus[1] - minus[1]).abs() <= 1e-12 * plus[1].abs().max(1.0),
            "{plus:?} {minus:?}"
        );
        assert!(
            (plus[2] + minus[2]).abs() <= 1e-12 * plus[2].abs(),
            "{plus:?} {minus:?}"
        );
    }
}

#[test]
fn polynomial_references_of_the_paper_valve_are_checked_for_feasibility() {
    use designer::design::{check_feasibility, Polynomial};
    let mut m = model("perfect-tracking-valve.toml");
    let lin = Linearization::derive(&mut m).unwrap();
    let (z_min, z_max) = (m.description.mechanics.z_min, m.description.mechanics.z_max);
    let closing = Polynomial {
        z0: z_max,
        zf: z_min,
        t0: 1e-3,
        tf: 6e-3,
    };
    let opening = Polynomial {
        z0: z_min,
        zf: z_max,
        t0: 1e-3,
        tf: 6e-3,
    };
    // The polynomial closing of the paper's valve needs slightly more than
    // 24 V right after take-off (the polynomial's jerk peaks at t₀: compare the
    // saturation of Fig. 5); the opening stays within ±24 V.
    let report = check_feasibility(&mut m, &lin, &closing, (-24.0, 24.0), 2000);
    let u_max = &report.conditions[4];
    let (start, end) = u_max.violated.expect("closing saturates");
    assert!(
        start < 1.01e-3 && end < 1.5e-3 && (24.0..26.0).contains(&u_max.worst_value),
        "{}",
        report.report()
    );
    assert_eq!(
        report
            .conditions
            .iter()
            .filter(|c| c.violated.is_some())
            .count(),
        1,
        "{}",
        report.report()
    );
    let report = check_feasibility(&mut m, &lin, &opening, (-24.0, 24.0), 2000);
    assert!(report.is_feasible(), "{}", report.report());
    assert!(report.min_flux > 0.0 && report.max_input < 24.0 && report.min_input > -24.0);
    // A much faster motion cannot be tracked within ±24 V: (54) must fail and say where.
    let fast = Polynomial {
        z0: z_max,
        zf: z_min,
        t0: 1e-3,
        tf: 1.5e-3,
    };
    let report = check_feasibility(&mut m, &lin, &fast, (-24.0, 24.0), 2000);
    assert!(!report.is_feasible());
    let text = report.report();
    assert!(
        text.contains("FAIL  (54)") && text.contains("longer motion"),
        "{text}"
    );
}
