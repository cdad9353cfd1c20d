//! Physical invariants of the model, checked on every bundled example:
//! - symmetry (jiles-atherton-actuator-model [JA 44–46]): the mechanics are
//!   even and the electrical states odd in (φ, H_c, u);
//! - the Jacobian against central finite differences;
//! - the z → 0⁺ limits: R_gap and R_gap' reach their limits, every derivative
//!   of f up to third order in z and φ stays finite at z = 0 (regularised log);
//! - the energy balance of a simulated closing-and-opening cycle.

use designer::description::{Core, Description};
use designer::model::{Model, ModelPlant, MU0};
use designer::replay::rest_state;
use designer::sim::{
    simulate_with, EventKind, Mode, Options, PiecewiseLinear, Plant, Quadrature, State, MAX_DIM,
};
use designer::sym::Tape;
use reldesign_tests::{example, example_with, examples, random_state, Rng};

fn eval(tape: &Tape, x: &[f64], u: f64, t: f64) -> Vec<f64> {
    let mut inputs = x.to_vec();
    inputs.extend([u, t]);
    let mut out = vec![0.0; tape.n_outputs()];
    tape.eval(&inputs, &mut tape.scratch(), &mut out);
    out
}

#[test]
fn mechanics_are_even_and_electrics_odd_in_flux_field_and_input() {
    for (name, d) in examples() {
        let mut model = Model::build(&d);
        let n = model.dim();
        let f = model.f.clone();
        let tape = model.compile(&f);
        let mut rng = Rng::new(44);
        for _ in 0..500 {
            let x = random_state(&d, &mut rng);
            let u = rng.uniform(d.supply.u_min, d.supply.u_max);
            let mut mirrored = x;
            for s in &mut mirrored[2..n] {
                *s = -*s;
            }
            let a = eval(&tape, &x[..n], u, 0.0);
            let b = eval(&tape, &mirrored[..n], -u, 0.0);
            for k in 0..n {
                let expected = if k < 2 { a[k] } else { -a[k] };
                let tol = 1e-12 * a[k].abs().max(1e-300);
                assert!(
                    (b[k] - expected).abs() <= tol,
                    "{name}: f[{k}] at {x:?}, u = {u}: {} vs {}",
                    b[k],
                    expected
                );
            }
        }
    }
}

#[test]
fn jacobian_matches_central_differences() {
    for (name, d) in examples() {
        let mut model = Model::build(&d);
        let n = model.dim();
        let jac = model.jacobian();
        let f = model.f.clone();
        let f_tape = model.compile(&f);
        let flat: Vec<_> = jac.into_iter().flatten().collect();
        let j_tape = model.compile(&flat);
        let scale = [d.mechanics.z_max - d.mechanics.z_min, 1.0, 1e-5, 1e3];
        let mut rng = Rng::new(7);
        let mut checked = 0;
        for _ in 0..300 {
            let mut x = random_state(&d, &mut rng);
            // stay inside the open interval so the difference stencil does too
            x[0] = x[0].clamp(d.mechanics.z_min + 1e-5, d.mechanics.z_max - 1e-5);
            let u = rng.uniform(d.supply.u_min, d.supply.u_max);
            let fx = eval(&f_tape, &x[..n], u, 0.0);
            if n == 4 && fx[2].abs() < 1e-3 * scale[2] * 1e3 {
                continue; // the JA branch δ = sign(φ̇) switches nearby
            }
            let j = eval(&j_tape, &x[..n], u, 0.0);
            for c in 0..n {
                let h = 1e-6 * scale[c];
                let (mut xp, mut xm) = (x, x);
                xp[c] += h;
                xm[c] -= h;
                let (fp, fm) = (
                    eval(&f_tape, &xp[..n], u, 0.0),
                    eval(&f_tape, &xm[..n], u, 0.0),
                );
                for r in 0..n {
                    let fd = (fp[r] - fm[r]) / (2.0 * h);
                    let sym = j[r * n + c];
                    let row_scale = (0..n)
                        .map(|cc| (j[r * n + cc] * scale[cc]).abs())
                        .fold(0.0, f64::max)
                        / scale[c];
                    assert!(
                        (fd - sym).abs() <= 1e-5 * sym.abs() + 1e-7 * row_scale,
                        "{name}: ∂f{r}/∂x{c} at {x:?}: symbolic {sym}, FD {fd}"
                    );
                }
            }
            checked += 1;
        }
        assert!(checked > 100, "{name}: only {checked} states checked");
    }
}

