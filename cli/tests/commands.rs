//! End-to-end tests of the `reldesign` command line (`/work/shared/spec/cli.md`):
//! `check`, `eval` and `simulate` on the examples, the measured-data CSV and the
//! broken descriptions of `tests/data/bad/`, run through the real binary.
//!
//! Every failure case asserts: non-zero exit, a message on stderr that names the
//! file and the offending entry, no panic text, nothing on stdout, and that no
//! output file was created or touched.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use designer::description::{parse_file, Core, Description, Drive};
use serde_json::Value;
use support::{assert_close, example_path, example_paths, rd, root, toml_files, Cli, TempDir, Tol};

const CLI: Cli = Cli::new(env!("CARGO_BIN_EXE_reldesign"));

fn three_pulses() -> PathBuf {
    root().join("tests/data/ja-three-pulses.csv")
}

fn description(path: &Path) -> Description {
    parse_file(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn base_name(path: &Path) -> String {
    path.file_name().unwrap().to_string_lossy().into_owned()
}

/// A parsed `simulate` output.
struct Csv {
    header: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Csv {
    fn parse(text: &str) -> Csv {
        let mut lines = text.lines();
        let header = lines
            .next()
            .expect("a header line")
            .split(',')
            .map(str::to_string)
            .collect::<Vec<_>>();
        let rows = lines
            .enumerate()
            .map(|(k, line)| {
                let row: Vec<f64> = line
                    .split(',')
                    .map(|c| {
                        c.parse::<f64>()
                            .unwrap_or_else(|_| panic!("line {}: bad cell {c:?}", k + 2))
                    })
                    .collect();
                assert_eq!(row.len(), header.len(), "line {}: {line}", k + 2);
                assert!(row.iter().all(|x| x.is_finite()), "line {}: {line}", k + 2);
                row
            })
            .collect();
        Csv { header, rows }
    }

    fn col(&self, name: &str) -> Vec<f64> {
        let j = self
            .header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", self.header));
        self.rows.iter().map(|r| r[j]).collect()
    }
}

/// The `t` and `v` columns of a measured-data CSV (comments skipped).
fn read_input(path: &Path) -> (Vec<f64>, Vec<f64>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.trim_start().starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').map(str::trim).collect();
    let jt = header.iter().position(|h| *h == "t").unwrap();
    let jv = header.iter().position(|h| *h == "v").unwrap();
    let (mut t, mut v) = (vec![], vec![]);
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        t.push(cells[jt].parse().unwrap());
        v.push(cells[jv].parse().unwrap());
    }
    (t, v)
}

/// Run-length compression (the sequence of modes visited).
fn runs(modes: &[f64]) -> Vec<u8> {
    let mut out: Vec<u8> = vec![];
    for &m in modes {
        let m = m as u8;
        if out.last() != Some(&m) {
            out.push(m);
        }
    }
    out
}

fn has_field_state(d: &Description) -> bool {
    matches!(d.core, Core::JilesAtherton(_))
}

// ---------------------------------------------------------------------------
// check
// ---------------------------------------------------------------------------

/// A description the parser accepts but warns about passes `check` (exit 0,
/// the summary on stdout) with the warning on stderr, naming the file and
/// the key: here feedback linearization too slow for a stiffened spring.
#[test]
fn check_prints_warnings_on_stderr_and_succeeds() {
    let text = std::fs::read_to_string(example_path("perfect-tracking-valve.toml")).unwrap();
    // k_s ×160 (and the preload, so the spring still holds it open) at the
    // example's 1 ms settling time: a steady error of 30 µm, 3 % of the stroke
    let text = support::replaced_once(&text, "stiffness = 50.0", "stiffness = 8000.0");
    let text = support::replaced_once(&text, "preload = -0.75", "preload = -12.0");
    let dir = TempDir::new("check-warning");
    let path = dir.write("stiff-valve.toml", text);
    let run = rd!("check", &path);
    let out = run.ok();
    let ctx = run.context();
    assert!(out.contains("valid actuator description"), "{ctx}");
    let warning = run
        .stderr
        .lines()
        .find(|l| l.starts_with("warning: "))
        .unwrap_or_else(|| panic!("no warning\n{ctx}"));
    assert!(
        warning.contains("stiff-valve.toml:")
            && warning.contains("controller.settling_time")
            && warning.contains("mechanics.stiffness"),
        "{ctx}"
    );
}

#[test]
fn check_summarises_every_example_deterministically() {
    for path in example_paths() {
        let d = description(&path);
        let first = rd!("check", path);
        let out = first.ok();
        let ctx = first.context();
        assert!(first.stderr.is_empty(), "check wrote to stderr\n{ctx}");
        assert!(
            out.contains(&format!(
                "{}: valid actuator description `{}`",
                path.display(),
                d.name
            )),
            "the summary must name the file and the description\n{ctx}"
        );
        let states = if has_field_state(&d) {
            "x = [z, v, phi, H_c]"
        } else {
            "x = [z, v, phi]"
        };
        assert!(out.contains(states), "missing `{states}`\n{ctx}");

        // The pull-in and drop-out lines carry a number in the supply range,
        // drop-out below pull-in (magnetic hysteresis of the statics).
        let switching = |label: &str| -> f64 {
            let line = out
                .lines()
                .find(|l| l.trim_start().starts_with(label))
                .unwrap_or_else(|| panic!("no `{label}` line\n{ctx}"));
            let (what, unit) = match d.supply.drive {
                Drive::Voltage => ("voltage", "V"),
                Drive::Current => ("current", "A"),
            };
            let rest = line
                .split_once("): ")
                .and_then(|(_, r)| r.trim_start().strip_prefix(what))
                .unwrap_or_else(|| panic!("`{line}`: expected `{what} <number> {unit}`"));
            let value: f64 = rest.split_whitespace().next().unwrap().parse().unwrap();
            assert!(rest.split_whitespace().nth(1) == Some(unit), "{line}");
            value
        };
        // Without a spring (the MSL solenoid) any flux pulls the armature in
        // (pull-in 0) and nothing ever pushes it off z_min (no drop-out).
        let m = &d.mechanics;
        let return_force = m.stiffness * m.z_min + m.preload < 0.0;
        let pull_in = switching("pull-in");
        assert!(
            (0.0 < pull_in || (!return_force && pull_in == 0.0)) && pull_in <= d.supply.u_max,
            "pull-in {pull_in} outside (0, u_max]\n{ctx}"
        );
        if return_force {
            let drop_out = switching("drop-out");
            assert!(
                0.0 < drop_out && drop_out < pull_in,
                "drop-out {drop_out} not in (0, pull-in {pull_in})\n{ctx}"
            );
        } else {
            assert!(out.contains("never pushes the armature off"), "{ctx}");
        }

        let second = rd!("check", path);
        assert_eq!(
            first.stdout,
            second.stdout,
            "check output differs between two runs of {}",
            path.display()
        );
    }
}

#[test]
fn check_rejects_a_missing_file() {
    let dir = TempDir::new("check-missing");
    let missing = dir.join("no-such-valve.toml");
    rd!("check", missing).rejected(&["no-such-valve.toml"]);
    assert!(dir.files().is_empty());
}

// ---------------------------------------------------------------------------
// eval
// ---------------------------------------------------------------------------

/// The raw number tokens of a flat array `"key":[…]` in compact JSON.
fn raw_array<'a>(json: &'a str, key: &str) -> Vec<&'a str> {
    let start = json
        .find(&format!("\"{key}\":["))
        .unwrap_or_else(|| panic!("no flat array `{key}` in {json}"))
        + key.len()
        + 4;
    let end = start + json[start..].find(']').unwrap();
    json[start..end].split(',').collect()
}

