//! The energy-optimal design's messages and `reldesign limits` (issue 11), on
//! the 12 V relay of the issue (`tests/data/relay-12v.toml`):
//!
//! - every failure class says which operation, what is violated and what to
//!   change, with a number; the numbers are checked against the CasADi/IPOPT
//!   direct-collocation oracle's bracket (`tests/oracle/` style, run once by
//!   hand: 5.15 V infeasible, 5.25 V feasible for the 6 ms closing; 3.50 ms
//!   infeasible, 3.62 ms feasible at ±10 V);
//! - a slow motion lands early and rests, and the report says so;
//! - a C¹ table gap is designed on its C² twin, and the report says so;
//! - `limits` prints, writes JSON and an SVG, and its shortest motion agrees
//!   with the design's own "needs" figure.

use std::path::{Path, PathBuf};

use serde_json::Value;
use support::{example_path, rd, root, TempDir};

/// `tests/data/relay-12v.toml` with some of its text replaced, in a fresh
/// directory (kept while the returned `TempDir` lives).
fn relay_with(name: &str, replacements: &[(&str, &str)]) -> (TempDir, PathBuf) {
    let mut text = std::fs::read_to_string(root().join("tests/data/relay-12v.toml")).unwrap();
    for (from, to) in replacements {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    let dir = TempDir::new(&format!("limits-{name}"));
    let path = dir.write("relay.toml", text);
    (dir, path)
}

/// `reldesign build MODEL`, the code written to a scratch directory (never
/// next to the model: some models are the repository's test data).
fn build(model: &Path) -> (bool, String) {
    let dir = TempDir::new("limits-build");
    let run = rd!("build", model, "--out", dir.join("out.rs"));
    (run.succeeded(), run.stderr)
}

/// The number that follows `key` in `text`.
fn number_after(text: &str, key: &str) -> f64 {
    let at = text
        .find(key)
        .unwrap_or_else(|| panic!("`{key}` not in:\n{text}"))
        + key.len();
    let digits: String = text[at..]
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.' || *c == 'e' || *c == '-')
        .collect();
    digits.parse().unwrap_or_else(|e| panic!("{digits:?}: {e}"))
}

#[test]
fn a_slow_motion_lands_early_and_rests_and_the_report_says_so() {
    let (ok, report) = build(&root().join("tests/data/relay-12v.toml"));
    assert!(ok, "{report}");
    assert!(report.contains("closing"), "{report}");
    assert!(report.contains("the motion lands at"), "{report}");
    assert!(report.contains("the motion rests until"), "{report}");
    let lands = number_after(&report, "the motion lands at");
    assert!((7.5..9.5).contains(&lands), "{lands} ms");
    assert!(!report.contains("improve the initial guess"));
}

#[test]
fn a_bound_too_low_says_which_bound_it_needs() {
    let (_dir, model) = relay_with(
        "bound",
        &[
            ("landing = 11e-3", "landing = 7e-3"),
            ("u_bound = 10.0", "u_bound = 4.0"),
        ],
    );
    let (ok, err) = build(&model);
    assert!(!ok);
    assert!(
        err.contains("the closing energy-optimal trajectory"),
        "{err}"
    );
    assert!(
        err.contains("keeps the input within trajectory.u_bound = 4.0000 V"),
        "{err}"
    );
    let needed = number_after(&err, "it needs trajectory.u_bound ≥");
    // the IPOPT oracle: infeasible at 5.15 V, feasible at 5.25 V
    assert!((5.15..5.26).contains(&needed), "{needed}");
    assert!(err.contains("the supply allows 12.0000 V"), "{err}");
}

#[test]
fn a_motion_too_short_says_which_time_it_needs() {
    let (_dir, model) = relay_with("short", &[("landing = 11e-3", "landing = 2.5e-3")]);
    let (ok, err) = build(&model);
    assert!(!ok);
    assert!(
        err.contains("no motion of 1.5000 ms exists with the input in [-10.0000, 10.0000] V"),
        "{err}"
    );
    assert!(
        err.contains("a larger trajectory.u_bound, up to the supply, does not help"),
        "{err}"
    );
    let needed = number_after(&err, "it needs trajectory.landing − trajectory.takeoff ≥");
    // the IPOPT oracle: infeasible at 3.50 ms, feasible at 3.62 ms
    assert!((3.5..3.65).contains(&needed), "{needed}");
}

#[test]
fn a_rest_state_that_needs_no_flux_is_named() {
    // no preload and no spring: the armature rests anywhere without flux, so
    // the rest states of (61)–(62) are outside the linearizable region φ > 0
    let (_dir, model) = relay_with(
        "rest",
        &[
            ("stiffness = 200.0", "stiffness = 0.0"),
            ("preload = -0.3", "preload = 0.0"),
        ],
    );
    let (ok, err) = build(&model);
    assert!(!ok);
    assert!(
        err.contains("the closing energy-optimal trajectory"),
        "{err}"
    );
    assert!(err.contains("resting at z = 5e-4 needs φ²"), "{err}");
    assert!(
        err.contains("cannot be balanced by a positive flux"),
        "{err}"
    );
}

#[test]
fn a_hermite_table_gap_is_designed_on_its_c2_twin() {
    let text = std::fs::read_to_string(example_path("table-gap-valve.toml")).unwrap();
    let design = "\n[trajectory]\noperations = [\"closing\"]\ntakeoff = 1e-3\nlanding = 6e-3\n\
                  shape = \"energy-optimal\"\nu_bound = 20.0\n\n[controller]\n\
                  law = \"feedback-linearization\"\nsettling_time = 1e-3\nsample_period = 1e-5\n";
    let dir = TempDir::new("limits-table");
    let path = dir.write("table.toml", text + design);
    let (ok, report) = build(&path);
    assert!(ok, "{report}");
    assert!(
        report.contains("note: the gap table's cubic Hermite through the given r_prime (C¹)"),
        "{report}"
    );
    assert!(
        report.contains("quintic Hermite through the same values and slopes (C²)"),
        "{report}"
    );
}

#[test]
fn limits_prints_json_and_a_plot_consistent_with_the_design() {
    let model = root().join("tests/data/relay-12v.toml");
    let dir = TempDir::new("limits-limits");
    let svg = dir.join("limits.svg");
    let out = rd!("limits", model, "--json", "--plot", svg).ok();
    let v: Value = serde_json::from_str(&out).unwrap();
    let ops = v["operations"].as_array().unwrap();
    assert_eq!(ops.len(), 2);
    assert_eq!(ops[0]["operation"], "closing");
    let closing = &ops[0];
    let at_supply = closing["supply"]["shortest_motion"].as_f64().unwrap();
    let at_bound = closing["u_bound"]["shortest_motion"].as_f64().unwrap();
    // the supply allows more input than u_bound: a faster motion
    assert!(at_supply < at_bound, "{at_supply} {at_bound}");
    // the design's own figure at ±10 V (IPOPT bracket [3.50, 3.62] ms)
    assert!((3.5e-3..3.65e-3).contains(&at_bound), "{at_bound}");
    assert!(closing["u_bound"]["peak_current"].as_f64().unwrap() > 0.0);
    // J falls from the fastest motion, then rises once rest is cheaper
    let curve = closing["u_bound"]["cost_curve"].as_array().unwrap();
    let j: Vec<f64> = curve.iter().map(|p| p["cost"].as_f64().unwrap()).collect();
    let min = j.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(j[0] > 2.0 * min && j[j.len() - 1] > min, "{j:?}");
    assert!(curve.iter().any(|p| p["rests"] == true));
    let resting_from = closing["u_bound"]["resting_from"].as_f64().unwrap();
    assert!((6.5e-3..8.0e-3).contains(&resting_from), "{resting_from}");
    let svg = std::fs::read_to_string(svg).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("closing (shortest"));

    let text = rd!("limits", model).ok();
    for needle in [
        "closing:",
        "opening:",
        "within the supply",
        "within trajectory.u_bound",
        "pull-in",
    ] {
        assert!(text.contains(needle), "`{needle}` missing:\n{text}");
    }
}

