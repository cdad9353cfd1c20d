//! Identification against synthetic bench data: a bundled example is
//! simulated with a square-wave voltage, seeded Gaussian noise is added
//! (σ_v = 15 mV, σ_i = 1 mA), the parameters to fit are perturbed by 20–50 %,
//! and `identify::fit` must recover them and bring the weighted error down
//! to the noise floor (the error of the true description on the same data).

use std::time::Instant;

use designer::description::{parse_file, Description};
use reldesign_identify::gap_fit::{fit_gap, reluctance_and_slope, GapModel, GapTable};
use reldesign_identify::staged_fit::{first_pulses, fit_staged};
use reldesign_identify::{
    current_wnrmse, edges, fit, params, reduced_parameters, simulate_outputs, FitOptions, FitParam,
    FitReport, Measured, Sensitivities,
};
use support::example_path;

fn example(name: &str) -> Description {
    parse_file(&example_path(name)).unwrap()
}

/// SplitMix64 and Box–Muller: seeded standard normal samples.
struct Noise(u64);

impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (((z ^ (z >> 31)) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// A square wave `high`/`low` of `period` (duty ½) sampled every `dt`, each
/// edge a one-sample ramp (the replay is linear between samples).
fn square(high: f64, low: f64, period: f64, dt: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let v = t
        .iter()
        .map(|t| {
            if (t / period).fract() < 0.5 {
                high
            } else {
                low
            }
        })
        .collect();
    (t, v)
}

/// The description `truth` driven by `v`, measured with noise.
fn synthetic(truth: &Description, t: Vec<f64>, v: Vec<f64>, seed: u64) -> Measured {
    let dt = t[1] - t[0];
    let clean = Measured {
        i: vec![0.0; t.len()],
        z: None,
        phi: None,
        lambda: None,
        dt,
        file_name: "synthetic.csv".into(),
        edges: None,
        t,
        v,
    };
    let sim = simulate_outputs(truth, &clean).unwrap();
    let mut noise = Noise(seed);
    Measured {
        v: clean.v.iter().map(|v| v + 15e-3 * noise.normal()).collect(),
        i: sim
            .current
            .iter()
            .map(|i| i + 1e-3 * noise.normal())
            .collect(),
        ..clean
    }
}

fn perturbed(d: &Description, changes: &[(&str, f64)]) -> Description {
    let mut d = d.clone();
    for (path, factor) in changes {
        let x = params::get(&d, path).unwrap();
        params::set(&mut d, path, x * factor).unwrap();
    }
    d
}

/// The start: `truth` with each of `changes` applied as a factor, and those
/// parameters fitted within ×⅓–3 of the truth.
fn started(truth: &Description, changes: &[(&str, f64)]) -> (Description, Vec<FitParam>) {
    let fitted = changes
        .iter()
        .map(|(p, _)| bounds(truth, p, 3.0, 3.0))
        .collect();
    (perturbed(truth, changes), fitted)
}

fn bounds(d: &Description, path: &str, below: f64, above: f64) -> FitParam {
    let x = params::get(d, path).unwrap();
    FitParam {
        path: path.into(),
        lower: x / below,
        upper: x * above,
    }
}

#[test]
fn saturating_valve_parameters_are_recovered_from_noisy_data() {
    let truth = example("semera-valve.toml");
    // 30 ms at 20 µs: the valve closes and opens once (0/30 V, period 20 ms).
    let (t, v) = square(30.0, 0.0, 20e-3, 20e-6, 1500);
    let data = synthetic(&truth, t, v, 7);
    let changes = [
        ("coil.resistance", 1.3),
        ("core.phi_sat", 0.7),
        ("core.r0", 1.5),
        ("gap.slope", 0.75),
    ];
    let (start, fitted) = started(&truth, &changes);
    let floor = current_wnrmse(&truth, &data).unwrap();
    let before = current_wnrmse(&start, &data).unwrap();
    let clock = Instant::now();
    let report = fit(&start, &data, &fitted, &FitOptions::default(), &|_| {}).unwrap();
    let seconds = clock.elapsed().as_secs_f64();
    assert_eq!(report.sensitivities, Sensitivities::Analytic);
    eprintln!(
        "saturating fit (analytic): {:?}, {seconds:.2} s, {} iterations, {} replays, wNRMSE {before:.4} → {:.5} (floor {floor:.5})\n{}",
        report.status, report.iterations, report.simulations, report.wnrmse_current, report.sensitivity
    );
    let clock = Instant::now();
    let options = FitOptions {
        sensitivities: Sensitivities::FiniteDifference,
        ..FitOptions::default()
    };
    let fd = fit(&start, &data, &fitted, &options, &|_| {}).unwrap();
    eprintln!(
        "saturating fit (finite differences): {:?}, {:.2} s, {} iterations, {} replays, wNRMSE {:.5}",
        fd.status, clock.elapsed().as_secs_f64(), fd.iterations, fd.simulations, fd.wnrmse_current
    );
    assert_eq!(fd.sensitivities, Sensitivities::FiniteDifference);
    // Both Jacobians lead to the same minimum.
    for ((path, a), (_, f)) in report.values.iter().zip(&fd.values) {
        assert!((a / f - 1.0).abs() < 1e-3, "{path}: {a:e} vs {f:e}");
    }
    // Tolerances: R 0.5 %, φ_sat 3 %, R_core0 and the gap slope 3 %.
    for ((path, value), tol) in report.values.iter().zip([5e-3, 3e-2, 3e-2, 3e-2]) {
        let want = params::get(&truth, path).unwrap();
        assert!(
            (value / want - 1.0).abs() < tol,
            "{path}: {value:e} vs {want:e}"
        );
    }
    assert!(
        before > 5.0 * floor,
        "the perturbation must matter: {before} vs {floor}"
    );
    assert!(
        report.wnrmse_current < 1.02 * floor,
        "{} vs floor {floor}",
        report.wnrmse_current
    );
    assert!(report.status.converged(), "{:?}", report.status);
}

/// A fit's `stop` reaches its solver: raised from the progress callback
/// (in `diagnose`, another thread's fit) after the second iteration, the
/// fit ends there, not converged, with the values of that iteration.
#[test]
fn a_fit_stops_when_its_stop_is_raised() {
    let truth = example("semera-valve.toml");
    let (t, v) = square(30.0, 0.0, 20e-3, 20e-6, 1500);
    let data = synthetic(&truth, t, v, 7);
    let start = perturbed(&truth, &[("coil.resistance", 1.3), ("core.r0", 1.5)]);
    let fitted = [
        bounds(&truth, "coil.resistance", 3.0, 3.0),
        bounds(&truth, "core.r0", 3.0, 3.0),
    ];
    let stop = reldesign_identify::lm::Stop::default();
    let options = FitOptions {
        stop: Some(stop.clone()),
        ..FitOptions::default()
    };
    let at_two = |p: reldesign_identify::FitProgress| {
        if p.iteration == 2 {
            stop.raise();
        }
    };
    let stopped = fit(&start, &data, &fitted, &options, &at_two).unwrap();
    assert_eq!(stopped.status, reldesign_identify::lm::Status::Stopped);
    assert_eq!(stopped.iterations, 2);
    // unstopped, the same fit goes on to converge
    let whole = fit(&start, &data, &fitted, &FitOptions::default(), &|_| {}).unwrap();
    assert!(
        whole.status.converged() && whole.iterations > 2,
        "{whole:?}"
    );
}

/// The five Jiles–Atherton parameters (79) on the JA valve: ±24 V, 10 µs
/// samples, so that the plunger closes and the core saturates.
fn ja_case(n: usize) -> (Description, Description, Measured, Vec<FitParam>) {
    let truth = example("jiles-atherton-valve.toml");
    let (t, v) = square(24.0, -24.0, 20e-3, 10e-6, n);
    let data = synthetic(&truth, t, v, 11);
    let changes = [
        ("core.m_sat", 1.3),
        ("core.b", 0.7),
        ("core.c", 0.8),
        ("core.kappa", 1.4),
        ("core.alpha", 1.25),
    ];
    let (start, mut fitted) = started(&truth, &changes);
    fitted[2] = FitParam {
        path: "core.c".into(),
        lower: 0.3,
        upper: 0.95,
    };
    (truth, start, data, fitted)
}

fn check_ja_fit(n: usize, tolerance: f64) {
    let (truth, start, data, fitted) = ja_case(n);
    let floor = current_wnrmse(&truth, &data).unwrap();
    let before = current_wnrmse(&start, &data).unwrap();
    let clock = Instant::now();
    let report = fit(&start, &data, &fitted, &FitOptions::default(), &|_| {}).unwrap();
    let seconds = clock.elapsed().as_secs_f64();
    eprintln!(
        "JA fit, {n} samples: {:?}, {seconds:.2} s, {} iterations, {} replays, wNRMSE {before:.4} → {:.5} (floor {floor:.5})\n{}",
        report.status, report.iterations, report.simulations, report.wnrmse_current, report.sensitivity
    );
    for (path, value) in &report.values {
        let want = params::get(&truth, path).unwrap();
        eprintln!(
            "  {path}: {value:e} (true {want:e}, {:+.3} %)",
            100.0 * (value / want - 1.0)
        );
    }
    // M_sat is pinned hardest (saturation), κ least (its relative standard
    // error is the largest): tolerances 1 %, b, c, α `tolerance`, κ 2·`tolerance`.
    for (path, value) in &report.values {
        let want = params::get(&truth, path).unwrap();
        let tol = match path.as_str() {
            "core.m_sat" => 0.01,
            "core.kappa" => 2.0 * tolerance,
            _ => tolerance,
        };
        assert!(
            (value / want - 1.0).abs() < tol,
            "{path}: {value:e} vs {want:e}"
        );
    }
    assert!(
        before > 3.0 * floor,
        "the perturbation must matter: {before} vs {floor}"
    );
    assert!(
        report.wnrmse_current < 1.02 * floor,
        "{} vs floor {floor}",
        report.wnrmse_current
    );
}

#[test]
fn jiles_atherton_parameters_are_recovered_from_a_short_record() {
    check_ja_fit(4000, 0.04);
}

/// The benchmark case: 40 000 samples (0.4 s at 10 µs). Slow; run
/// by `benches/fit.sh`, which prints the time.
#[test]
#[ignore]
fn jiles_atherton_parameters_are_recovered_from_40000_samples() {
    check_ja_fit(40_000, 0.04);
}

/// The description with N → s·N, l_c → p·l_c, A_c → p·A_c and the other
/// parameters moved so that every reduced parameter (55), (57), (60) stays.
fn same_reduced_model(d: &Description, s: f64, p: f64) -> Description {
    let mut e = d.clone();
    let get = |path: &str| params::get(d, path).unwrap();
    let mut set = |path: &str, x: f64| params::set(&mut e, path, x).unwrap();
    let vacuum = get("core.length") / (designer::model::MU0 * get("core.area"));
    set("coil.turns", s * get("coil.turns"));
    set("coil.eddy", s * s * get("coil.eddy"));
    set("gap.r0_prime", s * s * get("gap.r0_prime"));
    // (57): R_g0 + l_c/(μ0·A_c) scales by s²; l_c/(μ0·A_c) is unchanged for p = q.
    set("gap.r0", s * s * (get("gap.r0") + vacuum) - vacuum);
    set("core.length", p * get("core.length"));
    set("core.area", p * get("core.area"));
    set("core.m_sat", get("core.m_sat") * s / p);
    set("core.b", get("core.b") / (s * p));
    set("core.kappa", get("core.kappa") / (s * p));
    set("core.alpha", 1.0 - (1.0 - get("core.alpha")) / (s * s));
    e
}

#[test]
fn descriptions_with_the_same_reduced_parameters_give_the_same_current() {
    let a = example("jiles-atherton-valve.toml");
    let b = same_reduced_model(&a, 1.1, 1.2);
    let (ra, rb) = (
        reduced_parameters(&a).unwrap(),
        reduced_parameters(&b).unwrap(),
    );
    let fields = |r: reldesign_identify::ReducedParameters| {
        [
            r.k_e,
            r.r_g0,
            r.r_g0_prime,
            r.m_sat,
            r.b,
            r.kappa,
            r.alpha,
            r.c,
            r.resistance,
        ]
    };
    for (x, y) in fields(ra).iter().zip(fields(rb)) {
        assert!((x / y - 1.0).abs() < 1e-12, "{ra:?} vs {rb:?}");
    }
    assert_ne!(
        params::get(&a, "core.m_sat").unwrap(),
        params::get(&b, "core.m_sat").unwrap()
    );
    let (t, v) = square(24.0, -24.0, 20e-3, 10e-6, 3000);
    let data = synthetic(&a, t, v, 3);
    let (ia, ib) = (
        simulate_outputs(&a, &data).unwrap(),
        simulate_outputs(&b, &data).unwrap(),
    );
    let peak = ia.current.iter().fold(0.0f64, |m, i| m.max(i.abs()));
    let worst = ia
        .current
        .iter()
        .zip(&ib.current)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(
        worst < 1e-6 * peak,
        "currents differ by {worst:e} A (peak {peak:e} A)"
    );
    let zs =
        ia.z.iter()
            .zip(&ib.z)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(zs < 1e-9, "positions differ by {zs:e} m");
    // A perturbation off the invariant manifold does change the current.
    let c = perturbed(&a, &[("core.m_sat", 1.01)]);
    let ic = simulate_outputs(&c, &data).unwrap();
    let moved = ia
        .current
        .iter()
        .zip(&ic.current)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(moved > 1e3 * worst.max(1e-12), "{moved:e}");
}

#[test]
fn the_sensitivity_report_flags_the_over_parameterisation() {
    // With s = 1 the invariance is l_c, A_c ∝ p and M_sat, b, κ ∝ 1/p: in
    // ln θ the direction (1, 1, −1, −1, −1)/√5.
    let truth = example("jiles-atherton-valve.toml");
    let (t, v) = square(24.0, -24.0, 20e-3, 10e-6, 3000);
    let data = synthetic(&truth, t, v, 5);
    let paths = [
        "core.length",
        "core.area",
        "core.m_sat",
        "core.b",
        "core.kappa",
    ];
    let fitted: Vec<FitParam> = paths.iter().map(|p| bounds(&truth, p, 3.0, 3.0)).collect();
    let s =
        reldesign_identify::em_fit::sensitivity_at(&truth, &data, &fitted, &FitOptions::default())
            .unwrap();
    eprintln!("{s}");
    assert_eq!(s.weak_directions.len(), 1, "{s}");
    let want = [1.0, 1.0, -1.0, -1.0, -1.0].map(|x: f64| x / 5f64.sqrt());
    for (name, c) in &s.weak_directions[0] {
        let k = paths.iter().position(|p| p == name).unwrap();
        assert!((c - want[k]).abs() < 1e-3, "{s}");
    }
    assert!(s.to_string().contains("cannot separate"));
    // Without A_c the remaining four are separated.
    let s4 = reldesign_identify::em_fit::sensitivity_at(
        &truth,
        &data,
        &[
            fitted[0].clone(),
            fitted[2].clone(),
            fitted[3].clone(),
            fitted[4].clone(),
        ],
        &FitOptions::default(),
    )
    .unwrap();
    assert!(s4.identifiable(), "{s4}");
}

/// A McLyman-fit table generated by the model itself, with 0.2 % noise.
fn gap_table(theta: [f64; 4], with_slope: bool) -> GapTable {
    let mut noise = Noise(17);
    let z: Vec<f64> = (0..30).map(|k| 1e-5 + k as f64 * 3e-5).collect();
    let eval: Vec<(f64, f64)> = z.iter().map(|&z| reluctance_and_slope(theta, z)).collect();
    GapTable {
        r: eval
            .iter()
            .map(|e| e.0 * (1.0 + 2e-3 * noise.normal()))
            .collect(),
        r_prime: with_slope.then(|| {
            eval.iter()
                .map(|e| e.1 * (1.0 + 2e-3 * noise.normal()))
                .collect()
        }),
        z,
        file_name: "gap.csv".into(),
    }
}

#[test]
fn gap_fit_recovers_mclyman_fit_parameters() {
    let theta = [2.41e6, 7.94e10, 1350.0, 9.95e-3];
    let fit = fit_gap(&gap_table(theta, true), GapModel::McLymanFit).unwrap();
    eprintln!("{fit:?}");
    // Tolerances: r0' 1 %, r0 5 %, k1 10 %, k2 25 % (k2 enters through a logarithm).
    for ((name, got), (want, tol)) in fit
        .values
        .iter()
        .zip(theta.iter().zip([0.05, 0.01, 0.1, 0.25]))
    {
        assert!(
            (got / want - 1.0).abs() < tol,
            "{name}: {got:e} vs {want:e}"
        );
    }
    assert!(
        fit.nrmse_r < 3e-3 && fit.nrmse_r_prime.unwrap() < 3e-3,
        "{fit:?}"
    );
}

#[test]
fn gap_fit_recovers_mclyman_area_and_winding_length() {
    let (area, lw) = (20e-6, 15e-3);
    let mu0 = designer::model::MU0;
    let theta = [0.0, 1.0 / (mu0 * area), 1.0 / area.sqrt(), 2.0 * lw];
    let fit = fit_gap(&gap_table(theta, false), GapModel::McLyman).unwrap();
    eprintln!("{fit:?}");
    assert!((fit.values[0].1 / area - 1.0).abs() < 0.01, "{fit:?}");
    assert!((fit.values[1].1 / lw - 1.0).abs() < 0.1, "{fit:?}");
    assert!(fit.nrmse_r < 3e-3 && fit.nrmse_r_prime.is_none());
}

/// The starts of a multi-start fit run in parallel: the report must be the
/// one the starts give one after the other, whatever the threads' timing
/// (one thread, and more threads than starts, give the same bits).
#[test]
fn parallel_starts_give_the_same_report_on_any_number_of_threads() {
    let truth = example("semera-valve.toml");
    let (t, v) = square(30.0, 0.0, 20e-3, 20e-6, 600);
    let data = synthetic(&truth, t, v, 17);
    let changes = [("coil.resistance", 1.2), ("core.phi_sat", 0.8)];
    let (start, fitted) = started(&truth, &changes);
    let options = FitOptions {
        starts: 4,
        ..FitOptions::default()
    };
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| fit(&start, &data, &fitted, &options, &|_| {}).unwrap())
    };
    let (one, many) = (on(1), on(6));
    let bits = |r: &FitReport| -> Vec<u64> {
        let values = r.values.iter().map(|(_, v)| v.to_bits());
        values
            .chain([r.cost.to_bits(), r.wnrmse_current.to_bits()])
            .collect()
    };
    assert_eq!(bits(&one), bits(&many));
    assert_eq!(
        (one.best_start, one.iterations, one.simulations, one.status),
        (
            many.best_start,
            many.iterations,
            many.simulations,
            many.status
        )
    );
    assert!(
        one.iterations > 4,
        "every start iterates: {}",
        one.iterations
    );
}

