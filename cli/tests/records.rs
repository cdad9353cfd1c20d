//! Records as DAQ software writes them (issue 12 §4), through the binary:
//! `simulate --input` reads a byte-order mark, quoted names, CRLF and
//! semicolons as it reads the plain form; a decimal comma is named; and what
//! `simulate` writes is valid measured data whatever `--dt` (no shorter last
//! step).

use std::path::Path;

use designer::record::Record;
use support::{example_path, rd, Run, TempDir};

fn simulate(input: &Path, out: &Path) -> Run {
    let model = example_path("semera-valve.toml");
    rd!("simulate", model, "--input", input, "--out", out)
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
    let dir = TempDir::new("records-daq");
    let plain_in = dir.join("plain.csv");
    std::fs::write(&plain_in, pulse("t,v,i", ",", "\n", false)).unwrap();
    let plain_out = dir.join("plain-out.csv");
    simulate(&plain_in, &plain_out).ok();
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
        simulate(&input, &out).ok();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), expected, "{name}");
    }
    let eu = dir.join("eu.csv");
    std::fs::write(&eu, "t;v;i\n0;1,5;0\n5e-5;1,5;0\n").unwrap();
    simulate(&eu, &dir.join("eu-out.csv")).rejected(&["eu.csv:2", "decimal comma"]);
}

#[test]
fn what_simulate_writes_is_uniform_measured_data_whatever_the_step() {
    let dir = TempDir::new("records-dt");
    let model = example_path("semera-valve.toml");
    for dt in ["7e-6", "2e-5", "3.3e-5"] {
        let out = dir.join(format!("sq-{dt}.csv"));
        rd!(
            "simulate",
            model,
            "--square",
            "30:0:0.01:0.5",
            "--t-end",
            "0.02",
            "--dt",
            dt,
            "--out",
            out
        )
        .ok();
        let r = Record::read(&out).unwrap();
        let t = r.time(2).unwrap();
        r.check_uniform(&t)
            .unwrap_or_else(|e| panic!("--dt {dt}: {e}"));
        assert!(*t.last().unwrap() <= 0.02 + 1e-12);
    }
}
