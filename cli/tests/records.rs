//! Records as DAQ software writes them (issue 12 §4), through the binary:
//! `simulate --input` reads a byte-order mark, quoted names, CRLF and
//! semicolons as it reads the plain form; a decimal comma is named; and what
//! `simulate` writes is valid measured data whatever `--dt` (no shorter last
//! step).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use designer::record::Record;

const BIN: &str = env!("CARGO_BIN_EXE_reldesign");

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("cli/ has a parent")
        .to_path_buf()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("reldesign-records-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

fn simulate(input: &Path, out: &Path) -> Output {
    let model = root().join("examples/semera-valve.toml");
    run(&[
        "simulate",
        model.to_str().unwrap(),
        "--input",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

/// A 5 ms, 30 V pulse sampled every 50 µs, in the given layout.
fn pulse(header: &str, sep: &str, eol: &str, quote: bool) -> String {
    let q = |s: String| if quote { format!("\"{s}\"") } else { s };
    let mut text = format!("{header}{eol}");
    for k in 0..=200 {
        let t = k as f64 * 5e-5;
        let v = if (1e-3..6e-3).contains(&t) { 30.0 } else { 0.0 };
        text += &format!(
            "{}{sep}{}{sep}{}{eol}",
            q(format!("{t:e}")),
            q(format!("{v}")),
            q("0".into())
        );
    }
    text
}

#[test]
fn daq_exports_replay_as_the_plain_form_does() {
    let dir = scratch("daq");
    let plain_in = dir.join("plain.csv");
    std::fs::write(&plain_in, pulse("t,v,i", ",", "\n", false)).unwrap();
    let plain_out = dir.join("plain-out.csv");
    assert!(simulate(&plain_in, &plain_out).status.success());
    let expected = std::fs::read_to_string(&plain_out).unwrap();
    let forms = [
        (
            "bom",
            format!("\u{feff}{}", pulse("t,v,i", ",", "\n", false)),
        ),
        ("quoted", pulse("\"t\",\"v\",\"i\"", ",", "\n", true)),
        ("crlf", pulse("t,v,i", ",", "\r\n", false)),
        (
            "all",
            format!("\u{feff}{}", pulse("\"t\",\"v\",\"i\"", ",", "\r\n", true)),
        ),
        ("semicolons", pulse("t;v;i", ";", "\n", false)),
    ];
    for (name, text) in forms {
        let input = dir.join(format!("{name}.csv"));
        std::fs::write(&input, text).unwrap();
        let out = dir.join(format!("{name}-out.csv"));
        let o = simulate(&input, &out);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert_eq!(std::fs::read_to_string(&out).unwrap(), expected, "{name}");
    }
    let eu = dir.join("eu.csv");
    std::fs::write(&eu, "t;v;i\n0;1,5;0\n5e-5;1,5;0\n").unwrap();
    let o = simulate(&eu, &dir.join("eu-out.csv"));
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("eu.csv:2") && err.contains("decimal comma"),
        "{err}"
    );
}

#[test]
fn what_simulate_writes_is_uniform_measured_data_whatever_the_step() {
    let dir = scratch("dt");
    let model = root().join("examples/semera-valve.toml");
    for dt in ["7e-6", "2e-5", "3.3e-5"] {
        let out = dir.join(format!("sq-{dt}.csv"));
        let o = run(&[
            "simulate",
            model.to_str().unwrap(),
            "--square",
            "30:0:0.01:0.5",
            "--t-end",
            "0.02",
            "--dt",
            dt,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let r = Record::read(&out).unwrap();
        let t = r.time(2).unwrap();
        r.check_uniform(&t)
            .unwrap_or_else(|e| panic!("--dt {dt}: {e}"));
        assert!(*t.last().unwrap() <= 0.02 + 1e-12);
    }
}
