//! Outside check (issue 5 §4): the Modelica Standard Library solenoid against
//! its FEA tables (`../shared/data/msl-solenoid`, not written by this project).
//!
//! - The gap of `examples/msl-solenoid.toml` is re-derived from the quasi-static
//!   FEA table (R = N·i/φ − R_core, R' = −2·F/φ² from F = −½·R_gap'·φ²) and refitted
//!   (`gap_fit`, [JA 76–77]): the example cannot drift from its source.
//! - The 12 V pull-in is simulated and compared with the FEA transient: current
//!   NRMSE, first arrival at the 0.25 mm stopper, the back-EMF current dip.
//! - `diagnose` runs on the FEA transient written as a measured-data CSV.
//!
//! The asserted figures are the measured ones with a small margin: regression
//! checks of an outside comparison (they are printed with `--nocapture`).

use std::path::{Path, PathBuf};

use designer::description::{Description, Gap};
use designer::record::Record;
use reldesign_identify::diagnose::{diagnose, Cause, Options};
use reldesign_identify::gap_fit::{fit_gap, GapModel, GapTable};
use reldesign_identify::{simulate_outputs, Measured, SimOutputs};
use support::{assert_close, TempDir, Tol};

/// Coil current of the quasi-static FEA [A] (12 V on 10 Ω; data README).
const I_STATIC: f64 = 1.2;
/// The step voltage of the transient [V] (data README).
const V_STEP: f64 = 12.0;
/// The resampling period of the CSV given to `diagnose` [s]: most FEA rows lie
/// on this grid.
const DT: f64 = 1e-4;
/// The output period of the pull-in simulations [s]: fine enough to time the
/// arrival to 10 µs.
const DT_SIM: f64 = 1e-5;
const EXAMPLE: &str = "msl-solenoid.toml";
/// The FEA's first arrival at the 0.25 mm stopper [s] (a row of the table).
const FEA_ARRIVAL: f64 = 12.6134e-3;

fn data_dir() -> PathBuf {
    reldesign_tests::root().join("../shared/data/msl-solenoid")
}

