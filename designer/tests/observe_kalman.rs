//! The Kalman filters on the discretised model (jiles-atherton-actuator-model
//! §6.1, eqs. 84–87):
//!
//! - the symbolic Jacobians of the discrete map F(x, u) and of the
//!   measurement h(x, u) against central finite differences at random states,
//!   for every bundled example (3 and 4 states);
//! - the EKF and UKF on the hybrid simulator of the perfect-tracking valve
//!   driven open loop (24 V closes it, 0 V then −24 V briefly open it), with
//!   Gaussian measurement noise σ_i = 1 mA, σ_v = 15 mV (SplitMix64 +
//!   Box–Muller, seeded): position RMSE during motion, |z error| at landing,
//!   at T_s = 50 µs and 10 µs (table printed with `--nocapture`);
//!   covariance symmetric and positive definite at every step;
//! - the Jiles–Atherton valve (x = [z, z_prev, φ, H_c]) runs too;
//! - NaN measurements are skipped and do not poison the state.

// index loops over records and small matrices
#![allow(clippy::needless_range_loop)]

use designer::description::{parse_file, parse_str, Core, Description, Drive};
use designer::model::Model;
use designer::observe::discrete::{
    DiscreteModel, Estimate, FluxStep, KalmanSettings, StateKind, MAX_DIM,
};
use designer::observe::ekf::Ekf;
use designer::observe::ukf::Ukf;
use designer::replay::replay;
use designer::sim::{EventKind, Mode, Options, PiecewiseLinear};
use support::{example_path, example_paths, example_physics, replaced_once};

fn example(file: &str) -> Description {
    parse_file(&example_path(file)).unwrap_or_else(|e| panic!("{e}"))
}

fn all_examples() -> Vec<(String, Description)> {
    example_paths()
        .into_iter()
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, parse_file(&p).unwrap_or_else(|e| panic!("{e}")))
        })
        .collect()
}