/// Every number token of a JSON text (strings skipped).
fn number_tokens(json: &str) -> Vec<&str> {
    let b = json.as_bytes();
    let mut out = vec![];
    let mut k = 0;
    while k < b.len() {
        match b[k] {
            b'"' => {
                k += 1;
                while b[k] != b'"' {
                    k += if b[k] == b'\\' { 2 } else { 1 };
                }
                k += 1;
            }
            b'-' | b'0'..=b'9' => {
                let s = k;
                while k < b.len() && matches!(b[k], b'0'..=b'9' | b'.' | b'e' | b'E' | b'+' | b'-')
                {
                    k += 1;
                }
                out.push(&json[s..k]);
            }
            _ => k += 1,
        }
    }
    out
}

/// Significant digits of a decimal number text, without leading/trailing zeros.
fn significant_digits(s: &str) -> String {
    let mantissa = s.split(['e', 'E']).next().unwrap();
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    digits
        .trim_start_matches('0')
        .trim_end_matches('0')
        .to_string()
}

fn eval_json(model: &Path, states: &Path) -> (String, Value) {
    let run = rd!("eval", model, states);
    let out = run.ok();
    assert!(
        run.stderr.is_empty(),
        "eval wrote to stderr\n{}",
        run.context()
    );
    assert_eq!(out.lines().count(), 1, "one JSON object on one line\n{out}");
    let value: Value = serde_json::from_str(out.trim())
        .unwrap_or_else(|e| panic!("eval output is not JSON: {e}\n{out}"));
    assert!(value.is_object(), "eval output is not an object: {out}");
    // Deterministic: a second run prints the same bytes.
    let again = rd!("eval", model, states);
    assert_eq!(run.stdout, again.stdout, "eval output differs between runs");
    (out.trim().to_string(), value)
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap_or_else(|| panic!("not a number: {x}")))
        .collect()
}

/// Checks the keys of the contract and their shapes for `n` states of dimension `nx`.
fn assert_shapes(out: &Value, n: usize, nx: usize) {
    for key in ["i", "f_mag", "r_gap", "r_gap_dz"] {
        let v = numbers(&out[key]);
        assert_eq!(v.len(), n, "`{key}` must have one number per state: {out}");
    }
    let f = out["f"].as_array().expect("`f` is an array");
    assert_eq!(f.len(), n, "`f`: one vector per state");
    for fk in f {
        assert_eq!(numbers(fk).len(), nx, "`f`: vectors of length {nx}: {fk}");
    }
    let jac = out["df_dx"].as_array().expect("`df_dx` is an array");
    assert_eq!(jac.len(), n, "`df_dx`: one matrix per state");
    for j in jac {
        let rows = j.as_array().expect("`df_dx` entries are matrices");
        assert_eq!(rows.len(), nx, "`df_dx`: {nx} rows: {j}");
        for r in rows {
            assert_eq!(numbers(r).len(), nx, "`df_dx`: {nx} columns: {j}");
        }
    }
}