/// A record of `periods` square-wave periods of the saturating valve at
/// 20 µs, 400 samples each, its edges located by the truth.
fn pulses(periods: usize, seed: u64) -> (Description, Measured) {
    let truth = example("semera-valve.toml");
    let (t, v) = square(30.0, 0.0, 8e-3, 20e-6, 400 * periods);
    let mut data = synthetic(&truth, t, v, seed);
    data.edges = Some(edges::located(&truth, &data));
    (truth, data)
}

/// The first stage of a staged fit ends just before a voltage edge, past a
/// quarter of the record, with two whole pulses (four edges) before it;
/// none without located edges or where the record is too short.
#[test]
fn the_first_pulses_end_before_an_edge_past_a_quarter_of_the_record() {
    let (_, data) = pulses(24, 3);
    let n = data.len();
    let end = first_pulses(&data).expect("a long record of pulses has first pulses");
    let edges = data.edges.as_ref().unwrap();
    assert!(n / 4 <= end && 2 * end <= n, "{end} of {n}");
    assert!(
        edges.iter().any(|e| e.k + 1 == end),
        "{end}: not before an edge"
    );
    assert!(edges.iter().filter(|e| e.k + 1 < end).count() >= 4);
    // the edge before it is before the quarter: the first edge past it
    let before = edges.iter().filter(|e| e.k + 1 < end).last().unwrap();
    assert!(before.k < n / 4, "{} ≥ {}", before.k, n / 4);

    let unlocated = Measured {
        edges: None,
        ..data.clone()
    };
    assert_eq!(first_pulses(&unlocated), None);
    let (_, short) = pulses(8, 3);
    assert_eq!(first_pulses(&short), None, "3200 samples: one stage");
    let with_edges = |edges: Vec<reldesign_identify::edges::Edge>| Measured {
        edges: Some(edges),
        ..data.clone()
    };
    assert_eq!(first_pulses(&with_edges(Vec::new())), None, "no edges");
    assert_eq!(
        first_pulses(&with_edges(edges[..4].to_vec())),
        None,
        "two pulses only"
    );
    // the first edge past the quarter with four before it lies past half
    let mut late = edges[..4].to_vec();
    late.extend(edges.iter().filter(|e| 10 * e.k > 6 * n).copied());
    assert_eq!(first_pulses(&with_edges(late)), None, "past half");
}

