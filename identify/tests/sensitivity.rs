//! The analytic (forward-sensitivity) Jacobian of the fit against central
//! differences of whole replays, on the saturating valve: a stuck armature
//! (no motion) and a record with motion, bounces and sticking impacts.

use designer::description::{parse_file, Description};
use designer::model::Model;
use designer::replay::{replay, Replay};
use designer::sim::{EventKind, Options, PiecewiseLinear};
use reldesign_identify::edges::replay_input;
use reldesign_identify::sensitivity::{check, forward, OutputSensitivities};
use reldesign_identify::{params, Measured};
use support::example_path;

const PATHS: [&str; 5] = [
    "coil.resistance",
    "coil.eddy",
    "core.phi_sat",
    "gap.slope",
    "mechanics.stiffness",
];

fn valve() -> Description {
    let mut d = parse_file(&example_path("semera-valve.toml")).unwrap();
    // An eddy-current term, so that its sensitivity is not trivially zero.
    params::set(&mut d, "coil.eddy", 2e3).unwrap();
    d
}

/// A voltage record of `n` samples every 20 µs: `high` for the first
/// `on` samples, then 0 V.
fn record(high: f64, on: usize, n: usize) -> Measured {
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 20e-6).collect();
    let v = (0..n).map(|k| if k < on { high } else { 0.0 }).collect();
    Measured {
        i: vec![0.0; n],
        z: None,
        phi: None,
        lambda: None,
        dt: 20e-6,
        file_name: "synthetic.csv".into(),
        edges: None,
        t,
        v,
    }
}

/// The replay of `d` at relative tolerance `rtol`, driven as the fit
/// drives it (the voltage edge a step between samples), and its input.
fn replayed(d: &Description, data: &Measured, rtol: f64) -> (Model, Replay, PiecewiseLinear) {
    let mut model = Model::build(d);
    let input = replay_input(data).unwrap();
    let options = Options {
        rtol,
        max_steps: 10_000_000,
        ..Options::default()
    };
    let r = replay(&mut model, &input, &data.t, &options).unwrap();
    (model, r, input)
}

/// The analytic sensitivities of the replay of `d` (the fit's tolerance),
/// and its events.
fn analytic(d: &Description, data: &Measured) -> (OutputSensitivities, Vec<EventKind>) {
    let (mut model, r, input) = replayed(d, data, 1e-10);
    let s = forward(&mut model, &PATHS, &r.trajectory, &input).unwrap();
    (s, r.trajectory.events.iter().map(|e| e.kind).collect())
}

/// Central differences (relative step `h`) of current, z and φ, from
/// replays at a tolerance (1e-13) that keeps their noise far below the
/// compared error.
fn central(d: &Description, data: &Measured, path: &str, h: f64) -> [Vec<f64>; 3] {
    let x = params::get(d, path).unwrap();
    let at = |x: f64| {
        let mut d = d.clone();
        params::set(&mut d, path, x).unwrap();
        replayed(&d, data, 1e-13).1
    };
    let (plus, minus) = (at(x * (1.0 + h)), at(x * (1.0 - h)));
    let diff = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter()
            .zip(b)
            .map(|(a, b)| (a - b) / (2.0 * h * x))
            .collect()
    };
    let (p, m) = (&plus.trajectory, &minus.trajectory);
    [
        diff(&plus.current, &minus.current),
        diff(&p.component(0), &m.component(0)),
        diff(&p.component(2), &m.component(2)),
    ]
}

/// Largest |analytic − fd| relative to the largest |fd|, per signal.
fn compare(d: &Description, data: &Measured, tol: f64) -> Vec<EventKind> {
    let (s, events) = analytic(d, data);
    for (j, path) in PATHS.iter().enumerate() {
        let fd = central(d, data, path, 1e-4);
        for (name, m, f) in [
            ("current", &s.current, &fd[0]),
            ("z", &s.z, &fd[1]),
            ("phi", &s.phi, &fd[2]),
        ] {
            let scale = f.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            let err = f
                .iter()
                .enumerate()
                .fold(0.0f64, |a, (k, x)| a.max((m[(k, j)] - x).abs()));
            let kmax = (0..f.len())
                .max_by(|&a, &b| {
                    (m[(a, j)] - f[a])
                        .abs()
                        .total_cmp(&(m[(b, j)] - f[b]).abs())
                })
                .unwrap_or(0);
            eprintln!(
                "{path} {name}: scale {scale:.3e}, error {:.2e} at {kmax}",
                err / scale.max(1e-300)
            );
            assert!(
                err <= tol * scale || scale == 0.0 && err < 1e-12,
                "{path} ∂{name}: error {err:e} vs scale {scale:e}"
            );
        }
    }
    events
}

#[test]
fn the_analytic_jacobian_matches_central_differences_on_a_stuck_armature() {
    let d = valve();
    check(&d, &PATHS).unwrap();
    let data = record(3.0, 400, 500);
    let events = compare(&d, &data, 1e-5);
    assert!(
        !events.iter().any(|e| matches!(e, EventKind::Impact { .. })),
        "the armature must not move: {events:?}"
    );
}

#[test]
fn the_analytic_jacobian_matches_central_differences_through_impacts() {
    let d = valve();
    let data = record(30.0, 500, 1500);
    let events = compare(&d, &data, 1e-5);
    let impacts = events
        .iter()
        .filter(|e| matches!(e, EventKind::Impact { .. }))
        .count();
    assert!(impacts >= 2, "the record must have impacts: {events:?}");
}

#[test]
fn reset_parameters_and_hysteresis_are_not_supported() {
    let d = valve();
    assert!(check(&d, &["coil.resistance", "mechanics.restitution"]).is_err());
    let ja = parse_file(&example_path("jiles-atherton-valve.toml")).unwrap();
    assert!(check(&ja, &["coil.resistance"]).is_err());
}