#[test]
fn eval_perfect_tracking_valve() {
    let dir = TempDir::new("eval-pt");
    let model = example_path("perfect-tracking-valve.toml");
    let states = dir.write(
        "STATES.json",
        r#"{"x": [[0, 0, 0], [5e-4, 0.1, 1e-5], [1e-3, -0.5, -2e-5]], "u": [0, 12, -24]}"#,
    );
    let (text, out) = eval_json(&model, &states);
    assert_shapes(&out, 3, 3);

    // z = 0: the McLyman limit R_gap(0) = 0, R_gap'(0) = 1/(μ0·A).
    let mu0 = 4e-7 * std::f64::consts::PI;
    let a = 20e-6;
    let r_gap = numbers(&out["r_gap"]);
    let r_gap_dz = numbers(&out["r_gap_dz"]);
    assert_eq!(r_gap[0], 0.0, "R_gap(0) of the McLyman gap");
    assert_close(
        r_gap_dz[0],
        1.0 / (mu0 * a),
        Tol::rel(1e-12),
        "R_gap'(0) = 1/(μ0·A)",
    );
    assert!(
        r_gap[1] > 0.0 && r_gap[2] > r_gap[1],
        "R_gap increases: {r_gap:?}"
    );

    // At rest with zero flux and input: ż = 0, v̇ = −F0/m = 0.75/2e-3, φ̇ = 0.
    let f0: Vec<f64> = numbers(&out["f"][0]);
    assert_eq!(f0, vec![0.0, 375.0, 0.0], "f at rest");
    assert_eq!(numbers(&out["f"][1])[0], 0.1, "ż = v");
    assert_eq!(numbers(&out["f"][2])[0], -0.5, "ż = v");
    assert_eq!(numbers(&out["df_dx"][0][0]), vec![0.0, 1.0, 0.0], "∂ż/∂x");
    assert_eq!(numbers(&out["i"])[0], 0.0);

    // The quantities agree with each other as actuator.md defines them.
    let (n_turns, r_coil, k_e, r_core0, phi_sat) = (1200.0, 75.0, 1500.0, 3e6, 25e-6);
    let xs = [(5e-4, 1e-5, 12.0), (1e-3, -2e-5, -24.0)];
    for (k, &(_z, phi, u)) in xs.iter().enumerate() {
        let k = k + 1;
        let f_mag = numbers(&out["f_mag"])[k];
        let want = -0.5 * r_gap_dz[k] * phi * phi;
        assert_close(f_mag, want, Tol::rel(1e-14), format!("F_mag[{k}] = −½R'φ²"));
        let mmf = r_gap[k] * phi + r_core0 / (1.0 - f64::abs(phi) / phi_sat) * phi;
        let i_want = (n_turns * mmf + k_e * u) / (n_turns * n_turns + r_coil * k_e);
        let i = numbers(&out["i"])[k];
        assert_close(i, i_want, Tol::rel(1e-12), format!("i[{k}], spec formula"));
        let dphi = numbers(&out["f"][k])[2];
        let dphi_want = (n_turns * u - r_coil * mmf) / (n_turns * n_turns + r_coil * k_e);
        assert_close(dphi, dphi_want, Tol::rel(1e-12), format!("φ̇[{k}], spec"));
    }

    // Shortest round-trip numbers: each token parses back and has exactly the
    // digits of Rust's shortest representation of that double.
    let tokens = number_tokens(&text);
    assert!(tokens.len() >= 3 * (3 + 9 + 4), "too few numbers in {text}");
    for tok in tokens {
        let x: f64 = tok.parse().unwrap_or_else(|_| panic!("bad number {tok}"));
        assert!(x.is_finite(), "{tok}");
        assert_eq!(
            significant_digits(tok),
            significant_digits(&format!("{x:?}")),
            "`{tok}` is not the shortest round-trip form of {x:?}"
        );
    }
    let raw = raw_array(&text, "r_gap_dz");
    assert_eq!(raw[0].parse::<f64>().unwrap(), r_gap_dz[0]);

    // The feedback linearization of y = z (values: tests/oracle/check_linearization.py):
    // T(x) = [z, v, a] with a the free-motion acceleration, α = −L_f³h/L_gL_f²h,
    // β = 1/L_gL_f²h.
    // At φ = 0 the input does not reach the jerk (L_gL_f²h = 0): α and β are
    // undefined there and printed as null.
    for key in ["alpha", "beta", "lf3h", "lglf2h", "t"] {
        let v = out[key]
            .as_array()
            .unwrap_or_else(|| panic!("no `{key}`: {text}"));
        assert_eq!(v.len(), 3, "`{key}`: one per state: {text}");
    }
    let states = [[0.0, 0.0, 0.0], [5e-4, 0.1, 1e-5], [1e-3, -0.5, -2e-5]];
    let (lf3h, lglf2h) = (numbers(&out["lf3h"]), numbers(&out["lglf2h"]));
    assert_eq!(lglf2h[0], 0.0, "L_gL_f²h = 0 at zero flux");
    assert!(
        out["alpha"][0].is_null() && out["beta"][0].is_null(),
        "{text}"
    );
    for (k, x) in states.iter().enumerate() {
        let t = numbers(&out["t"][k]);
        let a = numbers(&out["f"][k])[1];
        assert_eq!(t, vec![x[0], x[1], a], "T(x) = [z, v, a] at state {k}");
        if k > 0 {
            let alpha = out["alpha"][k].as_f64().expect("α is a number");
            let beta = out["beta"][k].as_f64().expect("β is a number");
            assert!(lglf2h[k] != 0.0, "L_gL_f²h ≠ 0 with flux at state {k}");
            let tol = Tol::rel(1e-13);
            assert_close(beta, 1.0 / lglf2h[k], tol, format!("β = 1/L_gL_f²h at {k}"));
            assert_close(alpha, -lf3h[k] / lglf2h[k], tol, format!("α at {k}"));
        }
    }
}

