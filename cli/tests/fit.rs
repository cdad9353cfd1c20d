//! `reldesign fit` end to end: a recording made by `reldesign simulate` from a
//! bundled example is fitted from a perturbed copy of that example, and the
//! true values must come back; the gap mode fits a table generated from known
//! parameters; bad parameters fail with a message naming them.

use std::path::{Path, PathBuf};

use designer::description::{parse_file, Gap};
use serde_json::Value;
use support::{example_path, rd, TempDir};

/// A recording of the SEMERA valve (0/30 V square wave, 30 ms, 20 µs) and a
/// copy of the description with R = 90 Ω and φ_sat = 1.6e-5 Wb.
fn setup(dir: &Path) -> (PathBuf, PathBuf) {
    let example = example_path("semera-valve.toml");
    let data = dir.join("rec.csv");
    rd!(
        "simulate",
        example,
        "--square",
        "30:0:0.02:0.5",
        "--t-end",
        "0.03",
        "--dt",
        "2e-5",
        "--out",
        data
    )
    .ok();
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
    let dir = TempDir::new("fit-fit");
    let (model, data) = setup(dir.path());
    let fitted = dir.join("fitted.toml");
    let out = rd!(
        "fit",
        model,
        data,
        "--param",
        "coil.resistance=30:200",
        "--param",
        "core.phi_sat",
        "--out",
        fitted,
        "--json"
    )
    .ok();
    let v: Value = serde_json::from_str(&out).unwrap();
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
    let dir = TempDir::new("fit-text");
    let (model, data) = setup(dir.path());
    let s = rd!("fit", model, data, "--param", "coil.resistance").ok();
    assert!(
        s.contains("coil.resistance")
            && s.contains("wNRMSE current")
            && s.contains("identifiability"),
        "{s}"
    );
}

#[test]
fn unknown_parameters_and_bad_bounds_are_named() {
    let dir = TempDir::new("fit-bad");
    let (model, data) = setup(dir.path());
    let fitted = dir.join("never.toml");
    for (param, needle) in [
        ("core.b", "`core.b`"),
        ("coil.resistance=5:1", "LO < HI"),
        ("mechanics.mass=-1:1", "mechanics.mass"),
    ] {
        rd!("fit", model, data, "--param", param, "--out", fitted).rejected(&[needle]);
        assert!(!fitted.exists());
    }
}

#[test]
fn gap_mode_fits_a_reluctance_table() {
    let dir = TempDir::new("fit-gap");
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
    let model = example_path("jiles-atherton-valve.toml");
    let fitted = dir.join("gap.toml");
    let out = rd!(
        "fit",
        model,
        table,
        "--gap",
        "mclyman-fit",
        "--out",
        fitted,
        "--json"
    )
    .ok();
    let v: Value = serde_json::from_str(&out).unwrap();
    assert!(v["nrmse_r"].as_f64().unwrap() < 1e-5, "{v}");
    assert!(v["nrmse_r_prime"].as_f64().unwrap() < 1e-5, "{v}");
    match parse_file(&fitted).unwrap().gap {
        Gap::McLymanFit { r0_prime, .. } => assert!((r0_prime / r0p - 1.0).abs() < 1e-3),
        g => panic!("{g:?}"),
    }
}