/// SplitMix64 with Box–Muller normals.
struct Rng {
    state: u64,
    spare: Option<f64>,
}

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng {
            state: seed,
            spare: None,
        }
    }

    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1].
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Standard normal (Box–Muller, both values used).
    fn normal(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = 2.0 * std::f64::consts::PI * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

/// The settings of the tests for T_s (noise of the measurement, process
/// noise tuned on the perfect-tracking valve; see `filters_on_the_valve`).
fn settings(d: &Description, ts: f64) -> KalmanSettings {
    let ja = matches!(d.core, Core::JilesAtherton(_));
    let r = ts / 50e-6;
    KalmanSettings {
        sample_period: ts,
        voltage_noise: 15e-3,
        current_noise: 1e-3,
        process_z: 5e-9 * r,
        process_phi: 1.5e-8 * r,
        process_hc: ja.then_some(20.0 * r),
        initial_z_std: 1e-5,
        initial_phi_std: 1e-7,
        initial_hc_std: ja.then_some(50.0),
        ukf_alpha: 1.0,
        ukf_beta: 2.0,
        ukf_kappa: 0.0,
        flux_step: FluxStep::Euler,
    }
}

// ---------------------------------------------------------------- Jacobians

/// Central differences of the discrete map and the measurement against the
/// symbolic Jacobians, with either flux step. A component whose one-sided differences disagree lies
/// on a kink (the saturation (84a), |φ| at 0, the branch δ = sign(φ̇) of
/// Jiles–Atherton, the clamp (52)) and is skipped; most must be checked.
#[test]
fn symbolic_jacobians_match_finite_differences() {
    let steps = [FluxStep::Euler, FluxStep::Exponential { substeps: 2 }];
    let physics = example_physics("perfect-tracking-valve.toml");
    let current = replaced_once(&physics, "drive = \"voltage\"", "drive = \"current\"");
    let current = parse_str(&current, "current drive").unwrap();
    let subjects = all_examples()
        .into_iter()
        .chain([("current drive".into(), current)]);
    for ((file, d), flux_step) in subjects
        .into_iter()
        .flat_map(|e| steps.map(|s| (e.clone(), s)))
    {
        let model = Model::build(&d);
        let settings = KalmanSettings {
            flux_step,
            ..settings(&d, 50e-6)
        };
        let dm = DiscreteModel::new(&model, &settings).unwrap();
        let mut tapes = dm.tapes();
        let n = dm.dim();
        let m = &d.mechanics;
        let stroke = m.z_max - m.z_min;
        let phi_max = match d.core {
            Core::Saturating { phi_sat, .. } => 0.9 * phi_sat,
            _ => 2.5e-5,
        };
        // typical magnitudes of each state
        let r0 = d.coil.resistance;
        let scale: [f64; MAX_DIM] = std::array::from_fn(|k| match dm.kinds.get(k) {
            Some(StateKind::Flux) => phi_max,
            Some(StateKind::CoreField) => 1000.0,
            Some(StateKind::Resistance) => r0,
            _ => stroke,
        });
        let mut rng = Rng::new(0x5EED_0B5E ^ file.len() as u64);
        let (mut checked, mut skipped) = (0usize, 0usize);
        for _ in 0..100 {
            let z = rng.range(m.z_min + 0.1 * stroke, m.z_max - 0.1 * stroke);
            let v = rng.range(-1.0, 1.0);
            let sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
            let flux = sign * rng.range(0.05, 1.0) * phi_max;
            let mut x = [0.0; MAX_DIM];
            for (k, kind) in dm.kinds.iter().enumerate() {
                x[k] = match kind {
                    StateKind::Position => z,
                    StateKind::PreviousPosition => z - v * 50e-6,
                    StateKind::Flux => flux,
                    StateKind::CoreField => rng.range(-2000.0, 2000.0),
                    StateKind::Resistance => r0 * rng.range(0.9, 1.1),
                };
            }
            let u = rng.range(d.supply.u_min, d.supply.u_max);
            let (jac, gain) = tapes.jacobian(&x, u, 0.0);
            let meas = tapes.measure(&x, u, 0.0);
            // one column per state, then u
            for j in 0..=n {
                let (h, col_scale) = if j < n {
                    (1e-6 * scale[j], scale[j])
                } else {
                    (1e-6 * 24.0, 24.0)
                };
                let at = |tapes: &mut designer::observe::discrete::DiscreteTapes, dx: f64| {
                    let (mut xx, mut uu) = (x, u);
                    if j < n {
                        xx[j] += dx;
                    } else {
                        uu += dx;
                    }
                    let p = tapes.predict(&xx, uu, 0.0);
                    let y = tapes.measure(&xx, uu, 0.0).y;
                    (p.next, y)
                };
                let (fp, yp) = at(&mut tapes, h);
                let (f0, y0) = at(&mut tapes, 0.0);
                let (fm, ym) = at(&mut tapes, -h);
                // rows of F, then h
                for i in 0..=n {
                    let (p, c, mm, sym, row_scale) = if i < n {
                        let row_scale = (0..n)
                            .map(|k| (jac[i][k] * scale[k]).abs())
                            .fold(gain[i].abs() * 24.0, f64::max);
                        let sym = if j < n { jac[i][j] } else { gain[i] };
                        (fp[i], f0[i], fm[i], sym, row_scale)
                    } else {
                        let row_scale = (0..n)
                            .map(|k| (meas.dy_dx[k] * scale[k]).abs())
                            .fold(meas.dy_du.abs() * 24.0, f64::max);
                        let sym = if j < n { meas.dy_dx[j] } else { meas.dy_du };
                        (yp, y0, ym, sym, row_scale)
                    };
                    let forward = (p - c) / h * col_scale;
                    let backward = (c - mm) / h * col_scale;
                    let tol = 1e-6 * row_scale + 1e-14 * c.abs() / h * col_scale;
                    if (forward - backward).abs() > 1e3 * tol {
                        skipped += 1;
                        continue;
                    }
                    let central = (p - mm) / (2.0 * h) * col_scale;
                    let symbolic = sym * col_scale;
                    assert!(
                        (central - symbolic).abs() <= tol,
                        "{file}: ∂F{i}/∂x{j} at x = {x:?}, u = {u}: symbolic {symbolic:e}, \
                         central difference {central:e} (scaled by the column's magnitude)"
                    );
                    checked += 1;
                }
            }
        }
        println!("{file} ({flux_step:?}): {checked} Jacobian entries checked, {skipped} on kinks skipped");
        assert!(
            skipped * 20 < checked,
            "{file}: too many kinks ({skipped} of {})",
            checked + skipped
        );
    }
}

// ---------------------------------------------------------------- the valve

/// An open-loop record: true trajectory and noisy measurements at k·T_s.
struct Record {
    t: Vec<f64>,
    z: Vec<f64>,
    v: Vec<f64>,
    phi: Vec<f64>,
    mode: Vec<Mode>,
    u_meas: Vec<f64>,
    i_meas: Vec<f64>,
    /// (lift-off, first impact) of every stroke.
    strokes: Vec<(f64, f64)>,
}

/// 24 V on [0, 6 ms) closes the valve, 0 V on [6, 10 ms), −24 V on
/// [10, 10.4 ms) pulls the flux down, 0 V after: the valve opens and bounces
/// at z_max. Breakpoints on the sample grid (the filters' zero-order hold).
fn valve_record(d: &Description, ts: f64, t_end: f64, seed: u64) -> Record {
    let mut model = Model::build(d);
    // switching just after the sample: u_k of the record is the voltage held
    // over the sample ending at t_k (the filters' convention) and the current
    // at t_k is the one before the switch
    let k = |t: f64| (t / ts).round() * ts * (1.0 + 1e-9);
    // with current drive the input is the coil current: 0.35 A closes the
    // perfect-tracking valve
    let current_drive = d.supply.drive == Drive::Current;
    let amp = if current_drive { 0.35 } else { 24.0 };
    let input = PiecewiseLinear::steps(&[
        (0.0, amp),
        (k(6e-3), 0.0),
        (k(10e-3), -amp),
        (k(10.4e-3), 0.0),
    ])
    .unwrap();
    let n = (t_end / ts).round() as usize;
    let times: Vec<f64> = (0..=n).map(|k| k as f64 * ts).collect();
    let opts = Options {
        rtol: 1e-10,
        ..Options::default()
    };
    let r = replay(&mut model, &input, &times, &opts).unwrap();
    let mut rng = Rng::new(seed);
    let tr = &r.trajectory;
    let mut strokes = Vec::new();
    let mut lift_off = None;
    for e in &tr.events {
        match e.kind {
            EventKind::LiftOff { .. } => lift_off = Some(e.t),
            EventKind::Impact { .. } => {
                if let Some(a) = lift_off.take() {
                    strokes.push((a, e.t));
                }
            }
            _ => {}
        }
    }
    // u: the input as measured, i: the other coil quantity (the current, or
    // the voltage with current drive)
    let (sigma_v, sigma_i) = (15e-3, 1e-3);
    let (mut u_meas, mut i_meas) = (Vec::new(), Vec::new());
    for k in 0..tr.len() {
        if current_drive {
            u_meas.push(tr.u[k] + sigma_i * rng.normal());
            i_meas.push(r.voltage[k] + sigma_v * rng.normal());
        } else {
            u_meas.push(tr.u[k] + sigma_v * rng.normal());
            i_meas.push(r.current[k] + sigma_i * rng.normal());
        }
    }
    Record {
        t: tr.t.clone(),
        z: tr.component(0),
        v: tr.component(1),
        phi: tr.component(2),
        mode: tr.mode.clone(),
        u_meas,
        i_meas,
        strokes,
    }
}

/// Lower Cholesky factor exists (the covariance is positive definite).
fn positive_definite(n: usize, p: &[[f64; MAX_DIM]; MAX_DIM]) -> bool {
    let mut l = [[0.0; MAX_DIM]; MAX_DIM];
    for i in 0..n {
        for j in 0..=i {
            let mut s = p[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            if i == j {
                if s <= 0.0 || s.is_nan() {
                    return false;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    true
}

fn symmetric(n: usize, p: &[[f64; MAX_DIM]; MAX_DIM]) -> bool {
    (0..n).all(|i| (0..n).all(|j| p[i][j] == p[j][i]))
}

/// What a run of a filter over a record gives.
#[derive(Debug, Clone, Copy)]
struct Scores {
    /// RMSE of z over the strokes (from lift-off to the first impact) [m].
    rmse_motion: f64,
    /// RMSE of z over every sample in free motion, bounces included [m].
    rmse_free: f64,
    /// |ẑ − z| at the last sample before the first impact of the closing and
    /// of the opening stroke [m].
    landing_close: f64,
    landing_open: f64,
    /// RMSE of v during the strokes [m/s].
    rmse_v: f64,
    /// RMSE of φ over the whole run [Wb].
    rmse_phi: f64,
    /// Fraction of the samples at rest on a stop whose estimated mode is that stop.
    rest_agreement: f64,
    /// Fraction of the stroke samples estimated in mode 2.
    stroke_agreement: f64,
    repairs: usize,
}

trait Filter {
    fn step(&mut self, u: f64, y: f64) -> Estimate;
    fn covariance(&self) -> [[f64; MAX_DIM]; MAX_DIM];
    fn dim(&self) -> usize;
    fn repairs(&self) -> usize;
    fn skipped(&self) -> usize;
}

macro_rules! filter_impl {
    ($t:ty) => {
        impl Filter for $t {
            fn step(&mut self, u: f64, y: f64) -> Estimate {
                <$t>::step(self, u, y)
            }
            fn covariance(&self) -> [[f64; MAX_DIM]; MAX_DIM] {
                <$t>::covariance(self)
            }
            fn dim(&self) -> usize {
                <$t>::dim(self)
            }
            fn repairs(&self) -> usize {
                <$t>::repairs(self)
            }
            fn skipped(&self) -> usize {
                <$t>::skipped(self)
            }
        }
    };
}
filter_impl!(Ekf);
filter_impl!(Ukf);

/// Whether sample k lies on a stroke: from a lift-off to the first impact
/// after it (the bounces that follow are not part of it).
fn strokes(r: &Record) -> Vec<bool> {
    r.t.iter()
        .map(|&t| r.strokes.iter().any(|&(a, b)| a <= t && t <= b))
        .collect()
}

/// The last sample at or before `t`.
fn sample_before(r: &Record, t: f64) -> usize {
    r.t.iter().rposition(|&tk| tk <= t).unwrap_or(0)
}

/// Runs the filter over the record, checking at every sample that the
/// covariance is exactly symmetric and positive definite and the estimate
/// finite.
fn run<F: Filter>(filter: &mut F, r: &Record) -> Scores {
    let n = filter.dim();
    let on_stroke = strokes(r);
    let (mut se, mut count, mut se_v, mut se_phi) = (0.0, 0, 0.0, 0.0);
    let (mut se_free, mut count_free) = (0.0, 0);
    let (mut rest, mut rest_ok, mut stroke_ok) = (0, 0, 0);
    let mut errors = Vec::with_capacity(r.t.len());
    for k in 0..r.t.len() {
        let e = filter.step(r.u_meas[k], r.i_meas[k]);
        let p = filter.covariance();
        assert!(
            symmetric(n, &p) && positive_definite(n, &p),
            "covariance not symmetric positive definite at t = {}: {p:?}",
            r.t[k]
        );
        assert!(
            e.z.is_finite() && e.v.is_finite() && e.a.is_finite() && e.phi.is_finite(),
            "{e:?}"
        );
        let dz = e.z - r.z[k];
        errors.push(dz.abs());
        if on_stroke[k] {
            se += dz * dz;
            se_v += (e.v - r.v[k]).powi(2);
            count += 1;
            stroke_ok += usize::from(e.mode == Mode::Free);
        }
        if r.mode[k] == Mode::Free {
            se_free += dz * dz;
            count_free += 1;
        } else {
            rest += 1;
            rest_ok += usize::from(e.mode == r.mode[k]);
        }
        se_phi += (e.phi - r.phi[k]).powi(2);
    }
    assert_eq!(r.strokes.len(), 2, "closing and opening: {:?}", r.strokes);
    let close = sample_before(r, r.strokes[0].1);
    let open = sample_before(r, r.strokes[1].1);
    Scores {
        rmse_motion: (se / count as f64).sqrt(),
        rmse_free: (se_free / count_free as f64).sqrt(),
        landing_close: errors[close],
        landing_open: errors[open],
        rmse_v: (se_v / count as f64).sqrt(),
        rmse_phi: (se_phi / r.t.len() as f64).sqrt(),
        rest_agreement: rest_ok as f64 / rest as f64,
        stroke_agreement: stroke_ok as f64 / count as f64,
        repairs: filter.repairs(),
    }
}

fn print_header() {
    println!(
        "| example | filter | T_s | RMSE z (strokes) | RMSE z (all free motion) | |Δz| closing landing | \
         |Δz| opening landing | RMSE v (strokes) | RMSE φ | mode at rest / on strokes | repairs |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
}

fn print_row(example: &str, name: &str, ts: f64, s: &Scores) {
    println!(
        "| {example} | {name} | {:.0} µs | {:.2} µm | {:.2} µm | {:.2} µm | {:.2} µm | {:.1} mm/s | {:.3} µWb | {:.1} % / {:.1} % | {} |",
        ts * 1e6,
        s.rmse_motion * 1e6,
        s.rmse_free * 1e6,
        s.landing_close * 1e6,
        s.landing_open * 1e6,
        s.rmse_v * 1e3,
        s.rmse_phi * 1e6,
        s.rest_agreement * 100.0,
        s.stroke_agreement * 100.0,
        s.repairs
    );
}

/// Runs both filters on `file` at T_s and checks the bounds.
fn check_example(file: &str, ts: f64) -> [Scores; 2] {
    let d = example(file);
    let model = Model::build(&d);
    let stroke = d.mechanics.z_max - d.mechanics.z_min;
    let r = valve_record(&d, ts, 20e-3, 0xC0FF_EE00);
    let dm = DiscreteModel::new(&model, &settings(&d, ts)).unwrap();
    let ekf = run(&mut Ekf::new(&dm), &r);
    let ukf = run(&mut Ukf::new(&dm), &r);
    let short = file.trim_end_matches(".toml");
    print_row(short, "EKF", ts, &ekf);
    print_row(short, "UKF", ts, &ukf);
    for (name, s) in [("EKF", ekf), ("UKF", ukf)] {
        // Measured (perfect-tracking valve, 50 µs and 10 µs): RMSE on the
        // strokes 0.7–1.1 µm, |Δz| at landing ≤ 5.5 µm, φ to 0.12 µWb. The
        // bounds leave a margin of about 10 (the stroke is 1 mm).
        assert!(s.rmse_motion < 0.01 * stroke, "{file} {name} {ts}: {s:?}");
        assert!(s.landing_close < 0.03 * stroke, "{file} {name} {ts}: {s:?}");
        assert!(s.landing_open < 0.03 * stroke, "{file} {name} {ts}: {s:?}");
        assert!(s.rmse_phi < 1e-6, "{file} {name} {ts}: {s:?}");
        // Bounces are not part of the discretised model (84a saturates), and
        // after the opening the flux is ≈ 0, which leaves z unobservable from
        // the current: over all free motion (bounces included) the RMSE is
        // ≈ 79 µm on the perfect-tracking valve (27 µm with Jiles–Atherton),
        // the estimate resting on the stop while the armature bounces.
        assert!(s.rmse_free < 0.1 * stroke, "{file} {name} {ts}: {s:?}");
        // The mode (86): resting estimates are resting (the stuck phases
        // after the bounces), strokes are moving (but for the first samples
        // after lift-off, when the estimate still sits within the band).
        assert!(s.rest_agreement > 0.95, "{file} {name} {ts}: {s:?}");
        assert!(s.stroke_agreement > 0.9, "{file} {name} {ts}: {s:?}");
        assert_eq!(s.repairs, 0, "{file} {name} {ts}");
    }
    [ekf, ukf]
}

/// The perfect-tracking valve, open loop, T_s = 50 µs and 10 µs (the table
/// of the report: `cargo test -p reldesign-designer --test observe_kalman
/// -- --nocapture`).
#[test]
fn filters_on_the_perfect_tracking_valve() {
    print_header();
    for ts in [50e-6, 10e-6] {
        check_example("perfect-tracking-valve.toml", ts);
    }
}

/// The Jiles–Atherton valve: x = [z, z_prev, φ, H_c].
#[test]
fn filters_on_the_jiles_atherton_valve() {
    print_header();
    let [ekf, ukf] = check_example("jiles-atherton-valve.toml", 50e-6);
    // measured 2.3–2.6 µm on the strokes (the same before the filters moved to the runtime)
    assert!(ekf.rmse_motion < 10e-6 && ukf.rmse_motion < 10e-6);
}

/// The other coil models the examples do not cover: current drive (the
/// measurement is then the coil voltage) and a resistance drift (the model
/// depends on t). Estimates finite, covariance positive definite, strokes
/// tracked.
#[test]
fn current_drive_and_resistance_drift_run() {
    // the physics sections only (a controller needs voltage drive)
    let physics = example_physics("perfect-tracking-valve.toml");
    let variants = [
        (
            "current drive",
            replaced_once(&physics, "drive = \"voltage\"", "drive = \"current\""),
        ),
        (
            "resistance drift",
            replaced_once(
                &physics,
                "eddy = 1500.0",
                "eddy = 1500.0\nresistance_drift = 50.0",
            ),
        ),
    ];
    print_header();
    for (name, text) in variants {
        assert_ne!(text, physics, "{name}");
        let d = parse_str(&text, name).unwrap_or_else(|e| panic!("{e}"));
        let model = Model::build(&d);
        // With current drive the flux follows the current with the time
        // constant k_e/(R_gap + R_core) ≈ 65 µs at z_max (the eddy term alone
        // opposes N·i), so forward Euler (84c) needs a shorter sample period.
        let ts = if name == "current drive" {
            10e-6
        } else {
            50e-6
        };
        let dm = DiscreteModel::new(&model, &settings(&d, ts)).unwrap();
        assert_eq!(dm.uses_time, name == "resistance drift");
        let r = valve_record(&d, ts, 20e-3, 7);
        for (kind, s) in [
            ("EKF", run(&mut Ekf::new(&dm), &r)),
            ("UKF", run(&mut Ukf::new(&dm), &r)),
        ] {
            print_row(name, kind, ts, &s);
            // measured: 3.1 µm (current drive, 10 µs), 2.4–2.5 µm (drift)
            assert!(s.rmse_motion < 20e-6, "{name} {kind}: {s:?}");
        }
    }
}

/// NaN and ∞ samples are skipped (counted), do not poison the state, and the
/// estimate is back on the trajectory after them; a non-finite input is
/// replaced by the last finite one.
#[test]
fn nan_measurements_are_skipped() {
    let d = example("perfect-tracking-valve.toml");
    let model = Model::build(&d);
    let ts = 50e-6;
    let mut r = valve_record(&d, ts, 8e-3, 0xC0FF_EE00);
    let clean = r.i_meas.clone();
    // isolated NaNs, a 1 ms gap of the current during the stroke, a NaN and
    // an ∞ input
    let mut holes = vec![5, 17, 33];
    holes.extend(40..60);
    for &k in &holes {
        r.i_meas[k] = f64::NAN;
    }
    r.u_meas[80] = f64::NAN;
    r.u_meas[81] = f64::INFINITY;
    r.i_meas[90] = f64::NEG_INFINITY;
    let dm = DiscreteModel::new(&model, &settings(&d, ts)).unwrap();
    for ukf in [false, true] {
        let mut f: Box<dyn Filter> = if ukf {
            Box::new(Ukf::new(&dm))
        } else {
            Box::new(Ekf::new(&dm))
        };
        let mut worst_after = 0.0f64;
        for k in 0..r.t.len() {
            let e = f.step(r.u_meas[k], r.i_meas[k]);
            assert!(e.z.is_finite() && e.phi.is_finite() && e.v.is_finite() && e.a.is_finite());
            if r.t[k] > 6e-3 {
                worst_after = worst_after.max((e.z - r.z[k]).abs());
            }
        }
        assert_eq!(f.skipped(), holes.len() + 3, "UKF {ukf}");
        assert_eq!(f.repairs(), 0);
        // resting at z_min again, as the clean run
        assert!(worst_after < 1e-6, "UKF {ukf}: {worst_after:e}");
    }
    assert_eq!(clean.len(), r.i_meas.len());
}

#[test]
fn settings_are_validated() {
    let d = example("perfect-tracking-valve.toml");
    let ja = example("jiles-atherton-valve.toml");
    let (model, ja_model) = (Model::build(&d), Model::build(&ja));
    let ok = settings(&d, 50e-6);
    assert!(DiscreteModel::new(&model, &ok).is_ok());
    let bad = |f: &dyn Fn(&mut KalmanSettings)| {
        let mut s = ok;
        f(&mut s);
        DiscreteModel::new(&model, &s).err().map(|e| e.to_string())
    };
    for (what, msg) in [
        (bad(&|s| s.sample_period = 0.0), "sample_period"),
        (bad(&|s| s.current_noise = -1e-3), "current_noise"),
        (bad(&|s| s.voltage_noise = f64::NAN), "voltage_noise"),
        (bad(&|s| s.process_z = 0.0), "process_z"),
        (
            bad(&|s| s.initial_phi_std = f64::INFINITY),
            "initial_phi_std",
        ),
        (bad(&|s| s.ukf_alpha = 0.0), "ukf_alpha"),
        (bad(&|s| s.ukf_beta = -1.0), "ukf_beta"),
        (bad(&|s| s.ukf_kappa = -3.0), "ukf_kappa"),
        (
            bad(&|s| s.process_hc = Some(1.0)),
            "only to the Jiles–Atherton core",
        ),
    ] {
        let what = what.unwrap_or_else(|| panic!("{msg}: accepted"));
        assert!(what.contains(msg), "{what}");
    }
    let mut s = settings(&ja, 50e-6);
    s.initial_hc_std = None;
    let e = DiscreteModel::new(&ja_model, &s).err().unwrap().to_string();
    assert!(
        e.contains("initial_hc_std") && e.contains("required"),
        "{e}"
    );
}

/// Process noise and sample period sweep (slow; prints the table):
/// `cargo test -p reldesign-designer --test observe_kalman -- --ignored --nocapture`.
#[test]
#[ignore]
fn sweep_process_noise_and_sample_period() {
    print_header();
    for file in ["perfect-tracking-valve.toml", "jiles-atherton-valve.toml"] {
        let d = example(file);
        let model = Model::build(&d);
        for ts in [10e-6, 20e-6, 50e-6, 100e-6] {
            let r = valve_record(&d, ts, 20e-3, 0xC0FF_EE00);
            for factor in [0.3, 1.0, 3.0] {
                let mut s = settings(&d, ts);
                s.process_z *= factor;
                s.process_phi *= factor;
                let dm = DiscreteModel::new(&model, &s).unwrap();
                let name = format!("×{factor} noise");
                print_row(
                    file,
                    &format!("EKF {name}"),
                    ts,
                    &run(&mut Ekf::new(&dm), &r),
                );
                print_row(
                    file,
                    &format!("UKF {name}"),
                    ts,
                    &run(&mut Ukf::new(&dm), &r),
                );
            }
        }
    }
}

/// A sample period beyond twice the coil's electrical time constant makes
/// the flux's Euler step [JA 84c] diverge: refused with τ and the remedy.
#[test]
fn a_sample_period_too_long_for_the_coil_is_refused() {
    let ja = example("jiles-atherton-valve.toml");
    let model = Model::build(&ja);
    // τ = 1.13 ms at z_max (φ = 0; the gap's reluctance and the core's
    // field, R·(R_gap + l_c·dH_c/dφ)/(N² + R·k_e)): 2.2 ms is accepted, 2.3 ms not
    assert!(DiscreteModel::new(&model, &settings(&ja, 2.2e-3)).is_ok());
    let e = DiscreteModel::new(&model, &settings(&ja, 2.3e-3))
        .err()
        .expect("refused");
    let text = e.to_string();
    assert!(
        text.contains("observer.sample_period = 2.3e-3") && text.contains("τ = 1.129e-3 s"),
        "{text}"
    );
    assert!(text.contains("2τ") && text.contains("τ/5"), "{text}");
}
