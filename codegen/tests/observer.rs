//! The emitted EKF and UKF (jiles-atherton-actuator-model §6.1): the model
//! functions and the runtime's filters (`reldesign_runtime::observe`) on them
//! compile as a `#![no_std]`, `#![forbid(unsafe_code)]` crate under clippy's
//! panic lints (f64 and f32, 3 and 4 states, voltage and current drive, with
//! and without a resistance drift, with and without R as a state); their f64
//! estimates agree with the designer's reference filters (the same runtime
//! filters on tapes of the model) on the same noisy record, NaN samples
//! included, the f32 ones run without NaN close to them; every parameter and
//! setting is written on one line of the file; and the emission is
//! byte-identical across two runs.
//!
//! The check crate is the scratch crate `target/codegen-check-observer/`
//! (`support::ScratchCrate`, built in the scratch crates' shared target dir).

use std::fmt::Write as _;

use designer::description::{parse_file, parse_str, Core, Description};
use designer::model::Model;
use designer::observe::discrete::{
    DiscreteModel, Estimate, FluxStep, KalmanSettings, ResistanceSettings,
};
use designer::observe::ekf::Ekf;
use designer::observe::ukf::Ukf;
use designer::replay::replay;
use designer::sim::{Options, PiecewiseLinear};
use reldesign_build::{
    emit_ekf, emit_kalman_macro, emit_observer_params, emit_ukf, wrap_module, Float, ObserverInput,
};
use support::{example_path, example_physics, replaced_once, ScratchCrate};

const TS: f64 = 50e-6;

fn example(file: &str) -> Description {
    parse_file(&example_path(file)).unwrap_or_else(|e| panic!("{e}"))
}

/// The perfect-tracking valve's physics with a text replacement: current
/// drive, or a resistance drift (the model then depends on t).
fn variant(from: &str, to: &str) -> Description {
    let changed = replaced_once(&example_physics("perfect-tracking-valve.toml"), from, to);
    parse_str(&changed, "variant.toml").unwrap_or_else(|e| panic!("{e}"))
}

/// The settings of `designer/tests/observe_kalman.rs` at T_s = 50 µs.
fn settings(d: &Description) -> KalmanSettings {
    let ja = matches!(d.core, Core::JilesAtherton(_));
    KalmanSettings {
        sample_period: TS,
        voltage_noise: 15e-3,
        current_noise: 1e-3,
        process_z: 5e-9,
        process_phi: 1.5e-8,
        process_hc: ja.then_some(20.0),
        initial_z_std: 1e-5,
        initial_phi_std: 1e-7,
        initial_hc_std: ja.then_some(50.0),
        ukf_alpha: 1.0,
        ukf_beta: 2.0,
        ukf_kappa: 0.0,
        flux_step: FluxStep::Euler,
    }
}

/// R as a state (the sensorless design's settings).
const RESISTANCE: ResistanceSettings = ResistanceSettings {
    rate_std: 10.0,
    initial_std: 5.0,
};

fn discrete(d: &Description, resistance: bool, flux_step: FluxStep) -> DiscreteModel {
    let r = resistance.then_some(RESISTANCE);
    let settings = KalmanSettings {
        flux_step,
        ..settings(d)
    };
    DiscreteModel::with_resistance(&Model::build(d), &settings, r).unwrap()
}

/// The exponential flux step of the cases that use it.
const EXPONENTIAL: FluxStep = FluxStep::Exponential { substeps: 2 };

/// The emitted observer part of a file: `params!`, `kalman!`, then
/// `pub mod ekf` and `pub mod ukf` as the build wraps them.
fn emit(d: &Description, resistance: bool, flux_step: FluxStep, floats: &[Float]) -> String {
    let dm = discrete(d, resistance, flux_step);
    let input = ObserverInput {
        name: &d.name,
        discrete: &dm,
        floats: floats.to_vec(),
        calibration: None,
    };
    let ok =
        |r: Result<String, reldesign_build::ObserverError>| r.unwrap_or_else(|e| panic!("{e}"));
    ok(emit_observer_params(&input))
        + "\n"
        + &ok(emit_kalman_macro(&input))
        + "\n"
        + &wrap_module("ekf", "The EKF.", &ok(emit_ekf(&input)))
        + "\n"
        + &wrap_module("ukf", "The UKF.", &ok(emit_ukf(&input)))
}

/// SplitMix64 with Box–Muller normals (as in `designer/tests/observe_kalman.rs`).
struct Rng {
    state: u64,
    spare: Option<f64>,
}

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64
    }

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

