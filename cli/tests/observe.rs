//! `reldesign observe MODEL.toml DATA.csv [--out OUT.csv]`: the estimates
//! are the designer's (SEMERA, integral) on the recording, the report names
//! the unobservable intervals, and every bad input is rejected with the file
//! and the row or key named, leaving no output behind.

use std::fmt::Write as _;
use std::path::PathBuf;

use designer::description::{parse_file, Description};
use designer::model::Model;
use designer::observe::integral::{Integral, IntegralConfig};
use designer::observe::semera::{Semera, SemeraConfig};
use designer::replay::replay;
use designer::sim::{Options, PiecewiseLinear};
use support::{example_path, rd, root, TempDir};

fn valve_path() -> PathBuf {
    example_path("semera-valve.toml")
}

/// `reldesign observe ARGS…`.
macro_rules! obs {
    ($($arg:expr),* $(,)?) => {
        rd!("observe", $($arg),*)
    };
}

/// Two cycles of the 0/30 V square wave through the semera valve, sampled
/// every Δ with Gaussian noise σ_v, σ_i: `t,v,i,z` (z is ignored).
fn recording(d: &Description) -> String {
    let o = d.observer.as_ref().unwrap();
    let dt = o.sample_period;
    let n = (40e-3 / dt).round() as usize;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 * dt).collect();
    let input = PiecewiseLinear::square_wave(30.0, 0.0, 20e-3, 0.5, 40e-3).unwrap();
    let run = replay(&mut Model::build(d), &input, &t, &Options::default()).unwrap();
    let mut state = 88172645463325252u64;
    let mut gauss = move || {
        let mut u = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (a, b) = (u(), u());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    };
    let mut s = String::from("# semera valve, 0/30 V square wave\nt,v,i,z\n");
    for (k, &tk) in t.iter().enumerate() {
        let mid = tk - 0.5 * dt;
        let v = if mid >= 0.0 && (mid / 20e-3).fract() < 0.5 {
            30.0
        } else {
            0.0
        };
        let _ = writeln!(
            s,
            "{:?},{:?},{:?},{:?}",
            tk,
            v + o.voltage_noise * gauss(),
            run.current[k] + o.current_noise * gauss(),
            run.trajectory.x[k][0]
        );
    }
    s
}

/// (t, v, i) of a recording's text.
fn columns(text: &str) -> Vec<[f64; 3]> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('t'))
        .map(|l| {
            let c: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [c[0], c[1], c[2]]
        })
        .collect()
}

#[test]
fn observe_writes_the_designer_estimates_and_the_blind_intervals() {
    let dir = TempDir::new("ok");
    let d = parse_file(&valve_path()).unwrap();
    let text = recording(&d);
    let data = dir.write("DATA.csv", &text);
    let out = dir.join("OUT.csv");
    let run = obs!(valve_path(), data, "--out", out, "--stride", "4");
    let report = run.ok();
    assert!(run.stderr.is_empty(), "{}", run.context());
    assert!(
        report.contains("DATA.csv: 801 samples"),
        "{}",
        run.context()
    );
    assert!(report.contains("unobservable intervals"));
    assert!(
        report.contains("no current"),
        "the rest at the end is blind"
    );
    assert!(
        report.contains("no excitation"),
        "the steady current is blind"
    );
    assert_eq!(dir.files(), ["DATA.csv", "OUT.csv"]);

    // the same numbers as the designer's estimators on the same samples
    let rows = columns(&text);
    let mut s = Semera::new(&SemeraConfig::from_description(&d).unwrap());
    let mut g = Integral::new(&IntegralConfig::from_description(&d).unwrap());
    let mut want = String::from(
        "t,semera_r,semera_l,semera_lambda,semera_phi,semera_valid,\
         integral_r,integral_l,integral_lambda,integral_phi,integral_valid\n",
    );
    for [t, v, i] in rows {
        let _ = write!(want, "{t:?}");
        for e in [s.step(v, i), g.step(v, i)] {
            let _ = write!(
                want,
                ",{:?},{:?},{:?},{:?},{}",
                e.r,
                e.l,
                e.lambda,
                e.phi,
                u8::from(e.valid)
            );
        }
        want.push('\n');
    }
    let got = std::fs::read_to_string(&out).unwrap();
    assert_eq!(got, want, "OUT.csv differs from the designer's estimates");

    // without --out: the CSV on stdout, the report on stderr
    let run = obs!(valve_path(), data);
    assert_eq!(run.ok(), want);
    assert!(run.stderr.contains("unobservable intervals"));
    assert_eq!(dir.files(), ["DATA.csv", "OUT.csv"]);
}

