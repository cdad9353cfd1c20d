//! The model as a simulator plant (`model/plant.rs`) on every bundled
//! example: the held-branch field against the live one, the resting and
//! acceleration tapes against the whole field, the continuation beyond the
//! stops, and the batched coil outputs against the single-point ones.

use std::path::PathBuf;

use designer::description::{parse_file, Description};
use designer::model::{Model, ModelPlant};
use designer::sim::{Branches, Plant, State, MAX_SWITCHES};
use support::{assert_close, example_paths, Tol};

fn examples() -> Vec<(PathBuf, Description)> {
    example_paths()
        .into_iter()
        .map(|p| {
            let d = parse_file(&p).unwrap();
            (p, d)
        })
        .collect()
}

/// Deterministic states inside the stroke (a small LCG).
fn states(d: &Description, n: usize) -> Vec<State> {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = |lo: f64, hi: f64| {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
    };
    let m = &d.mechanics;
    let phi = match &d.core {
        designer::description::Core::Saturating { phi_sat, .. } => 0.9 * phi_sat,
        _ => 2.5e-5,
    };
    (0..n)
        .map(|_| {
            [
                uniform(m.z_min, m.z_max),
                uniform(-2.0, 2.0),
                uniform(-phi, phi),
                uniform(-2000.0, 2000.0),
            ]
        })
        .collect()
}

fn field(plant: &ModelPlant, x: &State, u: f64, branch: &Branches) -> State {
    let mut dx = [0.0; 4];
    plant.deriv_branch(0.0, x, u, branch, &mut dx);
    dx
}

#[test]
fn only_the_jiles_atherton_core_switches_and_its_function_is_the_flux_rate() {
    for (path, d) in examples() {
        let plant = ModelPlant::new(&mut Model::build(&d));
        let ja = path.to_string_lossy().contains("jiles-atherton");
        assert_eq!(plant.switches(), usize::from(ja), "{path:?}");
        if !ja {
            continue;
        }
        assert_eq!(plant.switching_component(0), Some(2));
        for x in states(&d, 50) {
            let mut s = [0.0; MAX_SWITCHES];
            plant.switching(0.0, &x, 7.0, &mut s);
            let mut live = [0.0; 4];
            plant.deriv(0.0, &x, 7.0, &mut live);
            assert_close(s[0], live[2], Tol::rel(1e-14), "s = φ̇");
            let held = field(&plant, &x, 7.0, &[s[0].signum(), 0.0, 0.0, 0.0]);
            assert_eq!(held, live, "at {x:?}");
            // The other branch differs (in dH_c/dt only).
            let other = field(&plant, &x, 7.0, &[-s[0].signum(), 0.0, 0.0, 0.0]);
            assert_eq!(other[..3], live[..3]);
            assert_ne!(other[3], live[3]);
        }
    }
}

#[test]
fn resting_field_and_acceleration_agree_with_the_whole_field() {
    for (path, d) in examples() {
        let plant = ModelPlant::new(&mut Model::build(&d));
        let branch = [1.0; MAX_SWITCHES];
        for x in states(&d, 50) {
            let whole = field(&plant, &x, -3.0, &branch);
            let mut resting = [f64::NAN; 4];
            plant.deriv_resting(0.0, &x, -3.0, &branch, &mut resting);
            for i in 2..plant.dim() {
                let what = format!("{path:?} {i}: {x:?}");
                assert_close(resting[i], whole[i], Tol::rel(1e-13), what);
            }
            let a = plant.accel_branch(0.0, &x, -3.0, &branch);
            assert_close(a, whole[1], Tol::rel(1e-13), format!("{path:?}: v̇"));
        }
    }
}

#[test]
fn beyond_the_stops_the_field_is_continued_by_its_tangent() {
    for (path, d) in examples() {
        let plant = ModelPlant::new(&mut Model::build(&d));
        assert!(plant.smooth_beyond_limits());
        let lim = plant.limits();
        let branch = [1.0; MAX_SWITCHES];
        for x in states(&d, 10) {
            let at = |z: f64| field(&plant, &[z, x[1], x[2], x[3]], 5.0, &branch);
            for (z_lim, out) in [(lim.z_min, -1.0), (lim.z_max, 1.0)] {
                let step = 1e-6 * (lim.z_max - lim.z_min);
                let (f0, f1, f2) = (
                    at(z_lim),
                    at(z_lim + out * step),
                    at(z_lim + 2.0 * out * step),
                );
                for i in 0..plant.dim() {
                    // Continuous at the stop, linear beyond it.
                    let (d1, d2) = (f1[i] - f0[i], f2[i] - f1[i]);
                    let scale = f0[i].abs().max(d1.abs()).max(1e-300);
                    assert!(
                        (d2 - d1).abs() <= 1e-9 * scale,
                        "{path:?} {i}: {d1} vs {d2}"
                    );
                }
                if out > 0.0 {
                    // C¹ at z_max: the slope beyond matches the slope inside.
                    let inside = at(z_lim - step);
                    for i in 0..plant.dim() {
                        let (d_out, d_in) = (f1[i] - f0[i], f0[i] - inside[i]);
                        let scale = d_out.abs().max(d_in.abs()).max(1e-12 * f0[i].abs());
                        assert!((d_out - d_in).abs() <= 1e-3 * scale, "{path:?} {i}");
                    }
                }
            }
        }
    }
}

#[test]
fn batched_coil_outputs_match_single_points() {
    for (path, d) in examples() {
        let plant = ModelPlant::new(&mut Model::build(&d));
        let lim = plant.limits();
        let mut xs = states(&d, 37);
        xs[3][0] = lim.z_min - 1e-7; // clamped to the stop, as in `coil`
        xs[4][0] = lim.z_max + 1e-7;
        let t: Vec<f64> = (0..xs.len()).map(|k| k as f64 * 1e-4).collect();
        let u: Vec<f64> = (0..xs.len()).map(|k| (k % 7) as f64 - 3.0).collect();
        let (current, voltage) = plant.currents_and_voltages(&t, &xs, &u);
        for k in 0..xs.len() {
            let one = plant.current_and_voltage(t[k], &xs[k], u[k]);
            assert_eq!((current[k], voltage[k]), one, "{path:?} point {k}");
            let coil = plant.coil(t[k], &xs[k], u[k]);
            assert_close(coil.current, one.0, Tol::rel(1e-13), "coil current");
            assert_close(coil.voltage, one.1, Tol::rel(1e-13), "coil voltage");
        }
    }
}