/// (u, i) measured at k·T_s for 24 V on [0, 6 ms), 0 V, −24 V on
/// [10, 10.4 ms), 0 V until `t_end`, with σ_v = 15 mV and σ_i = 1 mA. With
/// `holes`, a few samples are NaN (u, i or both).
fn record(d: &Description, t_end: f64, holes: bool) -> Vec<(f64, f64)> {
    let mut model = Model::build(d);
    // switching just after the sample: u_k of the record is the voltage held
    // over the sample ending at t_k (the filters' convention) and the current
    // at t_k is the one before the switch
    let k = |t: f64| (t / TS).round() * TS * (1.0 + 1e-9);
    let input = PiecewiseLinear::steps(&[
        (0.0, 24.0),
        (k(6e-3), 0.0),
        (k(10e-3), -24.0),
        (k(10.4e-3), 0.0),
    ])
    .unwrap();
    let n = (t_end / TS).round() as usize;
    let times: Vec<f64> = (0..=n).map(|k| k as f64 * TS).collect();
    let opts = Options {
        rtol: 1e-10,
        ..Options::default()
    };
    let r = replay(&mut model, &input, &times, &opts).unwrap();
    let mut rng = Rng {
        state: 0x0B5E_4E42,
        spare: None,
    };
    let mut rec: Vec<(f64, f64)> = (0..times.len())
        .map(|k| {
            (
                r.trajectory.u[k] + 15e-3 * rng.normal(),
                r.current[k] + 1e-3 * rng.normal(),
            )
        })
        .collect();
    if holes {
        for (k, (u, i)) in rec.iter_mut().enumerate() {
            match k {
                20 | 70 => *i = f64::NAN,
                45 | 120 => *u = f64::NAN,
                150 => (*u, *i) = (f64::NAN, f64::INFINITY),
                _ => {}
            }
        }
    }
    rec
}

/// Runs the designer's filter over the record: the estimates, then the
/// check binary's `end skipped repairs` line.
fn reference(
    d: &Description,
    (resistance, flux_step): (bool, FluxStep),
    ukf: bool,
    rec: &[(f64, f64)],
) -> (Vec<Estimate>, String) {
    let dm = discrete(d, resistance, flux_step);
    macro_rules! run {
        ($f:expr) => {{
            let mut f = $f;
            let e = rec.iter().map(|&(u, i)| f.step(u, i)).collect();
            (e, format!("end {} {}", f.skipped(), f.repairs()))
        }};
    }
    if ukf {
        run!(Ukf::new(&dm))
    } else {
        run!(Ekf::new(&dm))
    }
}

/// The cases run by the check binary: (module, example file, (R a state,
/// flux step), record file).
const CASES: [(&str, &str, (bool, FluxStep), &str); 6] = [
    (
        "valve",
        "perfect-tracking-valve.toml",
        (false, FluxStep::Euler),
        "valve.csv",
    ),
    (
        "valve",
        "perfect-tracking-valve.toml",
        (false, FluxStep::Euler),
        "valve-holes.csv",
    ),
    (
        "ja",
        "jiles-atherton-valve.toml",
        (false, FluxStep::Euler),
        "ja.csv",
    ),
    (
        "resist",
        "perfect-tracking-valve.toml",
        (true, FluxStep::Euler),
        "valve.csv",
    ),
    (
        "valveexp",
        "perfect-tracking-valve.toml",
        (true, EXPONENTIAL),
        "valve.csv",
    ),
    (
        "jaexp",
        "jiles-atherton-valve.toml",
        (true, EXPONENTIAL),
        "ja.csv",
    ),
];