#[test]
fn observe_rejects_bad_input_and_writes_nothing() {
    let dir = TempDir::new("bad");
    let d = parse_file(&valve_path()).unwrap();
    let good = recording(&d);
    let keep = "old bytes\n";
    let existing = dir.write("KEEP.csv", keep);
    let valve = std::fs::read_to_string(valve_path()).unwrap();
    let physics = &valve[..valve.find("\n# Estimation").unwrap()];

    let no_observer = dir.write("no-observer.toml", physics);
    let kalman_only = dir.write(
        "kalman-only.toml",
        &format!(
            "{physics}\n[observer]\nestimators = [\"ekf\"]\nsample_period = 50e-6\n\
             voltage_noise = 15e-3\ncurrent_noise = 1e-3\n\n[observer.kalman]\nprocess_z = 1e-7\n\
             process_phi = 1e-9\ninitial_z_std = 1e-5\ninitial_phi_std = 1e-7\n"
        ),
    );
    let bad_toml = root().join("tests/data/bad/observer-semera-missing-key.toml");

    // (description, recording text, what stderr must name)
    let mut lines: Vec<&str> = good.lines().collect();
    let header = lines[1];
    let cases: Vec<(PathBuf, String, Vec<&str>)> = vec![
        (
            no_observer.clone(),
            good.clone(),
            vec!["no-observer.toml", "no [observer] section"],
        ),
        (
            kalman_only.clone(),
            good.clone(),
            vec![
                "kalman-only.toml",
                "observer.estimators",
                "\"semera\"",
                "\"integral\"",
            ],
        ),
        (
            bad_toml.clone(),
            good.clone(),
            vec![
                "observer-semera-missing-key.toml",
                "observer.semera.inductance_accel_std",
            ],
        ),
        (
            valve_path(),
            good.replacen(header, "t,v,current,z", 1),
            vec!["DATA.csv", "missing column `i`"],
        ),
        (
            valve_path(),
            {
                lines[5] = "2e-4,30.0,abc,0.0";
                lines.join("\n")
            },
            vec!["DATA.csv:6", "`i`", "abc"],
        ),
        (
            valve_path(),
            // every other sample: Δ = 100 µs
            good.lines()
                .enumerate()
                .filter(|(k, _)| *k < 2 || k % 2 == 0)
                .map(|(_, l)| format!("{l}\n"))
                .collect(),
            vec![
                "DATA.csv",
                "`t`",
                "observer.sample_period",
                "semera-valve.toml",
            ],
        ),
        (
            valve_path(),
            good.replacen("\n0.0001,", "\n0.00011,", 1),
            vec!["DATA.csv:5", "`t`", "not uniform"],
        ),
        (
            valve_path(),
            "t,v,i\n0,0,0\n5e-5,0,0\n".into(),
            vec!["DATA.csv", "at least 4 data rows"],
        ),
    ];
    for (model, text, needles) in cases {
        let data = dir.write("DATA.csv", &text);
        let out = dir.join("OUT.csv");
        obs!(model, data, "--out", out).rejected(&needles);
        obs!(model, data, "--out", existing).rejected(&needles);
        obs!(model, data).rejected(&needles);
        assert_eq!(
            dir.files(),
            [
                "DATA.csv",
                "KEEP.csv",
                "kalman-only.toml",
                "no-observer.toml"
            ],
            "a file was written for {needles:?}"
        );
        assert_eq!(std::fs::read_to_string(&existing).unwrap(), keep);
    }
    let data = dir.write("DATA.csv", &good);
    obs!(valve_path(), data, "--stride", "0").rejected(&["--stride"]);
    obs!(valve_path(), dir.join("missing.csv")).rejected(&["missing.csv"]);
}