/// A staged fit races the starts on the first pulses and fits the winner
/// alone on the whole record: its report is that start's one-stage fit bit
/// for bit (`only_start`), at the whole record's best cost (here one of the
/// three starts ends in a worse minimum, and two in the same one), with
/// fewer replays of the whole record.
#[test]
fn a_staged_fit_gives_the_one_stage_fit_of_its_best_start() {
    let (truth, data) = pulses(24, 11);
    let changes = [
        ("coil.resistance", 1.2),
        ("core.phi_sat", 0.7),
        ("core.r0", 1.4),
    ];
    let (start, fitted) = started(&truth, &changes);
    let options = FitOptions {
        starts: 3,
        use_flux: false,
        ..FitOptions::default()
    };
    let bits = |r: &FitReport| -> Vec<u64> {
        let values = r.values.iter().map(|(_, v)| v.to_bits());
        values
            .chain([r.cost.to_bits(), r.wnrmse_current.to_bits()])
            .collect()
    };
    let whole = fit(&start, &data, &fitted, &options, &|_| {}).unwrap();
    let each: Vec<FitReport> = (0..3)
        .map(|k| {
            let only = FitOptions {
                only_start: Some(k),
                ..options.clone()
            };
            fit(&start, &data, &fitted, &only, &|_| {}).unwrap()
        })
        .collect();
    let best = each.iter().map(|r| r.cost).fold(f64::INFINITY, f64::min);
    let worst = each.iter().map(|r| r.cost).fold(0.0, f64::max);
    assert!(
        worst > 1.2 * best,
        "a start the race must avoid: {worst:e} vs {best:e}"
    );
    assert_eq!(bits(&each[whole.best_start]), bits(&whole));
    assert_eq!(each[whole.best_start].best_start, whole.best_start);

    let staged = fit_staged(&start, &data, &fitted, &options).unwrap();
    let alone = &each[staged.best_start];
    assert_eq!(bits(&staged), bits(alone));
    // every stage counted: the race on the first pulses, then the winner
    let end = first_pulses(&data).unwrap();
    let race = fit(&start, &data.head(end), &fitted, &options, &|_| {}).unwrap();
    assert_eq!(race.best_start, staged.best_start);
    assert_eq!(staged.iterations, race.iterations + alone.iterations);
    assert_eq!(staged.simulations, race.simulations + alone.simulations);
    // a start that is not one of them is an error that says so
    let beyond = FitOptions {
        only_start: Some(3),
        ..options.clone()
    };
    let err = fit(&start, &data, &fitted, &beyond, &|_| {}).unwrap_err();
    assert!(err.to_string().contains("start 3"), "{err}");
    assert!(
        staged.cost <= best * (1.0 + 1e-6),
        "{:e} vs {best:e}",
        staged.cost
    );
    eprintln!(
        "best starts: one stage {}, staged {}; one stage {} iterations, {} replays; staged {} iterations, {} replays ({} of the whole record)",
        whole.best_start,
        staged.best_start,
        whole.iterations,
        whole.simulations,
        staged.iterations,
        staged.simulations,
        alone.simulations
    );
    // the replays of the whole record the race saves
    assert!(alone.simulations < whole.simulations);
}