/// The check crate: lib with the emitted modules, a binary that runs every
/// filter over the record files and prints one line per estimate.
fn write_crate() -> ScratchCrate {
    let krate = ScratchCrate::new("codegen-check-observer");
    let mut lib = String::from(
        "//! Emitted by codegen/tests/observer.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n\n",
    );
    // the variants are compiled and linted only
    let euler = FluxStep::Euler;
    for (module, d, resistance, flux_step) in [
        (
            "valve",
            example("perfect-tracking-valve.toml"),
            false,
            euler,
        ),
        ("ja", example("jiles-atherton-valve.toml"), false, euler),
        (
            "current",
            variant("drive = \"voltage\"", "drive = \"current\""),
            false,
            euler,
        ),
        (
            "drift",
            variant("eddy = 1500.0", "eddy = 1500.0\nresistance_drift = 50.0"),
            false,
            euler,
        ),
        (
            "resist",
            example("perfect-tracking-valve.toml"),
            true,
            euler,
        ),
        (
            "valveexp",
            example("perfect-tracking-valve.toml"),
            true,
            EXPONENTIAL,
        ),
        (
            "jaexp",
            example("jiles-atherton-valve.toml"),
            true,
            EXPONENTIAL,
        ),
    ] {
        let code = emit(&d, resistance, flux_step, &[Float::F64, Float::F32]);
        krate.write(&format!("src/{module}.rs"), &code);
        writeln!(lib, "pub mod {module};").unwrap();
    }
    krate.write("src/lib.rs", &lib);

    let mut main = String::from(
        "//! Runs the emitted filters over record files (`u,i` per line).\n\
         use codegen_check_observer::*;\n\n\
         fn read(path: &str) -> Vec<(f64, f64)> {\n\
         \x20   std::fs::read_to_string(path)\n\
         \x20       .unwrap()\n\
         \x20       .lines()\n\
         \x20       .map(|l| {\n\
         \x20           let (u, i) = l.split_once(',').unwrap();\n\
         \x20           (u.parse().unwrap(), i.parse().unwrap())\n\
         \x20       })\n\
         \x20       .collect()\n\
         }\n\n\
         macro_rules! run {\n\
         \x20   ($filter:ty, $f:ty, $rec:expr) => {{\n\
         \x20       let mut f = <$filter>::new();\n\
         \x20       for &(u, i) in $rec {\n\
         \x20           let e = f.step(u as $f, i as $f);\n\
         \x20           let extra = e.hc.or(e.r).map_or(0.0, f64::from);\n\
         \x20           println!(\"{:?} {:?} {:?} {:?} {:?} {}\", e.z as f64, e.v as f64, e.a as f64, e.phi as f64, extra, e.mode);\n\
         \x20       }\n\
         \x20       println!(\"end {} {}\", f.skipped(), f.repairs());\n\
         \x20   }};\n\
         }\n\n\
         fn main() {\n\
         \x20   let dir = std::env::args().nth(1).unwrap();\n",
    );
    for (module, _, _, file) in CASES {
        writeln!(main, "    let rec = read(&format!(\"{{dir}}/{file}\"));").unwrap();
        for kind in ["ekf", "ukf"] {
            for float in ["f64", "f32"] {
                writeln!(
                    main,
                    "    run!({module}::{kind}::{float}::Filter, {float}, &rec);"
                )
                .unwrap();
            }
        }
    }
    main.push_str("}\n");
    krate.write("src/main.rs", &main);
    krate
}

#[test]
fn emission_is_byte_identical_across_runs() {
    let floats = [Float::F64, Float::F32];
    for (file, resistance, flux_step) in [
        ("perfect-tracking-valve.toml", false, FluxStep::Euler),
        ("perfect-tracking-valve.toml", true, FluxStep::Euler),
        ("jiles-atherton-valve.toml", false, FluxStep::Euler),
        ("jiles-atherton-valve.toml", true, EXPONENTIAL),
    ] {
        let d = example(file);
        let emit = || emit(&d, resistance, flux_step, &floats);
        let (a, b) = (emit(), emit());
        assert!(a == b, "{file}: two emissions differ");
    }
}

/// The part of `code` from `pub mod {name} {` to the next top-level `}`.
fn module<'a>(code: &'a str, name: &str) -> &'a str {
    let start = code.find(&format!("\npub mod {name} {{")).unwrap();
    let end = start + code[start..].find("\n}\n").unwrap();
    &code[start..end]
}