#[test]
fn eval_jiles_atherton_valve_has_four_states() {
    let dir = TempDir::new("eval-ja");
    let model = example_path("jiles-atherton-valve.toml");
    let states = dir.write(
        "STATES.json",
        r#"{"x": [[0, 0, 0, 0], [4.5e-4, 0.2, 5e-6, 300], [9e-4, -1, -1e-5, -1500]],
            "u": [0, 6, -12], "t": [0, 0.01, 0.02]}"#,
    );
    let (text, out) = eval_json(&model, &states);
    assert_shapes(&out, 3, 4);
    // The linearization on (z, v, φ), H_c exogenous: L_f³z reads H_c, the
    // transform does not (the CasADi oracle checks the values).
    for key in ["alpha", "beta", "lf3h", "lglf2h", "t"] {
        assert!(out.get(key).is_some(), "`{key}` missing: {text}");
    }
    let lf3h = |k: usize| out["lf3h"][k].as_f64();
    assert!(lf3h(1).is_some_and(f64::is_finite), "{text}");
    // at φ = 0 the relative degree is lost: α, β print as null
    assert!(out["alpha"][0].is_null(), "{text}");
    // mclyman-fit: R_gap(0) = r0 and R_gap'(0) = r0_prime, exactly as written.
    let raw = raw_array(&text, "r_gap");
    assert_eq!(
        raw[0].parse::<f64>().unwrap(),
        2.41e6,
        "R_gap(0) = r0: {text}"
    );
    let r_gap_dz = numbers(&out["r_gap_dz"]);
    assert_close(
        r_gap_dz[0],
        7.94e10,
        Tol::rel(1e-15),
        "R_gap'(0) = r0_prime",
    );
    let r_gap = numbers(&out["r_gap"]);
    assert!(
        r_gap.windows(2).all(|w| w[1] > w[0]),
        "R_gap increases: {r_gap:?}"
    );
    // Spring at rest, no flux: v̇ = −(k_s·0 − k_s·z_s)/m = 55·0.015/1.6e-3.
    let f0 = numbers(&out["f"][0]);
    assert_close(f0[1], 55.0 * 0.015 / 1.6e-3, Tol::rel(1e-14), "v̇ at rest");
    assert_eq!((f0[0], f0[2], f0[3]), (0.0, 0.0, 0.0), "f at rest: {f0:?}");
}

