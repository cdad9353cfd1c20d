//! The analytic (forward-sensitivity) Jacobian of the fit against central
//! differences of whole replays, on the saturating valve (a stuck armature,
//! and a record with motion, bounces and sticking impacts, the restitution
//! among the parameters) and on the Jiles–Atherton valve (flux reversals).

use designer::description::{parse_file, Description, Gap};
use designer::model::Model;
use designer::replay::{replay, Replay};
use designer::sim::{EventKind, Options, PiecewiseLinear};
use reldesign_identify::edges::{replay_input, replay_knots, Edge};
use reldesign_identify::sensitivity::{
    check, forward, forward_with_steps, input_response, InputPerturbations, InputStep,
    OutputSensitivities,
};
use reldesign_identify::{params, Measured};
use support::example_path;

const PATHS: [&str; 6] = [
    "coil.resistance",
    "coil.eddy",
    "core.phi_sat",
    "gap.slope",
    "mechanics.stiffness",
    "mechanics.restitution",
];

/// The Jiles–Atherton core's fitted parameters (as the diagnosis fits
/// them), with the resistance and a mechanical one.
const JA_PATHS: [&str; 7] = [
    "coil.resistance",
    "core.m_sat",
    "core.b",
    "core.c",
    "core.kappa",
    "core.length",
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
    record_of(n, |k| if k < on { high } else { 0.0 })
}