#[test]
fn emitted_modules_hold_the_model_and_not_the_algorithm() {
    let code = emit(
        &example("perfect-tracking-valve.toml"),
        false,
        FluxStep::Euler,
        &[Float::F64],
    );
    for needle in [
        "macro_rules! params {",
        "pub const N: $f = 1200.0;",
        "pub const Z_MAX: $f = 0.001;",
        "macro_rules! kalman {",
        "pub const T_S: $f = 5e-5;",
        "pub const SETTINGS: reldesign_runtime::observe::Settings<$f, 3>",
    ] {
        assert!(code.contains(needle), "missing {needle}");
    }
    let (ekf, ukf) = (module(&code, "ekf"), module(&code, "ukf"));
    for (code, name, own) in [
        (
            ekf,
            "ekf",
            [
                "impl observe::Linearised<f64, 3> for Model {",
                "pub type Filter = observe::Ekf<Model, f64, 3>;",
            ],
        ),
        (
            ukf,
            "ukf",
            [
                "impl observe::Sampled<f64, 3> for Model {",
                "pub type Filter = observe::Ukf<Model, f64, 3, 7>;",
            ],
        ),
    ] {
        for needle in [
            "pub mod f64 {",
            "params!(f64);",
            "kalman!(f64);",
            "model!(f64);",
            "pub fn transition(",
            "pub fn measurement(",
            "pub fn acceleration(",
            "// [JA 84a] z_{k+1} = sat",
            "// [JA 84c] φ_{k+1}",
            "// [JA 87] a = f_v",
            "pub struct Model;",
            "impl observe::Stateless<f64, 3> for Model {",
            "pub type Estimate = observe::Estimate<f64>;",
        ]
        .iter()
        .chain(&own)
        {
            assert!(code.contains(needle), "{name}: missing {needle}");
        }
        assert!(
            !code.contains("pub mod f32"),
            "{name}: only the requested floats"
        );
        // one macro, the model functions written once over the float type
        // (the parameters and settings are the file's `params!`, `kalman!`)
        assert_eq!(code.matches("macro_rules!").count(), 1, "{name}");
        assert!(code.contains("macro_rules! model {"), "{name}");
        // no panics, and no filter algebra: that is the runtime's
        for forbidden in [
            ".unwrap()",
            ".expect(",
            "panic!",
            " as f",
            " as usize",
            "unsafe",
            "linalg",
            "cholesky",
            "fn step",
            "pub const",
        ] {
            assert!(!code.contains(forbidden), "{name} contains {forbidden}");
        }
    }
}

/// One parameter, one line: every model parameter, stop and filter setting
/// is defined on exactly one line of the file (in `params!` or `kalman!`),
/// whatever the floats and filters.
#[test]
fn every_parameter_and_setting_is_written_once() {
    for (file, resistance, flux_step) in [
        ("perfect-tracking-valve.toml", true, FluxStep::Euler),
        ("jiles-atherton-valve.toml", false, FluxStep::Euler),
        ("jiles-atherton-valve.toml", true, EXPONENTIAL),
    ] {
        let d = example(file);
        let code = emit(&d, resistance, flux_step, &[Float::F64, Float::F32]);
        let dm = discrete(&d, resistance, flux_step);
        let mut names: Vec<String> = dm
            .model_params
            .iter()
            .map(|(name, _, _)| reldesign_build::const_name(name).unwrap())
            .collect();
        names.extend(["Z_MIN", "Z_MAX", "T_S", "VOLTAGE_NOISE", "CURRENT_NOISE"].map(String::from));
        names.extend(
            [
                "PROCESS_Z",
                "PROCESS_PHI",
                "INITIAL_Z_STD",
                "INITIAL_PHI_STD",
            ]
            .map(String::from),
        );
        names.extend(["UKF_ALPHA", "UKF_BETA", "UKF_KAPPA"].map(String::from));
        if resistance {
            names.extend(["RESISTANCE_RATE_STD", "INITIAL_RESISTANCE_STD"].map(String::from));
        } else {
            names.extend(["PROCESS_HC", "INITIAL_HC_STD"].map(String::from));
        }
        for name in names {
            let lines = code
                .lines()
                .filter(|l| l.trim_start().starts_with(&format!("pub const {name}:")))
                .count();
            assert_eq!(lines, 1, "{file}: `{name}` is defined on {lines} lines");
        }
    }
}

/// One parsed output line: z, v, a, φ, H_c, mode.
type Row = ([f64; 5], u8);

fn parse(line: &str) -> Row {
    let w: Vec<&str> = line.split(' ').collect();
    assert_eq!(w.len(), 6, "{line}");
    let v: Vec<f64> = w[..5].iter().map(|x| x.parse().unwrap()).collect();
    ([v[0], v[1], v[2], v[3], v[4]], w[5].parse().unwrap())
}

/// z, v, a, φ, then H_c or R (0 without).
fn values(e: &Estimate) -> [f64; 5] {
    [e.z, e.v, e.a, e.phi, e.hc.or(e.r).unwrap_or(0.0)]
}