#[test]
fn gap_limits_at_zero_and_finite_third_derivatives() {
    let pt = example("perfect-tracking-valve.toml");
    let mut model = Model::build(&pt);
    let z = model.states[0];
    let r_dz2 = model.graph.diff(model.r_gap_dz, z);
    let tape = model.compile(&[model.r_gap, model.r_gap_dz, r_dz2]);
    let at = |z: f64| eval(&tape, &[z, 0.0, 0.0], 0.0, 0.0);
    // McLyman [PT 6], [PT 13]: R_gap(0) = 0, R_gap'(0) = 1/(μ0·A)
    let r0 = at(0.0);
    assert_eq!(r0[0], 0.0);
    let expected = 1.0 / (MU0 * 20e-6);
    assert!(
        (r0[1] - expected).abs() < 1e-12 * expected,
        "{} vs {expected}",
        r0[1]
    );
    // continuity towards 0⁺ and a finite (regularised) second derivative
    for zq in [1e-15, 1e-12] {
        let v = at(zq);
        assert!(
            (v[1] - r0[1]).abs() < 1e-4 * r0[1],
            "R_gap'({zq}) = {}",
            v[1]
        );
    }
    assert!(r0[2].is_finite() && at(1e-12)[2].is_finite());

    let ja = example("jiles-atherton-valve.toml");
    let mut model = Model::build(&ja);
    let tape = model.compile(&[model.r_gap, model.r_gap_dz]);
    let v = eval(&tape, &[0.0, 0.0, 0.0, 0.0], 0.0, 0.0);
    assert_eq!(
        v,
        vec![2.41e6, 7.94e10],
        "mclyman-fit limits (jiles-atherton-actuator-model eq. 14)"
    );

    for (name, d) in examples() {
        third_derivatives_are_finite(&name, &d);
    }
}

/// Every ∂³f/∂a∂b∂c for a, b, c in {z, φ} is finite on a grid including z = 0,
/// z_max and φ = 0.
fn third_derivatives_are_finite(name: &str, d: &Description) {
    let mut model = Model::build(d);
    let n = model.dim();
    let (z, phi) = (model.states[0], model.states[2]);
    let mut exprs = Vec::new();
    for &fk in &model.f.clone() {
        for first in [z, phi] {
            let d1 = model.graph.diff(fk, first);
            for second in [z, phi] {
                let d2 = model.graph.diff(d1, second);
                for third in [z, phi] {
                    exprs.push(model.graph.diff(d2, third));
                }
            }
        }
    }
    let tape = model.compile(&exprs);
    let m = &d.mechanics;
    let phi_max = match d.core {
        Core::Saturating { phi_sat, .. } => 0.9 * phi_sat,
        _ => 2e-5,
    };
    for zq in [m.z_min, m.z_min + 1e-12, 0.5 * (m.z_min + m.z_max), m.z_max] {
        for phiq in [0.0, 1e-9, phi_max, -phi_max] {
            let mut x = vec![zq, 0.3, phiq, 100.0];
            x.truncate(n);
            for (k, v) in eval(&tape, &x, 1.0, 0.0).into_iter().enumerate() {
                assert!(
                    v.is_finite(),
                    "{name}: third derivative #{k} not finite at z = {zq}, φ = {phiq}"
                );
            }
        }
    }
}

/// ∫u·i, ∫R·i², ∫k_e·φ̇², ∫c·v² along the trajectory.
struct Power<'a> {
    plant: &'a ModelPlant,
    resistance: f64,
    eddy: f64,
    damping: f64,
}

impl Quadrature for Power<'_> {
    fn len(&self) -> usize {
        4
    }

    fn integrand(&self, t: f64, x: &State, dx: &State, u: f64, _mode: Mode, out: &mut [f64; 8]) {
        let i = self.plant.coil(t, x, u).current;
        out[0] = u * i;
        out[1] = self.resistance * i * i;
        out[2] = self.eddy * dx[2] * dx[2];
        out[3] = self.damping * x[1] * x[1];
    }

    fn scale(&self) -> [f64; 8] {
        [1e-3; 8]
    }
}

