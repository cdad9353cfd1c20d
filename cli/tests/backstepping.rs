//! `reldesign build` and `reldesign loop` for `[controller] law =
//! "backstepping"` (switched-force-backstepping [SB]): the region in
//! `--report-json` (the fixed keys), the region's SVG, the loop from
//! the paper's initial conditions, and designs that cannot be certified
//! rejected with the reason and what to change, nothing written.

use serde_json::Value;
use support::{example_path, rd, TempDir};

/// The backstepping example's physics with `keys` as its `[controller]`.
fn variant(dir: &TempDir, name: &str, keys: &str) -> std::path::PathBuf {
    let physics = support::example_physics("backstepping-valve.toml");
    dir.write(
        name,
        format!("{physics}\n[controller]\nlaw = \"backstepping\"\nsample_period = 1e-5\n{keys}\n"),
    )
}

#[test]
fn build_reports_the_region_with_its_fixed_keys_and_draws_it() {
    let dir = TempDir::new("bs-build");
    let (out, json, svg) = (dir.join("c.rs"), dir.join("r.json"), dir.join("region.svg"));
    let model = example_path("backstepping-valve.toml");
    let run = rd!(
        "build",
        model,
        "--out",
        out,
        "--report-json",
        json,
        "--plot",
        svg
    );
    let text = run.ok();
    assert!(text.is_empty(), "the code went to the file: {text}");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let region = &report["region"];
    for key in ["a", "p", "c", "decay", "contains_rest", "identity"] {
        assert!(!region[key].is_null(), "region.{key} missing: {region}");
    }
    let number = |v: &Value| v.as_f64().unwrap();
    let a: Vec<Vec<f64>> = serde_json::from_value(region["a"].clone()).unwrap();
    assert_eq!(a, [[-100.0, 1.0], [-1.0, -100.0]]);
    let p: Vec<Vec<f64>> = serde_json::from_value(region["p"].clone()).unwrap();
    assert_eq!(p[0][1], p[1][0]);
    assert!(
        p[0][0] > 0.0 && p[0][0] * p[1][1] > p[0][1] * p[0][1],
        "P ≻ 0: {p:?}"
    );
    assert!(number(&region["c"]) > 0.0 && number(&region["decay"]) == 40.0);
    assert_eq!(region["contains_rest"], Value::Bool(true));
    assert_eq!(region["identity"]["contains_rest"], Value::Bool(false));
    // the regions' velocity extent max |z₂| = √(C·(P⁻¹)₂₂), scale-free: the
    // paper's V₁ (P = ½I) admits 0.0122 m/s, the LMI's 0.0632 m/s (the rest
    // on z_max has z₂ = α₁·(z_max − y_r) = 0.06 m/s)
    let det = p[0][0] * p[1][1] - p[0][1] * p[0][1];
    let extent = (number(&region["c"]) * p[0][0] / det).sqrt();
    let paper = (number(&region["identity"]["c"]) * 2.0).sqrt();
    assert!(
        (extent - 0.0632).abs() < 5e-4 && (paper - 0.0122).abs() < 2e-4,
        "{extent} {paper}"
    );
    assert_eq!(report["controller"]["law"], "backstepping");
    assert_eq!(report["controller"]["switching"], "hybrid");
    let svg = std::fs::read_to_string(&svg).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("F_d = 0") && svg.contains("X₀"));
    assert!(std::fs::read_to_string(&out)
        .unwrap()
        .contains("SwitchedBackstepping<Design, f64>"));
}