#[test]
fn emitted_filters_compile_pass_clippy_and_match_the_designer() {
    let krate = write_crate();
    let data = krate.dir().join("data");
    std::fs::create_dir_all(&data).unwrap();
    let mut records = Vec::new();
    for (_, file, resistance, name) in CASES {
        let d = example(file);
        let rec = record(&d, 15e-3, name.contains("holes"));
        let text: String = rec.iter().map(|(u, i)| format!("{u:?},{i:?}\n")).collect();
        krate.write(&format!("data/{name}"), &text);
        records.push((d, resistance, rec, name));
    }

    let text = krate.run_panic_free(&[data.to_str().unwrap()]);
    let mut lines = text.lines();

    println!("| record | filter | max rel. difference f64 (z, v, a, φ, H_c or R) | max rel. difference f32 | skipped | repairs f64/f32 |");
    for (d, resistance, rec, name) in &records {
        for ukf in [false, true] {
            let (want, want_end) = reference(d, *resistance, ukf, rec);
            // each quantity relative to its largest magnitude over the run
            let mut scale = [0.0f64; 5];
            for e in &want {
                for (s, v) in scale.iter_mut().zip(values(e)) {
                    *s = s.max(v.abs());
                }
            }
            let mut worst = [[0.0f64; 5]; 2];
            let mut ends = Vec::new();
            for (fi, float) in ["f64", "f32"].into_iter().enumerate() {
                for (k, e) in want.iter().enumerate() {
                    let (got, mode) = parse(lines.next().unwrap());
                    for (q, (g, w)) in got.iter().zip(values(e)).enumerate() {
                        assert!(g.is_finite(), "{name} {float}: NaN at sample {k}: {got:?}");
                        let rel = (g - w).abs() / scale[q].max(f64::MIN_POSITIVE);
                        worst[fi][q] = worst[fi][q].max(rel);
                    }
                    if fi == 0 {
                        assert_eq!(
                            mode,
                            e.mode.number(),
                            "{name} f64 {}: mode at sample {k}",
                            if ukf { "UKF" } else { "EKF" }
                        );
                    }
                }
                let end = lines.next().unwrap();
                assert!(end.starts_with("end "), "{end}");
                if fi == 0 {
                    assert_eq!(end, want_end, "{name} f64: skipped and repaired samples");
                }
                ends.push(end.to_owned());
            }
            let kind = if ukf { "UKF" } else { "EKF" };
            let fmt = |w: &[f64; 5]| {
                w.iter()
                    .map(|x| format!("{x:.1e}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            println!(
                "| {name} | {kind} | {} | {} | {} | {} |",
                fmt(&worst[0]),
                fmt(&worst[1]),
                ends[0].split(' ').nth(1).unwrap(),
                ends.iter()
                    .map(|e| e.split(' ').nth(2).unwrap())
                    .collect::<Vec<_>>()
                    .join("/")
            );
            // f64: the same runtime filter, monomorphised on the emitted
            // model (straight-line code with libm) and on the tapes (std's
            // math): the differences are the model's rounding, which the
            // filter does not amplify.
            // Measured ≤ 1.8e-13 relative (v, UKF), bound 1e-11.
            for (q, &w) in worst[0].iter().enumerate() {
                assert!(
                    w <= 1e-11,
                    "{name} {kind} f64: quantity {q} differs by {w:e} relative"
                );
            }
            // f32: rounding at ~6e-8 of the states and of the covariance, which
            // the filter carries over the run: measured ≤ 1.8e-4 relative to each
            // quantity's range (v and a, at landing and lift-off), bound 1e-3.
            for (q, &w) in worst[1].iter().enumerate() {
                assert!(
                    w <= 1e-3,
                    "{name} {kind} f32: quantity {q} differs by {w:e} relative"
                );
            }
        }
    }
    assert!(lines.next().is_none());
}

/// Through the build (`reldesign_build::Design`): a file declares `params!` (with
/// the stops) and `kalman!` once, with a controller (whose emitter writes
/// `params!`) and without one (the observers' own).
#[test]
fn the_build_declares_params_and_kalman_once() {
    let text = std::fs::read_to_string(example_path("perfect-tracking-valve.toml")).unwrap();
    let physics = &text[..text.find("\n[trajectory]").unwrap()];
    let observers = &text[text.find("\n[observer]").unwrap()..];
    for (name, toml) in [
        ("with a controller", text.clone()),
        ("observers only", format!("{physics}\n{observers}")),
    ] {
        let d = parse_str(&toml, "valve.toml").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(d.controller.is_some(), name == "with a controller");
        let design = designer::design::Design::new(&d).unwrap();
        let code = reldesign_build::emit(&design).unwrap();
        for (needle, count) in [
            ("macro_rules! params {", 1),
            ("macro_rules! kalman {", 1),
            ("pub const Z_MIN: $f = 0.0;", 1),
            ("pub const Z_MAX: $f = 0.001;", 1),
            (
                "params!(f32);",
                if name == "observers only" { 2 } else { 3 },
            ),
            ("kalman!(f64);", 2),
            // the model functions once per filter, not once per float
            ("macro_rules! model {", 2),
            ("model!(f32);", 2),
            ("pub fn transition(", 2),
            ("pub mod ekf {", 1),
            ("pub mod ukf {", 1),
        ] {
            assert_eq!(code.matches(needle).count(), count, "{name}: {needle}");
        }
    }
}