/// Closes and reopens the actuator with a voltage pulse and checks
/// ∫u·i = ∫R·i² + ∫k_e·φ̇² + ∫c·v² + impact losses + Δ(½mv² + ½k_s z² + F0·z + W).
fn energy_balance_closes(name: &str, d: &Description, pulse: (f64, f64, f64), t_end: f64) {
    let mut model = Model::build(d);
    let w = model.stored_energy.expect("non-hysteretic core");
    let w_tape = model.compile(&[w]);
    let plant = ModelPlant::new(&mut model);
    let m = &d.mechanics;
    let power = Power {
        plant: &plant,
        resistance: d.coil.resistance,
        eddy: d.coil.eddy,
        damping: m.damping,
    };
    let input = PiecewiseLinear::pulses(0.0, &[pulse]).unwrap();
    let times: Vec<f64> = (0..=1000).map(|k| t_end * k as f64 / 1000.0).collect();
    let options = Options {
        rtol: 1e-10,
        ..Options::default()
    };
    let tr = simulate_with(
        &plant,
        &input,
        rest_state(&model),
        Mode::StuckMax,
        &times,
        &power,
        &options,
    )
    .unwrap();
    let modes: Vec<Mode> = tr.mode.clone();
    assert!(
        modes.contains(&Mode::StuckMin)
            || tr
                .events
                .iter()
                .any(|e| matches!(e.kind, EventKind::Impact { .. })),
        "{name}: never closed"
    );
    assert_eq!(
        *modes.last().unwrap(),
        Mode::StuckMax,
        "{name}: did not reopen"
    );
    let impact_loss: f64 = tr
        .events
        .iter()
        .filter_map(|e| match e.kind {
            EventKind::Impact {
                v_before, v_after, ..
            } => Some(0.5 * m.mass * (v_before * v_before - v_after * v_after)),
            _ => None,
        })
        .sum();
    let energy = |x: &State| {
        let mut xs = x[..plant.dim()].to_vec();
        xs.extend([0.0, 0.0]);
        let mut out = [0.0];
        w_tape.eval(&xs, &mut w_tape.scratch(), &mut out);
        0.5 * m.mass * x[1] * x[1] + 0.5 * m.stiffness * x[0] * x[0] + m.preload * x[0] + out[0]
    };
    let (first, last) = (&tr.x[0], &tr.x[tr.x.len() - 1]);
    let q = &tr.q[tr.q.len() - 1];
    let supplied = q[0];
    let accounted = q[1] + q[2] + q[3] + impact_loss + energy(last) - energy(first);
    let relative = (supplied - accounted).abs() / supplied.abs();
    assert!(relative < 1e-6, "{name}: supplied {supplied} J, accounted {accounted} J (rel. {relative:e}); impacts {impact_loss} J");
    let _ = MAX_DIM;
}

#[test]
fn energy_balance_over_a_closing_and_opening_cycle() {
    energy_balance_closes(
        "perfect-tracking",
        &example("perfect-tracking-valve.toml"),
        (1e-3, 7e-3, 24.0),
        0.04,
    );
    energy_balance_closes(
        "semera (no eddy, linear gap)",
        &example("semera-valve.toml"),
        (1e-3, 7e-3, 30.0),
        0.04,
    );
    energy_balance_closes(
        "table gap",
        &example("table-gap-valve.toml"),
        (1e-3, 7e-3, 24.0),
        0.04,
    );
    energy_balance_closes(
        "sliding-mode (fitted McLyman)",
        &example("sliding-mode-valve.toml"),
        (1e-3, 7e-3, 40.0),
        0.06,
    );
    let linear_core = example_with(
        "perfect-tracking-valve.toml",
        &[
            ("model = \"saturating\"", "model = \"linear\""),
            ("phi_sat", "# phi_sat"),
        ],
    );
    energy_balance_closes("linear core", &linear_core, (1e-3, 7e-3, 24.0), 0.04);
}