#[test]
fn eval_rejects_bad_states() {
    let dir = TempDir::new("eval-bad");
    let model = example_path("perfect-tracking-valve.toml");
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "wrong state length",
            r#"{"x": [[0, 0, 0], [0, 0]], "u": [0, 0]}"#,
            &["x[1]", "z, v, phi"],
        ),
        ("missing u", r#"{"x": [[0, 0, 0]]}"#, &["`u`"]),
        (
            "non-number",
            r#"{"x": [[0, "fast", 0]], "u": [0]}"#,
            &["x[0][1]", "fast"],
        ),
        (
            "null input",
            r#"{"x": [[0, 0, 0]], "u": [null]}"#,
            &["u[0]"],
        ),
        (
            "length mismatch of u",
            r#"{"x": [[0, 0, 0], [0, 0, 0]], "u": [0]}"#,
            &["`u`", "`x`"],
        ),
        (
            "length mismatch of t",
            r#"{"x": [[0, 0, 0]], "u": [0], "t": [0, 1]}"#,
            &["`t`"],
        ),
        (
            "unknown key",
            r#"{"x": [[0, 0, 0]], "u": [0], "speed": [1]}"#,
            &["`speed`"],
        ),
        ("not an object", r#"[[0, 0, 0]]"#, &["object"]),
        ("x not an array", r#"{"x": 3, "u": [0]}"#, &["`x`"]),
        ("overflow", r#"{"x": [[0, 0, 1e999]], "u": [0]}"#, &[":1:"]),
        (
            "truncated JSON",
            "{\"x\": [[0, 0, 0]],\n \"u\": [0",
            &["STATES.json:2:", "JSON"],
        ),
    ];
    for (what, json, needles) in cases {
        let states = dir.write("STATES.json", json);
        let run = rd!("eval", model, states);
        let mut all = vec![states.to_str().unwrap()];
        all.extend_from_slice(needles);
        run.rejected_in(&format!("case `{what}` (STATES.json = {json})"), &all);
        assert_eq!(dir.files(), ["STATES.json"], "case `{what}` left files");
    }
    let missing = dir.join("nothing-here.json");
    rd!("eval", model, missing).rejected(&["nothing-here.json"]);
}

// ---------------------------------------------------------------------------
// simulate
// ---------------------------------------------------------------------------

#[test]
fn simulate_replays_the_three_pulse_record_on_every_example() {
    let dir = TempDir::new("sim-record");
    let input = three_pulses();
    let (t_in, v_in) = read_input(&input);
    assert!(t_in.len() > 1000, "the record has {} samples", t_in.len());
    for path in example_paths() {
        let d = description(&path);
        let out = dir.join("OUT.csv");
        let _ = std::fs::remove_file(&out);
        let run = rd!("simulate", path, "--input", input, "--out", out,);
        if d.supply.drive == Drive::Current {
            // The record has no current column: the replay must say so.
            run.rejected(&["ja-three-pulses.csv", "`i`"]);
            continue;
        }
        run.ok();
        assert!(run.stdout.is_empty(), "--out given: stdout stays empty");
        assert_eq!(dir.files(), ["OUT.csv"], "only OUT.csv is written");
        let text = std::fs::read_to_string(&out).unwrap();
        let ja = has_field_state(&d);
        let header = if ja {
            "t,v,i,z,vz,phi,Hc,mode"
        } else {
            "t,v,i,z,vz,phi,mode"
        };
        let name = &d.name;
        assert_eq!(text.lines().next(), Some(header), "{name}: header");
        let csv = Csv::parse(&text);
        assert_eq!(
            csv.rows.len(),
            t_in.len(),
            "{name}: one row per input sample"
        );
        assert_eq!(csv.col("t"), t_in, "{name}: the input's time points");
        assert_eq!(
            csv.col("v"),
            v_in,
            "{name}: the input voltage at its samples"
        );

        let (z_min, z_max) = (d.mechanics.z_min, d.mechanics.z_max);
        let (z, mode) = (csv.col("z"), csv.col("mode"));
        for (k, (&zk, &mk)) in z.iter().zip(&mode).enumerate() {
            assert!(
                [1.0, 2.0, 3.0].contains(&mk),
                "{name}: mode {mk} at row {k}"
            );
            assert!(
                (z_min..=z_max).contains(&zk),
                "{name}: z = {zk} outside [{z_min}, {z_max}] at row {k}"
            );
            if mk == 1.0 {
                assert_eq!(zk, z_min, "{name}: stuck at z_min, row {k}");
            }
            if mk == 3.0 {
                assert_eq!(zk, z_max, "{name}: stuck at z_max, row {k}");
            }
        }
        // From rest at z_max with zero flux (and H_c = 0).
        let first = &csv.rows[0];
        assert_eq!(
            (first[3], first[4], first[5], *first.last().unwrap()),
            (z_max, 0.0, 0.0, 3.0),
            "{name}: initial row {first:?}"
        );
        if ja {
            assert_eq!(csv.col("Hc")[0], 0.0, "{name}: demagnetised start");
            assert!(
                csv.col("Hc").iter().any(|h| h.abs() > 1.0),
                "{name}: H_c moves"
            );
        }
        let max_i = csv.col("i").iter().fold(0.0f64, |a, b| a.max(b.abs()));
        assert!(max_i > 0.01, "{name}: a current flows (max |i| = {max_i})");
        if name == "jiles_atherton_valve" || name == "perfect_tracking_valve" {
            // 6 V does not pull in; 24 V closes; −12 V releases; it lands at z_max.
            assert_eq!(runs(&mode), [3, 2, 1, 2, 3], "{name}: mode sequence");
        }
    }
}

#[test]
fn simulate_is_deterministic_and_stdout_equals_out() {
    let dir = TempDir::new("sim-determinism");
    let model = example_path("jiles-atherton-valve.toml");
    let input = three_pulses();
    let mut outputs = vec![];
    for name in ["a.csv", "b.csv"] {
        let out = dir.join(name);
        rd!("simulate", model, "--input", input, "--out", out,).ok();
        outputs.push(std::fs::read(&out).unwrap());
    }
    assert!(
        outputs[0] == outputs[1],
        "two runs give different CSV bytes"
    );
    let to_stdout = rd!("simulate", model, "--input", input);
    to_stdout.ok();
    assert!(
        to_stdout.stdout == outputs[0],
        "without --out the same CSV goes to stdout"
    );
}

fn generated(dir: &TempDir, model: &Path, input_args: &[&str]) -> Csv {
    let out = dir.join("gen.csv");
    let mut args: Vec<&OsStr> = vec![OsStr::new("simulate"), model.as_os_str()];
    args.extend(input_args.iter().map(OsStr::new));
    args.extend([OsStr::new("--out"), out.as_os_str()]);
    CLI.run(&args).ok();
    let csv = Csv::parse(&std::fs::read_to_string(&out).unwrap());
    std::fs::remove_file(&out).unwrap();
    csv
}

#[test]
fn simulate_pulse_closes_and_reopens_the_perfect_tracking_valve() {
    let dir = TempDir::new("sim-pulse");
    let model = example_path("perfect-tracking-valve.toml");
    let csv = generated(
        &dir,
        &model,
        &["--pulse", "24:0.001:0.008", "--t-end", "0.03"],
    );
    assert_eq!(csv.header.join(","), "t,v,i,z,vz,phi,mode");
    let (t, v, z, mode) = (csv.col("t"), csv.col("v"), csv.col("z"), csv.col("mode"));
    assert_eq!(t.len(), 3001, "0..=30 ms at the default step of 10 µs");
    assert_eq!(t[0], 0.0);
    assert_eq!(*t.last().unwrap(), 0.03);
    for k in 1..t.len() {
        assert!(
            (t[k] - t[k - 1] - 1e-5).abs() < 1e-12,
            "uniform grid at {k}"
        );
    }
    for k in 0..t.len() {
        if t[k] > 0.0011 && t[k] < 0.0079 {
            assert_eq!(v[k], 24.0, "pulse on at t = {}", t[k]);
        } else if t[k] < 0.0009 || t[k] > 0.0081 {
            assert_eq!(v[k], 0.0, "pulse off at t = {}", t[k]);
        }
    }
    let closed: Vec<f64> = (0..t.len())
        .filter(|&k| mode[k] == 1.0)
        .map(|k| t[k])
        .collect();
    assert!(!closed.is_empty(), "the valve never sticks at z_min");
    assert!(z.contains(&0.0), "z never reaches z_min = 0");
    assert!(
        closed[0] > 0.001 && closed[0] < 0.008,
        "closes during the pulse, at {}",
        closed[0]
    );
    assert!(
        *closed.last().unwrap() > 0.008,
        "holds after the pulse ends"
    );
    assert_eq!(runs(&mode), [3, 2, 1, 2, 3], "closes and reopens");
    assert_eq!(*z.last().unwrap(), 1e-3, "ends at z_max");
    assert!(z.iter().all(|&x| (0.0..=1e-3).contains(&x)));
}

#[test]
fn simulate_square_wave_and_negative_pulse() {
    let dir = TempDir::new("sim-square");
    let model = example_path("perfect-tracking-valve.toml");
    let csv = generated(
        &dir,
        &model,
        &["--square", "24:-12:0.02:0.5", "--t-end", "0.04"],
    );
    let (t, v) = (csv.col("t"), csv.col("v"));
    assert_eq!(t.len(), 4001);
    assert_eq!(v[0], 24.0, "starts high at t = 0");
    for k in 0..t.len() {
        assert!(
            v[k] == 24.0 || v[k] == -12.0,
            "v = {} at t = {}",
            v[k],
            t[k]
        );
        let phase = t[k] % 0.02;
        if phase > 1e-4 && phase < 0.0099 {
            assert_eq!(v[k], 24.0, "high in the first half period, t = {}", t[k]);
        } else if phase > 0.0101 && phase < 0.0199 {
            assert_eq!(v[k], -12.0, "low in the second half period, t = {}", t[k]);
        }
    }
    assert!(
        runs(&csv.col("mode")).contains(&1),
        "24 V pulls the valve in"
    );

    // A negative amplitude is a value, not an option.
    let csv = generated(
        &dir,
        &model,
        &["--pulse", "-12:0.001:0.002", "--t-end", "0.004"],
    );
    let v = csv.col("v");
    assert_eq!(v.len(), 401);
    assert_eq!(v[150], -12.0);
    assert!(csv.col("phi")[199] < 0.0, "negative voltage, negative flux");
}

#[test]
fn simulate_plot_writes_an_svg() {
    let dir = TempDir::new("sim-plot");
    let model = example_path("perfect-tracking-valve.toml");
    let (out, svg) = (dir.join("OUT.csv"), dir.join("out.svg"));
    rd!(
        "simulate",
        model,
        "--pulse",
        "24:0.001:0.008",
        "--t-end",
        "0.02",
        "--out",
        out,
        "--plot",
        svg,
    )
    .ok();
    assert_eq!(dir.files(), ["OUT.csv", "out.svg"]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("<svg"),
        "not an SVG: {}",
        &text[..text.len().min(200)]
    );
    assert!(text.trim_end().ends_with("</svg>"), "SVG not complete");
    assert!(
        text.contains("perfect_tracking_valve"),
        "title names the valve"
    );
    assert!(
        text.contains("<polyline") || text.contains("<path"),
        "no curve drawn"
    );
    assert_eq!(
        Csv::parse(&std::fs::read_to_string(&out).unwrap())
            .rows
            .len(),
        2001
    );
}

#[test]
fn simulate_rejects_bad_generated_inputs() {
    let dir = TempDir::new("sim-badargs");
    let model = example_path("perfect-tracking-valve.toml");
    let input = three_pulses();
    let out = dir.join("OUT.csv");
    let m = model.to_str().unwrap();
    let o = out.to_str().unwrap();
    let i = input.to_str().unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (&["simulate", m, "--out", o], &["--input", "--pulse"]),
        (
            &["simulate", m, "--square", "24:0:0.02:0.5", "--out", o],
            &["--t-end"],
        ),
        (
            &[
                "simulate",
                m,
                "--square",
                "24:0:0.02",
                "--t-end",
                "0.1",
                "--out",
                o,
            ],
            &["24:0:0.02", "HIGH:LOW:PERIOD:DUTY"],
        ),
        (
            &["simulate", m, "--pulse", "24:0.002:0.001", "--out", o],
            &["24:0.002:0.001", "END"],
        ),
        (
            &["simulate", m, "--pulse", "24:x:0.001", "--out", o],
            &["24:x:0.001"],
        ),
        (
            &[
                "simulate",
                m,
                "--pulse",
                "24:0.001:0.003",
                "--pulse",
                "12:0.002:0.004",
                "--out",
                o,
            ],
            &["overlap"],
        ),
        (
            &[
                "simulate",
                m,
                "--input",
                i,
                "--pulse",
                "24:0.001:0.003",
                "--out",
                o,
            ],
            &["--input", "--pulse"],
        ),
    ];
    for (args, needles) in cases {
        let run = CLI.run(args);
        run.rejected_in(&format!("case {args:?}"), needles);
        assert!(
            dir.files().is_empty(),
            "case {args:?} left {:?}",
            dir.files()
        );
    }
}

/// The first line of a bad description: `# expect: fragment | fragment …`.
fn expected_fragments(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let first = text.lines().next().unwrap_or("");
    let spec = first
        .strip_prefix("# expect:")
        .unwrap_or_else(|| panic!("{}: first line must be `# expect: …`", path.display()));
    spec.split(" | ").map(|s| s.trim().to_string()).collect()
}

#[test]
fn bad_descriptions_are_rejected_and_leave_no_files() {
    let dir = TempDir::new("bad-toml");
    let input = three_pulses();
    let states = dir.write("STATES.json", r#"{"x": [[0, 0, 0]], "u": [0]}"#);
    let existing = dir.write("KEEP.csv", "t,v,i,z,vz,phi,mode\nold bytes\n");
    let bad = toml_files(&root().join("tests/data/bad"));
    assert!(bad.len() >= 40, "only {} bad descriptions", bad.len());
    for path in &bad {
        let name = base_name(path);
        let fragments = expected_fragments(path);
        let mut needles: Vec<&str> = vec![&name];
        needles.extend(fragments.iter().map(String::as_str));
        let ctx = |what: &str| format!("{what} on {}", path.display());

        let check = rd!("check", path);
        check.rejected_in(&ctx("check"), &needles);

        let out = dir.join("OUT.csv");
        let sim = rd!("simulate", path, "--input", input, "--out", out,);
        sim.rejected_in(&ctx("simulate"), &[&name]);
        assert!(!out.exists(), "{}: OUT.csv was written", ctx("simulate"));

        let keep = rd!(
            "simulate",
            path,
            "--input",
            input,
            "--out",
            existing,
            "--plot",
            dir.join("p.svg"),
        );
        keep.rejected_in(&ctx("simulate over KEEP.csv"), &[&name]);

        let eval = rd!("eval", path, states);
        eval.rejected_in(&ctx("eval"), &[&name]);

        assert_eq!(
            dir.files(),
            ["KEEP.csv", "STATES.json"],
            "{}: files created",
            ctx("simulate")
        );
        assert_eq!(
            std::fs::read_to_string(&existing).unwrap(),
            "t,v,i,z,vz,phi,mode\nold bytes\n",
            "{}: an existing output was touched",
            ctx("simulate")
        );
    }
}

#[test]
fn simulate_rejects_bad_records_and_leaves_the_output_alone() {
    let dir = TempDir::new("bad-csv");
    let model = example_path("perfect-tracking-valve.toml");
    const OLD: &str = "t,v,i,z,vz,phi,mode\n0.0,0.0,0.0,0.001,0.0,0.0,3\n";
    // (what, CSV text, needles besides the file name)
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "non-numeric cell",
            "t,v\n0,0\n1e-5,abc\n2e-5,1\n",
            &["bad.csv:3", "`v`", "abc"],
        ),
        (
            "non-numeric time after a comment",
            "# scope export\nt,v\n0,0\n# trigger\n1e-5,1\nlater,1\n",
            &["bad.csv:6", "`t`", "later"],
        ),
        (
            "non-increasing t",
            "t,v\n0,0\n1e-5,1\n1e-5,2\n",
            &["bad.csv:4", "`t`"],
        ),
        (
            "decreasing t",
            "t,v\n0,0\n2e-5,1\n1e-5,2\n",
            &["bad.csv:4", "`t`"],
        ),
        (
            "missing v column",
            "t,i\n0,0\n1e-5,1\n2e-5,1\n",
            &["bad.csv", "`v`"],
        ),
        (
            "NaN",
            "t,v\n0,0\n1e-5,NaN\n2e-5,1\n",
            &["bad.csv:3", "`v`", "NaN"],
        ),
        (
            "infinite voltage",
            "v,t\n0,0\ninf,1e-5\n1,2e-5\n",
            &["bad.csv:3", "`v`"],
        ),
        ("short row", "t,v\n0,0\n1e-5\n2e-5,1\n", &["bad.csv:3"]),
        ("no data", "t,v\n", &["bad.csv"]),
        ("empty file", "", &["bad.csv"]),
    ];
    let out = dir.write("OUT.csv", OLD);
    for (what, csv, needles) in cases {
        let input = dir.write("bad.csv", csv);
        let run = rd!(
            "simulate",
            model,
            "--input",
            input,
            "--out",
            out,
            "--plot",
            dir.join("plot.svg"),
        );
        let mut all = vec![input.to_str().unwrap()];
        all.extend_from_slice(needles);
        run.rejected_in(&format!("case `{what}`:\n{csv}"), &all);
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            OLD,
            "case `{what}`: OUT.csv was touched"
        );
        assert_eq!(
            dir.files(),
            ["OUT.csv", "bad.csv"],
            "case `{what}` left files"
        );

        // Without --out nothing may reach stdout either (checked by rejected()).
        let run = rd!("simulate", model, "--input", input);
        run.rejected_in(&format!("case `{what}` without --out"), &all);
    }
    let missing = dir.join("no-record.csv");
    rd!("simulate", model, "--input", missing, "--out", out,).rejected(&["no-record.csv"]);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), OLD);
}