/// A record of `n` samples every 20 µs of the voltage `v(k)`.
fn record_of(n: usize, v: impl Fn(usize) -> f64) -> Measured {
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 20e-6).collect();
    let v = (0..n).map(v).collect();
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
/// drives it (the samples joined linearly, a step at each placed edge),
/// and its input.
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
fn analytic(
    d: &Description,
    data: &Measured,
    paths: &[&str],
) -> (OutputSensitivities, Vec<EventKind>) {
    let (mut model, r, input) = replayed(d, data, 1e-10);
    let s = forward(&mut model, paths, &r.trajectory, &input).unwrap();
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
fn compare(d: &Description, data: &Measured, paths: &[&str], tol: f64) -> Compared {
    check(d, paths).unwrap();
    let (s, events) = analytic(d, data, paths);
    let intervals = (s.radau_intervals, s.rk4_intervals);
    assert_eq!(
        intervals.0 + intervals.1,
        data.len() - 1,
        "one step per interval"
    );
    for (j, path) in paths.iter().enumerate() {
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
    eprintln!(
        "intervals: {} by Radau, {} by RK4",
        intervals.0, intervals.1
    );
    Compared {
        events,
        radau: intervals.0,
        rk4: intervals.1,
    }
}

/// The events of the replay and how its sample intervals were integrated.
struct Compared {
    events: Vec<EventKind>,
    radau: usize,
    rk4: usize,
}

#[test]
fn the_analytic_jacobian_matches_central_differences_on_a_stuck_armature() {
    let d = valve();
    let data = record(3.0, 400, 500);
    let c = compare(&d, &data, &PATHS, 1e-5);
    assert!(
        !c.events
            .iter()
            .any(|e| matches!(e, EventKind::Impact { .. })),
        "the armature must not move: {:?}",
        c.events
    );
    // No event, no breakpoint inside an interval: Radau throughout, but
    // where the cubic does not follow x (the voltage ramp down at 400).
    assert!(c.rk4 <= 5, "{} intervals by RK4", c.rk4);
}

#[test]
fn the_analytic_jacobian_matches_central_differences_through_impacts() {
    let d = valve();
    let mut data = record(30.0, 500, 1500);
    // The switch-off placed as a step 7 µs into its interval, as the
    // diagnosis places edges: a breakpoint inside an interval.
    data.edges = Some(vec![Edge {
        k: 499,
        tau: data.t[499] + 7e-6,
        located: true,
    }]);
    // In motion the Radau steps (order 3, one per 20 µs sample) follow the
    // differences to 2e-5; stuck, to 1e-6.
    let c = compare(&d, &data, &PATHS, 1e-4);
    let bounces = c
        .events
        .iter()
        .filter(|e| matches!(e, EventKind::Impact { v_after, .. } if *v_after != 0.0))
        .count();
    assert!(bounces >= 2, "the record must have bounces: {:?}", c.events);
    // RK4 across the events and the edge, and where the motion is too fast
    // for the cubic (890 by Radau, 609 by RK4 when written).
    assert!(
        c.rk4 > c.events.len() && c.radau > c.rk4,
        "{} / {}",
        c.radau,
        c.rk4
    );
}

/// ±`volts`, reversed every 4 ms (200 samples): the flux, and with it
/// δ = sign φ̇ [JA 26], reverses 5 times.
fn reversals(volts: f64) -> Measured {
    record_of(1200, |k| if (k / 200) % 2 == 0 { volts } else { -volts })
}

/// The sensitivities cross each reversal's kink (f_x jumps where φ̇
/// changes sign between samples) at second order: 2e-4 of the largest
/// derivative, not the 1e-6 of a smooth field.
#[test]
fn the_analytic_jacobian_matches_central_differences_on_the_hysteretic_core() {
    let d = parse_file(&example_path("jiles-atherton-valve.toml")).unwrap();
    let c = compare(&d, &reversals(4.0), &JA_PATHS, 5e-4);
    assert!(
        c.events.is_empty(),
        "the armature must not move: {:?}",
        c.events
    );
    assert!(c.radau > 10 * c.rk4, "{} / {}", c.radau, c.rk4);
}

/// With motion, on a linear gap: the example's McLyman fit has a curvature
/// k1·z·ln(k2/z) singular at the stop (∂²R/∂z² ∝ 1/z), which the
/// sensitivities resolve to only about 1 % after a bounce there.
#[test]
fn the_analytic_jacobian_matches_central_differences_on_a_moving_hysteretic_valve() {
    let mut d = parse_file(&example_path("jiles-atherton-valve.toml")).unwrap();
    d.gap = Gap::Linear {
        slope: 2.0e10,
        offset: 2.41e6,
    };
    let c = compare(&d, &reversals(24.0), &JA_PATHS, 2e-3);
    let bounces = c
        .events
        .iter()
        .filter(|e| matches!(e, EventKind::Impact { v_after, .. } if *v_after != 0.0))
        .count();
    assert!(bounces >= 5, "the armature must bounce: {:?}", c.events);
}

#[test]
fn only_the_mode_logic_and_absent_terms_are_not_supported() {
    let d = valve();
    assert!(check(&d, &["coil.resistance", "mechanics.bounce_threshold"]).is_err());
    // No resistance drift in the model: its symbol is not there to differentiate.
    assert!(check(&d, &["coil.resistance_drift"]).is_err());
    assert!(check(&d, &["mechanics.z_max"]).is_err());
}

/// Largest |analytic − central difference| of the current relative to the
/// largest |difference|, per placed edge of `data` (its instant moved by
/// ±`h` seconds), from [`forward_with_steps`] with the values of `paths`
/// before them (whose columns must be [`forward`]'s, bit for bit).
fn step_errors(d: &Description, data: &Measured, paths: &[&str], h: f64) -> Vec<f64> {
    let edges = data.edges.clone().unwrap();
    let steps: Vec<InputStep> = edges
        .iter()
        .map(|e| InputStep {
            t: e.tau,
            before: data.v[e.k],
            after: data.v[e.k + 1],
        })
        .collect();
    let (mut model, r, input) = replayed(d, data, 1e-10);
    let s = forward_with_steps(&mut model, paths, &steps, &r.trajectory, &input).unwrap();
    let values = forward(&mut model, paths, &r.trajectory, &input).unwrap();
    let p = paths.len();
    assert_eq!(s.current.columns(0, p), values.current);
    assert_eq!(s.phi.columns(0, p), values.phi);
    let moved = |n: usize, by: f64| {
        let mut data = data.clone();
        data.edges.as_mut().unwrap()[n].tau += by;
        replayed(d, &data, 1e-13).1.current
    };
    (0..edges.len())
        .map(|n| {
            let (scale, err) =
                central_error(&moved(n, h), &moved(n, -h), h, |k| s.current[(k, p + n)]);
            eprintln!(
                "edge {n}: ∂i/∂τ scale {scale:.3e}, error {:.2e}",
                err / scale
            );
            err / scale
        })
        .collect()
}

/// The central difference of the currents `plus` and `minus` (at ±`h`)
/// against `analytic(k)` at each sample: the largest |difference| (the
/// scale) and the largest |analytic − difference|.
fn central_error(
    plus: &[f64],
    minus: &[f64],
    h: f64,
    analytic: impl Fn(usize) -> f64,
) -> (f64, f64) {
    (plus.iter().zip(minus).enumerate()).fold((0.0f64, 0.0f64), |(scale, err), (k, (a, b))| {
        let fd = (a - b) / (2.0 * h);
        (scale.max(fd.abs()), err.max((analytic(k) - fd).abs()))
    })
}

/// An edge `frac` of a sample after sample `k` of `data`.
fn edge(data: &Measured, k: usize, frac: f64) -> Edge {
    Edge {
        k,
        tau: data.t[k] + frac * data.dt,
        located: true,
    }
}

/// The instants of voltage edges between samples as parameters: the switch-on
/// and the switch-off of a closing and opening saturating valve (bounces
/// after both), and the reversals of a Jiles–Atherton core.
#[test]
fn the_edge_instants_sensitivities_match_central_differences() {
    let d = valve();
    let mut data = record_of(1500, |k| if (50..500).contains(&k) { 30.0 } else { 0.0 });
    data.edges = Some(vec![edge(&data, 49, 0.65), edge(&data, 499, 0.35)]);
    // (A step of 2e-8 s moves the lift-off after the switch-on across
    // sample 158 and the difference there is off by 20 %; at 5e-9 s the
    // two agree to 2.5e-5.)
    for err in step_errors(&d, &data, &PATHS, 5e-9) {
        assert!(err < 2e-4, "{err:e}");
    }
    let ja = parse_file(&example_path("jiles-atherton-valve.toml")).unwrap();
    let mut data = reversals(4.0);
    data.edges = Some(
        [199, 399, 599]
            .iter()
            .zip([0.2, 0.5, 0.9])
            .map(|(&k, f)| edge(&data, k, f))
            .collect(),
    );
    for err in step_errors(&ja, &data, &JA_PATHS, 2e-8) {
        assert!(err < 2e-5, "{err:e}");
    }
}

/// The largest error of the linearised response to each perturbation of
/// the voltage's samples (`columns`), against central differences of
/// replays of the perturbed voltage (±`h` times each column), relative to
/// the largest difference of its current.
fn input_errors(d: &Description, data: &Measured, columns: &[Vec<f64>], h: f64) -> Vec<f64> {
    let (mut model, r, input) = replayed(d, data, 1e-10);
    let (knots, sample) = replay_knots(data);
    let perturbations = InputPerturbations {
        knots: &knots,
        sample: &sample,
        columns,
    };
    let s = input_response(&mut model, perturbations, &r.trajectory, &input).unwrap();
    let current = |sign: f64, e: &[f64]| {
        let v = data
            .v
            .iter()
            .zip(e)
            .map(|(v, e)| v + sign * h * e)
            .collect();
        replayed(d, &Measured { v, ..data.clone() }, 1e-13)
            .1
            .current
    };
    (columns.iter().enumerate())
        .map(|(j, e)| {
            let (scale, err) = central_error(&current(1.0, e), &current(-1.0, e), h, |k| {
                s.current[(k, j)]
            });
            assert!(scale > 0.0, "column {j} moves nothing");
            err / scale
        })
        .collect()
}

/// Columns of seeded standard normal values, one per sample, and one
/// impulse at sample `at`.
fn noise_columns(n: usize, at: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = designer::random::SplitMix64::new(seed);
    let mut normal = || {
        let (u1, u2) = (rng.uniform().max(1e-300), rng.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    };
    let noise = (0..n).map(|_| normal()).collect();
    let impulse = (0..n).map(|k| if k == at { 1.0 } else { 0.0 }).collect();
    vec![noise, impulse]
}

/// The current's response to noise on the voltage's samples (what the
/// diagnosis's standard errors propagate), linearised along the replay,
/// against replays of the perturbed voltage: the saturating valve closing
/// and opening with bounces, its edges between samples (a sample next to an
/// edge holds the level on its side of the step), to 3e-4 (noise) and
/// 5e-4 (an impulse on the sample before the switch-off), and the
/// Jiles–Atherton core's reversals, to 1e-4. (Perturbing the input by its
/// value at the end of a piece instead of the piece's own, across the
/// switch-off, made the impulse's error 2e-2.)
#[test]
fn the_input_response_matches_replays_of_the_perturbed_voltage() {
    let d = valve();
    let mut data = record_of(1500, |k| if (50..500).contains(&k) { 30.0 } else { 0.0 });
    data.edges = Some(vec![edge(&data, 49, 0.65), edge(&data, 499, 0.35)]);
    for (j, err) in input_errors(&d, &data, &noise_columns(1500, 499, 5), 1e-5)
        .into_iter()
        .enumerate()
    {
        assert!(err < 1e-3, "saturating valve, column {j}: {err:e}");
    }
    let ja = parse_file(&example_path("jiles-atherton-valve.toml")).unwrap();
    let mut data = reversals(4.0);
    data.edges = Some(vec![edge(&data, 199, 0.2), edge(&data, 399, 0.5)]);
    for (j, err) in input_errors(&ja, &data, &noise_columns(1200, 400, 6), 1e-5)
        .into_iter()
        .enumerate()
    {
        assert!(err < 3e-4, "Jiles–Atherton core, column {j}: {err:e}");
    }
}