fn read_record(name: &str) -> Record {
    let path = data_dir().join(name);
    Record::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn column(record: &Record, name: &str) -> Vec<f64> {
    record
        .column(name)
        .unwrap_or_else(|e| panic!("{}: {e}", record.file_name))
}

/// Which flux of the quasi-static FEA is the model's φ.
#[derive(Debug, Clone, Copy)]
enum Flux {
    /// φ = L·i/N: the flux linkage per turn, what the coil's voltage sees (the example's).
    Linkage,
    /// φ = the FEA's armature flux (column `phi`).
    Armature,
}

/// The gap table of the quasi-static FEA: R_gap = N·i/φ − R_core (the core's
/// constant share is the example's `core.r0`), R_gap' = −2·F/φ² (from the
/// model's force F = −½·R_gap'·φ²).
fn gap_table(desc: &Description, flux: Flux) -> GapTable {
    let record = read_record("quasistatic-12V-fea.csv");
    let n = desc.coil.turns;
    let phi: Vec<f64> = match flux {
        Flux::Linkage => column(&record, "inductance")
            .iter()
            .map(|l| l * I_STATIC / n)
            .collect(),
        Flux::Armature => column(&record, "phi"),
    };
    let (z, force) = (column(&record, "z"), column(&record, "force"));
    let r_core = match desc.core {
        designer::description::Core::Linear { r0 } => r0,
        ref other => panic!("{EXAMPLE}: expected a linear core, found {other:?}"),
    };
    GapTable {
        r: phi.iter().map(|p| n * I_STATIC / p - r_core).collect(),
        r_prime: Some(
            force
                .iter()
                .zip(&phi)
                .map(|(f, p)| -2.0 * f / (p * p))
                .collect(),
        ),
        z,
        file_name: record.file_name,
    }
}

/// The FEA transient as recorded (non-uniform t).
struct Transient {
    t: Vec<f64>,
    i: Vec<f64>,
    z: Vec<f64>,
}

fn transient() -> Transient {
    let record = read_record("pullin-12V-fea.csv");
    Transient {
        t: column(&record, "t"),
        i: column(&record, "i"),
        z: column(&record, "z"),
    }
}

/// Linear interpolation of (t, x) at `at` (t increasing; clamped at the ends).
fn interpolate(t: &[f64], x: &[f64], at: f64) -> f64 {
    let k = t.partition_point(|s| *s <= at);
    if k == 0 {
        return x[0];
    }
    if k == t.len() {
        return x[k - 1];
    }
    let (t0, t1) = (t[k - 1], t[k]);
    x[k - 1] + (x[k] - x[k - 1]) * (at - t0) / (t1 - t0)
}

/// The transient on a uniform grid t = 0, dt, … (the spec's CSV needs uniform
/// samples). Linear interpolation: at dt = 0.1 ms the FEA rows are already on
/// the grid but for extra rows the solver added at events (impacts), which it
/// drops; a finer grid only adds points on the FEA's own straight segments.
/// The voltage is the 12 V step: v = 12 V from the row at t = 0 on.
fn measured(fea: &Transient, dt: f64) -> Measured {
    let end = fea.t[fea.t.len() - 1];
    let n = (end / dt).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let at = |x: &[f64]| t.iter().map(|s| interpolate(&fea.t, x, *s)).collect();
    Measured {
        v: vec![V_STEP; n],
        i: at(&fea.i),
        z: Some(at(&fea.z)),
        phi: None,
        lambda: None,
        dt,
        file_name: "pullin-12V-fea.csv (resampled)".into(),
        edges: None,
        t,
    }
}

/// √(Σ (sim − exp)²/Σ exp²), as [JA 77].
fn nrmse(sim: &[f64], exp: &[f64]) -> f64 {
    let num: f64 = sim.iter().zip(exp).map(|(s, e)| (s - e).powi(2)).sum();
    let den: f64 = exp.iter().map(|e| e * e).sum();
    (num / den).sqrt()
}

/// The first time z reaches `stop` (interpolated between samples).
fn first_arrival(t: &[f64], z: &[f64], stop: f64) -> Option<f64> {
    let k = z.iter().position(|z| *z <= stop + 1e-12)?;
    if k == 0 {
        return Some(t[0]);
    }
    let s = (z[k - 1] - stop) / (z[k - 1] - z[k]);
    Some(t[k - 1] + s * (t[k] - t[k - 1]))
}

/// The current dip of the back-EMF: (time of the current's peak before the
/// arrival, time of its minimum between the peak and 1 ms after the arrival).
fn dip(t: &[f64], i: &[f64], arrival: f64) -> (f64, f64) {
    let argmax = |lo: f64, hi: f64, sign: f64| {
        t.iter()
            .zip(i)
            .filter(|(s, _)| **s >= lo && **s <= hi)
            .max_by(|a, b| (sign * a.1).total_cmp(&(sign * b.1)))
            .map_or(f64::NAN, |(s, _)| *s)
    };
    let peak = argmax(0.0, arrival, 1.0);
    (peak, argmax(peak, arrival + 1e-3, -1.0))
}

/// The landing: the last time z comes down onto `stop` (interpolated), after
/// which it does not rise above it again.
fn landing(t: &[f64], z: &[f64], stop: f64) -> f64 {
    let Some(k) = z.iter().rposition(|z| *z > stop + 1e-12) else {
        return t[0];
    };
    first_arrival(&t[k..], &z[k..], stop).unwrap_or(f64::NAN)
}

/// Figures of one pull-in.
#[derive(Debug)]
struct PullIn {
    arrival: f64,
    peak: f64,
    dip: f64,
    landing: f64,
}

fn pull_in(t: &[f64], i: &[f64], z: &[f64], z_min: f64) -> PullIn {
    let arrival = first_arrival(t, z, z_min).unwrap_or_else(|| panic!("z never reaches {z_min}"));
    let (peak, dip) = dip(t, i, arrival);
    PullIn {
        arrival,
        peak,
        dip,
        // The FEA's compliant stop lets z settle 30 µm beyond 0.25 mm; the
        // landing is the last crossing of 0.25 mm downwards.
        landing: landing(t, z, z_min),
    }
}

fn simulate(desc: &Description, data: &Measured) -> SimOutputs {
    simulate_outputs(desc, data).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn gap_fit_reproduces_the_example() {
    let desc = reldesign_tests::example(EXAMPLE);
    let fit = fit_gap(&gap_table(&desc, Flux::Linkage), GapModel::McLymanFit)
        .unwrap_or_else(|e| panic!("{e}"));
    let Gap::McLymanFit {
        r0,
        r0_prime,
        k1,
        k2,
    } = desc.gap
    else {
        panic!("{EXAMPLE}: expected gap.model = \"mclyman-fit\"");
    };
    let committed = [("r0", r0), ("r0_prime", r0_prime), ("k1", k1), ("k2", k2)];
    for ((name, value), (_, fitted)) in committed.iter().zip(&fit.values) {
        println!("gap.{name}: committed {value:.6e}, refitted {fitted:.6e}");
        let scale = value.abs().max(1.0);
        assert!(
            (value - fitted).abs() <= 1e-6 * scale,
            "{EXAMPLE}: gap.{name} = {value:e} but the FEA table fits {fitted:e}; \
             refit with `reldesign fit … --gap mclyman-fit --out`"
        );
    }
    let nrmse_rp = fit.nrmse_r_prime.unwrap_or(f64::NAN);
    println!(
        "gap fit NRMSE (77): R {:.3} %, R' {:.3} %",
        100.0 * fit.nrmse_r,
        100.0 * nrmse_rp
    );
    // Measured 2.53 % and 1.71 %: the table's R and R' disagree at small gaps (saturation).
    assert!(fit.nrmse_r < 0.027, "NRMSE R = {}", fit.nrmse_r);
    assert!(nrmse_rp < 0.018, "NRMSE R' = {nrmse_rp}");
}

/// The simulated pull-in of `desc` against the FEA: (current NRMSE, figures).
/// With `print`, a few samples of both and the current NRMSE before and after
/// the FEA's arrival at the stopper are printed.
fn compare(desc: &Description, data: &Measured, print: bool) -> (f64, PullIn) {
    let sim = simulate(desc, data);
    let e_i = nrmse(&sim.current, &data.i);
    if print {
        let k = data.t.partition_point(|t| *t < FEA_ARRIVAL);
        println!(
            "current NRMSE (77): {:.2} % before the FEA's arrival, {:.2} % after",
            100.0 * nrmse(&sim.current[..k], &data.i[..k]),
            100.0 * nrmse(&sim.current[k..], &data.i[k..])
        );
    }
    let figures = pull_in(&sim.t, &sim.current, &sim.z, desc.mechanics.z_min);
    if print {
        report(data, &sim);
    }
    (e_i, figures)
}

#[test]
fn pull_in_against_the_fea_transient() {
    let desc = reldesign_tests::example(EXAMPLE);
    let fea = transient();
    let data = measured(&fea, DT_SIM);
    let fea_figs = pull_in(&fea.t, &fea.i, &fea.z, desc.mechanics.z_min);
    let (e_i, sim_figs) = compare(&desc, &data, true);
    println!("current NRMSE (77) over 0…50 ms: {:.2} %", 100.0 * e_i);
    println!("FEA:        {fea_figs:?}");
    println!("simulation: {sim_figs:?}");
    // The FEA figures are rows of the table (a check of this test's reading
    // of it): arrival 12.6134 ms, current peak 7.6 ms, dip bottom 12.6868 ms,
    // landing after two rebounds 15.0127 ms.
    assert_close(fea_figs.arrival, FEA_ARRIVAL, Tol::abs(1e-7), "FEA arrival");
    assert_close(fea_figs.peak, 7.6e-3, Tol::abs(1e-7), "FEA peak");
    assert_close(fea_figs.dip, 12.6868e-3, Tol::abs(1e-7), "FEA dip");
    assert_close(fea_figs.landing, 15.0127e-3, Tol::abs(1e-7), "FEA landing");
    // Measured: NRMSE 9.14 %, arrival 12.74 ms, peak 7.95 ms, the dip's
    // bottom and the landing at the arrival (γ = 0: no rebound).
    assert!(e_i < 0.095, "current NRMSE {e_i}");
    assert_close(
        sim_figs.arrival,
        12.74e-3,
        Tol::abs(0.05e-3),
        "simulated arrival",
    );
    assert_close(sim_figs.peak, 7.95e-3, Tol::abs(0.1e-3), "simulated peak");
    assert_close(sim_figs.dip, 12.74e-3, Tol::abs(0.05e-3), "simulated dip");
    assert_close(
        sim_figs.landing,
        sim_figs.arrival,
        Tol::abs(1e-9),
        "simulated landing",
    );
}

/// The example's choice of φ (flux linkage per turn, not the armature flux):
/// the armature-flux table, fitted the same way, simulates a worse pull-in.
#[test]
fn linkage_flux_beats_the_armature_flux() {
    let desc = reldesign_tests::example(EXAMPLE);
    let fea = transient();
    let data = measured(&fea, DT_SIM);
    let with = |flux: Flux| {
        let fit = fit_gap(&gap_table(&desc, flux), GapModel::McLymanFit)
            .unwrap_or_else(|e| panic!("{e}"));
        let mut d = desc.clone();
        d.gap = fit.gap;
        let (e_i, figs) = compare(&d, &data, false);
        println!(
            "{flux:?}: gap NRMSE R {:.2} %, R' {:.2} %; current NRMSE {:.2} %; {figs:?}",
            100.0 * fit.nrmse_r,
            100.0 * fit.nrmse_r_prime.unwrap_or(f64::NAN),
            100.0 * e_i
        );
        (e_i, figs.arrival)
    };
    let (linkage, armature) = (with(Flux::Linkage), with(Flux::Armature));
    let fea_arrival = first_arrival(&fea.t, &fea.z, desc.mechanics.z_min).unwrap_or(f64::NAN);
    assert!(
        linkage.0 < armature.0,
        "current NRMSE {linkage:?} vs {armature:?}"
    );
    assert!(
        (linkage.1 - fea_arrival).abs() < (armature.1 - fea_arrival).abs(),
        "arrival {linkage:?} vs {armature:?}, FEA {fea_arrival}"
    );
}

/// A few samples of the FEA and the simulation, for the README.
fn report(data: &Measured, sim: &SimOutputs) {
    for ms in [1, 3, 5, 7, 9, 11, 12, 13, 15, 20, 30, 40, 50] {
        let k = ((ms as f64 * 1e-3) / data.dt).round() as usize;
        let k = k.min(data.t.len() - 1);
        let z = data.z.as_ref().map_or(f64::NAN, |z| z[k]);
        println!(
            "t = {ms:2} ms: i FEA {:.4} A, sim {:.4} A; z FEA {:.3} mm, sim {:.3} mm",
            data.i[k],
            sim.current[k],
            1e3 * z,
            1e3 * sim.z[k]
        );
    }
}

/// The measured-data CSV (`shared/spec/measured-data.md`): t,v,i,z.
fn write_csv(path: &Path, data: &Measured) {
    let z = data.z.as_ref().expect("the resampled transient has z");
    let mut text = String::from(
        "# MSL solenoid FEA pull-in (pullin-12V-fea.csv), resampled to 0.1 ms; v: 12 V step at t = 0\n\
         t,v,i,z\n",
    );
    for k in 0..data.t.len() {
        text += &format!(
            "{:e},{:e},{:e},{:e}\n",
            data.t[k], data.v[k], data.i[k], z[k]
        );
    }
    std::fs::write(path, text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

#[test]
fn diagnose_the_fea_record() {
    let desc = reldesign_tests::example(EXAMPLE);
    let dir = TempDir::new("msl-solenoid");
    let path = dir.join("pullin-12V-fea-uniform.csv");
    write_csv(&path, &measured(&transient(), DT));
    let data = Measured::read(&path).unwrap_or_else(|e| panic!("{e}"));
    let d = diagnose(&desc, &data, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    drop(dir);
    println!(
        "diagnose: cause {}; whole record wNRMSE {:.2} % -> {:.2} % (gain {:.1} %)",
        d.cause,
        100.0 * d.whole.baseline_wnrmse,
        100.0 * d.whole.extended_wnrmse,
        100.0 * d.whole.gain
    );
    if let Some(h) = d.held_out {
        println!(
            "held out: {:.2} % -> {:.2} % (gain {:.1} %)",
            100.0 * h.baseline_wnrmse,
            100.0 * h.extended_wnrmse,
            100.0 * h.gain
        );
    }
    println!("noise floor {:.3e}", d.noise_floor);
    for s in &d.ranking {
        let values = s.fit.as_ref().map_or_else(
            |e| e.clone(),
            |f| {
                f.values
                    .iter()
                    .map(|(p, v)| format!("{p} = {v:.4e}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            },
        );
        println!(
            "  {:<16} wNRMSE {:.2} %  BIC {:.1}  {values}",
            s.cause.name(),
            100.0 * s.wnrmse_fit,
            s.bic
        );
    }
    for n in &d.not_applicable {
        println!("  {:<16} n/a: {}", n.cause.name(), n.reason);
    }
    // Hysteresis (Jiles–Atherton) ranks first by BIC, saturation second, both
    // well ahead of the rest: the misfit is the steel's nonlinearity at the
    // stopper. But the FEA's steel is single-valued and the record's flux
    // never reverses (a 12 V step): no λ–i loop, so hysteresis is not
    // identifiable from it (issue 12 §2), and the core saturation is named.
    assert_eq!(d.cause, Cause::Saturation, "cause {}", d.cause);
    let (cause, why) = d
        .not_identifiable
        .first()
        .expect("hysteresis is reported as not identifiable");
    assert_eq!(*cause, Cause::Hysteresis);
    assert!(why.contains("never reverses"), "{why}");
    assert!(
        d.whole.extended_wnrmse <= d.whole.baseline_wnrmse * (1.0 + 1e-9),
        "the extended model is worse than the baseline on the record: {:?}",
        d.whole
    );
}