#[test]
fn simulate_output_paths() {
    let dir = TempDir::new("sim-paths");
    let model = example_path("perfect-tracking-valve.toml");
    // A missing output directory is created (README: "create output directories").
    let out = dir.join("new-dir").join("OUT.csv");
    rd!("simulate", model, "--input", three_pulses(), "--out", out).ok();
    let header = std::fs::read_to_string(&out).unwrap();
    assert!(header.starts_with("t,v,i,z,vz,phi,mode\n"));
    std::fs::remove_dir_all(dir.join("new-dir")).unwrap();

    // The output path is a directory: the rename fails, the temporary is removed.
    let sub = dir.join("sub");
    std::fs::create_dir(&sub).unwrap();
    rd!("simulate", model, "--input", three_pulses(), "--out", sub).rejected(&["sub"]);
    // A parent that is a regular file: no directory can be created there.
    let file = dir.write("plain-file", "keep\n");
    let under_file = file.join("OUT.csv");
    rd!(
        "simulate",
        model,
        "--input",
        three_pulses(),
        "--out",
        under_file
    )
    .rejected(&["plain-file"]);
    assert_eq!(
        dir.files(),
        ["plain-file", "sub"],
        "a temporary file was left behind"
    );
    assert!(std::fs::read_dir(&sub).unwrap().next().is_none());
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep\n");
}