#[test]
fn limits_refuses_a_hysteretic_core_with_a_reason() {
    rd!("limits", example_path("jiles-atherton-valve.toml")).rejected(&[
        "Pontryagin",
        "sign(dφ/dt)",
        "polynomial",
    ]);
}

#[test]
fn an_infeasible_polynomial_says_which_time_it_needs_and_that_time_works() {
    let poly = [("shape = \"energy-optimal\"", "shape = \"polynomial\"")];
    let (_short, short) = relay_with(
        "poly-short",
        &[poly[0], ("landing = 11e-3", "landing = 3e-3")],
    );
    let (ok, err) = build(&short);
    assert!(!ok);
    assert!(err.contains("the closing reference is infeasible"), "{err}");
    let needed = number_after(
        &err,
        "the polynomial needs trajectory.landing − trajectory.takeoff ≥",
    );
    // the polynomial needs more time than the energy-optimal motion (3.56 ms)
    assert!(needed > 3.6, "{needed}");
    let landing = format!("landing = {:e}", 1e-3 + 1.002 * needed * 1e-3);
    let (_enough, enough) = relay_with("poly-enough", &[poly[0], ("landing = 11e-3", &landing)]);
    let (ok, report) = build(&enough);
    assert!(ok, "{report}");
    let landing = format!("landing = {:e}", 1e-3 + 0.98 * needed * 1e-3);
    let (_too_short, too_short) =
        relay_with("poly-too-short", &[poly[0], ("landing = 11e-3", &landing)]);
    assert!(!build(&too_short).0);
}

/// With `[trajectory] standoff`, `limits` says how much of t_f − t₀ the
/// approach holds (5·δ/(4·v_c)), in its text and its JSON; without, null.
#[test]
fn limits_names_the_approachs_share_of_the_motion() {
    let (_dir, model) = relay_with(
        "standoff",
        &[(
            "u_bound = 10.0",
            "u_bound = 10.0\nstandoff = 20e-6\napproach_speed = 10e-3",
        )],
    );
    let v: Value = serde_json::from_str(&rd!("limits", model, "--json").ok()).unwrap();
    let approach = v["approach_time"].as_f64().unwrap();
    assert!((approach - 2.5e-3).abs() < 1e-15, "{approach}");
    assert!(rd!("limits", model).ok().contains("holds the approach too"));
    let plain = root().join("tests/data/relay-12v.toml");
    let v: Value = serde_json::from_str(&rd!("limits", plain, "--json").ok()).unwrap();
    assert!(v["approach_time"].is_null());
}