#[test]
fn uncertifiable_designs_are_rejected_with_the_reason_and_nothing_is_written() {
    let dir = TempDir::new("bs-bad");
    let cases = [
        (
            "rest-outside.toml",
            "gains = [1000.0, 1000.0, 5000.0]\nswitching = \"hybrid\"\nposition = 5e-4",
            vec![
                "no quadratic V",
                "spring's rest",
                "change the gains",
                "switching = \"none\"",
            ],
        ),
        (
            "decay.toml",
            "gains = [100.0, 100.0, 2000.0]\ndecay = 500.0\nposition = 5e-4",
            vec!["α = 500", "α ≤ 200", "controller.decay"],
        ),
    ];
    for (name, keys, needles) in cases {
        let model = variant(&dir, name, keys);
        let (out, json, svg) = (dir.join("c.rs"), dir.join("r.json"), dir.join("r.svg"));
        let run = rd!(
            "build",
            model,
            "--out",
            out,
            "--report-json",
            json,
            "--plot",
            svg
        );
        let mut all = vec![name];
        all.extend(needles.iter().copied());
        run.rejected(&all);
        for f in [&out, &json, &svg] {
            assert!(!f.exists(), "{name}: {} written", f.display());
        }
    }
    // targets the magnet cannot hold: one where the spring pulls closed (no
    // attracting flux balances it), one beyond the supply's steady input
    for (name, keys, needles) in [
        (
            "pulls.toml",
            "gains = [100.0, 100.0, 2000.0]\nposition = 5e-4",
            vec!["cannot be held", "the magnet only attracts"],
        ),
        (
            "supply.toml",
            "gains = [100.0, 100.0, 2000.0]\nposition = 5e-4",
            vec!["needs a steady input", "supply.u_max"],
        ),
    ] {
        let text = std::fs::read_to_string(variant(&dir, name, keys)).unwrap();
        let text = if name == "pulls.toml" {
            text.replace("preload = -0.75", "preload = 0.0")
        } else {
            text.replace("u_max = 24.0", "u_max = 5.0")
        };
        let model = dir.write(name, text);
        let out = dir.join("c.rs");
        let mut all = vec![name];
        all.extend(needles.iter().copied());
        rd!("build", model, "--out", out).rejected(&all);
        assert!(!out.exists(), "{name}: code written");
    }
    // without switching the same gains design (the region is reported, X₀ outside)
    let model = variant(
        &dir,
        "none.toml",
        "gains = [1000.0, 1000.0, 5000.0]\nswitching = \"none\"\nposition = 5e-4",
    );
    let json = dir.join("none.json");
    rd!(
        "build",
        model,
        "--out",
        dir.join("none.rs"),
        "--report-json",
        json
    )
    .ok();
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["region"]["contains_rest"], Value::Bool(false));
    // sweep compares landings: a positioner is refused with the command to use
    let example = example_path("backstepping-valve.toml");
    rd!("sweep", example).rejected(&["backstepping", "no soft landing to sweep", "reldesign loop"]);
    // --plot is the backstepping law's
    let other = example_path("perfect-tracking-valve.toml");
    rd!(
        "build",
        other,
        "--out",
        dir.join("pt.rs"),
        "--plot",
        dir.join("pt.svg")
    )
    .rejected(&["--plot", "backstepping"]);
    assert!(!dir.join("pt.rs").exists());
}

#[test]
fn loop_runs_from_the_papers_initial_conditions() {
    let dir = TempDir::new("bs-loop");
    let model = variant(
        &dir,
        "hold.toml",
        "gains = [100.0, 100.0, 2000.0]\nswitching = \"hybrid\"\nposition = 5e-4",
    );
    let out = dir.join("loop.csv");
    // outside D with F_d < 0: rushing towards z_min
    let run = rd!(
        "loop",
        model,
        "--out",
        out,
        "--initial-state",
        "8e-4,-3,0",
        "--duration",
        "0.08"
    );
    let text = run.ok();
    assert!(
        text.contains("start outside D") && text.contains("switched 1 time(s)"),
        "{text}"
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    let header = csv.lines().next().unwrap();
    assert_eq!(
        header,
        "t,u,i,z,vz,phi,mode,z_ref,switching,lyapunov,desired_force"
    );
    let last: Vec<f64> = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    assert!((last[3] - 5e-4).abs() < 5e-6, "z(80 ms) = {}", last[3]);
    assert_eq!(last[8], 2.0, "inside D at the end");
    // the option is the backstepping law's; a malformed state is refused
    let pt = example_path("perfect-tracking-valve.toml");
    rd!(
        "loop",
        pt,
        "--out",
        dir.join("x.csv"),
        "--initial-state",
        "8e-4,0,0"
    )
    .rejected(&["--initial-state", "backstepping"]);
    rd!(
        "loop",
        model,
        "--out",
        dir.join("y.csv"),
        "--initial-state",
        "8e-4,0"
    )
    .rejected(&["--initial-state", "three"]);
    assert!(!dir.join("x.csv").exists() && !dir.join("y.csv").exists());
}