/// A command that fails must leave an existing output untouched, also when
/// the failure comes after the simulation (here: the plot path is a directory).
#[test]
fn failed_plot_leaves_the_csv_untouched() {
    let dir = TempDir::new("sim-plot-fail");
    let model = example_path("perfect-tracking-valve.toml");
    let out = dir.write("OUT.csv", "old\n");
    let svg = dir.join("plot.svg");
    std::fs::create_dir(&svg).unwrap();
    rd!(
        "simulate",
        model,
        "--input",
        three_pulses(),
        "--out",
        out,
        "--plot",
        svg,
    )
    .rejected(&["plot.svg"]);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old\n");
    assert_eq!(dir.files(), ["OUT.csv", "plot.svg"]);
}

/// `file:line: …` stays greppable: the renderer must not break a long path.
#[test]
fn long_paths_are_not_wrapped() {
    let dir = TempDir::new("long-path");
    let deep = dir.join(&"a_rather_long_directory_name/".repeat(4));
    std::fs::create_dir_all(&deep).unwrap();
    let input = deep.join("bad.csv");
    std::fs::write(&input, "t,v\n0,0\n1e-5,abc\n").unwrap();
    let run = rd!(
        "simulate",
        example_path("perfect-tracking-valve.toml"),
        "--input",
        input,
    );
    run.rejected(&[]);
    let want = format!("{}:3", input.display());
    assert!(
        run.stderr.contains(&want),
        "{want} split\n{}",
        run.context()
    );
}

