//! `reldesign fit` end to end: a recording made by `reldesign simulate` from a
//! bundled example is fitted from a perturbed copy of that example, and the
//! true values must come back; the gap mode fits a table generated from known
//! parameters; bad parameters fail with a message naming them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use designer::description::{parse_file, Gap};
use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_reldesign");

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("cli/ has a parent")
        .to_path_buf()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reldesign-fit-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

/// A recording of the SEMERA valve (0/30 V square wave, 30 ms, 20 µs) and a
/// copy of the description with R = 90 Ω and φ_sat = 1.6e-5 Wb.
fn setup(dir: &Path) -> (PathBuf, PathBuf) {
    let example = root().join("examples/semera-valve.toml");
    let data = dir.join("rec.csv");
    let out = run(&[
        "simulate",
        example.to_str().unwrap(),
        "--square",
        "30:0:0.02:0.5",
        "--t-end",
        "0.03",
        "--dt",
        "2e-5",
        "--out",
        data.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&example).unwrap();
    let text = text
        .replacen("resistance = 75.0", "resistance = 90.0", 1)
        .replacen("phi_sat = 2e-5", "phi_sat = 1.6e-5", 1);
    let model = dir.join("start.toml");
    std::fs::write(&model, text).unwrap();
    (model, data)
}

#[test]
fn fit_recovers_resistance_and_saturation_flux_and_writes_the_model() {
    let dir = scratch("fit");
    let (model, data) = setup(&dir);
    let fitted = dir.join("fitted.toml");
    let out = run(&[
        "fit",
        model.to_str().unwrap(),
        data.to_str().unwrap(),
        "--param",
        "coil.resistance=30:200",
        "--param",
        "core.phi_sat",
        "--out",
        fitted.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = v["values"]["coil.resistance"].as_f64().unwrap();
    let phi_sat = v["values"]["core.phi_sat"].as_f64().unwrap();
    // The recording is noise-free but its edges were exact jumps, replayed
    // here as one-sample ramps: 0.5 % on R, 1 % on φ_sat.
    assert!((r / 75.0 - 1.0).abs() < 5e-3, "{v}");
    assert!((phi_sat / 2e-5 - 1.0).abs() < 1e-2, "{v}");
    // R and φ_sat enter the model's field: the Jacobian is analytic.
    assert_eq!(v["jacobian"], "analytic forward sensitivities", "{v}");
    let before = v["wnrmse_current_before"].as_f64().unwrap();
    let after = v["wnrmse_current"].as_f64().unwrap();
    // The error left is the edges' jump-versus-ramp mismatch, where |φ̇| (the
    // weight) is largest.
    assert!(after < 0.25 * before, "{v}");
    let d = parse_file(&fitted).unwrap();
    assert_eq!(d.coil.resistance, r);
    // The design sections and comments of the original survive.
    let text = std::fs::read_to_string(&fitted).unwrap();
    assert!(text.contains("[observer.semera]") && text.contains("# Solenoid valve"));
}

#[test]
fn text_output_names_values_errors_and_identifiability() {
    let dir = scratch("text");
    let (model, data) = setup(&dir);
    let out = run(&[
        "fit",
        model.to_str().unwrap(),
        data.to_str().unwrap(),
        "--param",
        "coil.resistance",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(
        s.contains("coil.resistance")
            && s.contains("wNRMSE current")
            && s.contains("identifiability"),
        "{s}"
    );
}

#[test]
fn unknown_parameters_and_bad_bounds_are_named() {
    let dir = scratch("bad");
    let (model, data) = setup(&dir);
    let fitted = dir.join("never.toml");
    for (param, needle) in [
        ("core.b", "`core.b`"),
        ("coil.resistance=5:1", "LO < HI"),
        ("mechanics.mass=-1:1", "mechanics.mass"),
    ] {
        let out = run(&[
            "fit",
            model.to_str().unwrap(),
            data.to_str().unwrap(),
            "--param",
            param,
            "--out",
            fitted.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(needle),
            "{param}: {err}"
        );
        assert!(!err.contains("panicked") && out.stdout.is_empty());
        assert!(!fitted.exists());
    }
}

#[test]
fn gap_mode_fits_a_reluctance_table() {
    let dir = scratch("gap");
    // R = r0 + r0'·z/(1 + k1·z·ln(k2/z)) and its derivative (13), exact.
    let (r0, r0p, k1, k2) = (2.41e6, 7.94e10, 1350.0, 9.95e-3);
    let mut csv = String::from("# generated gap table\nz,r,r_prime\n");
    for k in 0..25 {
        let z = 2e-5 + k as f64 * 3.6e-5;
        let d = 1.0 + k1 * z * (k2 / z).ln();
        let r = r0 + r0p * z / d;
        let rp = r0p * (1.0 + k1 * z) / (d * d);
        csv += &format!("{z:e},{r:e},{rp:e}\n");
    }
    let table = dir.join("gap.csv");
    std::fs::write(&table, csv).unwrap();
    let model = root().join("examples/jiles-atherton-valve.toml");
    let fitted = dir.join("gap.toml");
    let out = run(&[
        "fit",
        model.to_str().unwrap(),
        table.to_str().unwrap(),
        "--gap",
        "mclyman-fit",
        "--out",
        fitted.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["nrmse_r"].as_f64().unwrap() < 1e-5, "{v}");
    assert!(v["nrmse_r_prime"].as_f64().unwrap() < 1e-5, "{v}");
    match parse_file(&fitted).unwrap().gap {
        Gap::McLymanFit { r0_prime, .. } => assert!((r0_prime / r0p - 1.0).abs() < 1e-3),
        g => panic!("{g:?}"),
    }
}