// ---------------------------------------------------------------------------
// help and usage errors
// ---------------------------------------------------------------------------

#[test]
fn help_lists_the_subcommands() {
    let run = rd!("--help");
    let out = run.ok();
    for word in ["Usage", "check", "eval", "simulate"] {
        assert!(out.contains(word), "--help lacks {word}\n{}", run.context());
    }
    let run = rd!("simulate", "--help");
    let out = run.ok();
    for word in [
        "--input", "--out", "--pulse", "--square", "--t-end", "--plot",
    ] {
        assert!(out.contains(word), "simulate --help lacks {word}\n{out}");
    }
    let run = rd!("--version");
    assert!(
        run.ok().contains(env!("CARGO_PKG_VERSION")),
        "--version prints the version\n{}",
        run.context()
    );
}

#[test]
fn usage_errors_are_helpful() {
    rd!("frobnicate", "valve.toml").rejected(&["frobnicate", "--help"]);
    rd!().rejected(&["Usage", "check", "simulate"]);
    rd!("check").rejected(&["MODEL"]);
    rd!("eval", "valve.toml").rejected(&["STATES"]);
    rd!("simulate", "valve.toml", "--bogus").rejected(&["--bogus"]);
}

// ------------------------------------------------------------------ build

/// `build` writes exactly the checked-in generated module, twice the same
/// bytes, and reports the design on stderr.
#[test]
fn build_emits_the_checked_in_module_deterministically() {
    let dir = TempDir::new("build");
    let (a, b) = (dir.join("a.rs"), dir.join("b.rs"));
    let model = example_path("perfect-tracking-valve.toml");
    for out in [&a, &b] {
        let run = rd!("build", model, "--out", out);
        assert!(run.ok().is_empty(), "the code goes to --out, not stdout");
        for needle in ["energy-optimal: J =", "reference table:", "(54)", "gains K"] {
            assert!(
                run.stderr.contains(needle),
                "report lacks {needle:?}\n{}",
                run.context()
            );
        }
    }
    let code = std::fs::read(&a).unwrap();
    assert_eq!(
        code,
        std::fs::read(&b).unwrap(),
        "build is not deterministic"
    );
    let checked_in = std::fs::read(root().join("generated/src/perfect_tracking_valve.rs")).unwrap();
    assert_eq!(
        code, checked_in,
        "generated/ is stale or build differs from it"
    );
    // stdout mode prints the same module
    let run = rd!("build", model, "--quiet");
    assert_eq!(run.ok().as_bytes(), code.as_slice());
    assert!(
        run.stderr.is_empty(),
        "--quiet prints no report\n{}",
        run.context()
    );
}

/// A description without design sections, and an infeasible design, are
/// clear errors that write nothing.
#[test]
fn build_refuses_what_it_cannot_design() {
    let dir = TempDir::new("build-bad");
    let out = dir.join("out.rs");
    let run = rd!("build", example_path("table-gap-valve.toml"), "--out", out);
    run.rejected(&[
        "table-gap-valve.toml",
        "nothing to build",
        "[trajectory]",
        "[controller]",
    ]);
    assert!(!out.exists());
    // The paper's valve with a 5th-degree polynomial within ±20 V: the closing
    // needs 24.5 V right after takeoff (Fig. 5's saturation).
    let text = std::fs::read_to_string(example_path("perfect-tracking-valve.toml"))
        .unwrap()
        .replace("shape = \"energy-optimal\"", "shape = \"polynomial\"");
    let model = dir.join("polynomial.toml");
    std::fs::write(&model, text).unwrap();
    let run = rd!("build", model, "--out", out);
    run.rejected(&[
        "polynomial.toml",
        "closing reference is infeasible",
        "FAIL (54)",
        "longer motion",
    ]);
    assert!(!out.exists());
    // A [trajectory] with nothing to track it.
    let text = std::fs::read_to_string(example_path("perfect-tracking-valve.toml")).unwrap();
    let start = text.find("[controller]").unwrap();
    let end = start + text[start..].find("\n\n").unwrap();
    let model = dir.join("no-controller.toml");
    std::fs::write(&model, format!("{}{}", &text[..start], &text[end..])).unwrap();
    let run = rd!("build", model, "--out", out);
    run.rejected(&["no-controller.toml", "[trajectory] alone", "[controller]"]);
    assert!(!out.exists());
}
