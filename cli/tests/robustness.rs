//! `reldesign robustness` (model-free-sliding-mode-soft-landing §4.1): the JSON
//! contract of `shared/spec/cli.md`, the Monte Carlo's reproducibility, and
//! bad input rejected with a message that names what and where.

use serde_json::Value;
use support::{example_path, rd, TempDir};

fn json(run: &support::Run) -> Value {
    serde_json::from_str(&run.ok()).unwrap_or_else(|e| panic!("{e}\n{}", run.context()))
}

#[test]
fn json_follows_the_contract() {
    let model = example_path("sliding-mode-valve.toml");
    let out = json(&rd!("robustness", model, "--json"));
    let ops = out["operations"].as_array().unwrap();
    assert_eq!(ops.len(), 2);
    for (op, name) in ops.iter().zip(["closing", "opening"]) {
        assert_eq!(op["operation"], name);
        for key in ["max_u_star", "required_u_max", "u_max"] {
            assert!(op[key].as_f64().is_some_and(f64::is_finite), "{key}: {op}");
        }
        let (u, req) = (
            op["u_max"].as_f64().unwrap(),
            op["required_u_max"].as_f64().unwrap(),
        );
        assert_eq!(op["feasible"], true);
        assert_eq!(op["met"], u >= req);
        assert!(op["max_u_star"].as_f64().unwrap() < req);
    }
    assert!(out.get("monte_carlo").is_none(), "only with --vary");
}

#[test]
fn monte_carlo_reports_the_worst_draw_and_repeats_exactly() {
    let model = example_path("sliding-mode-valve.toml");
    let args = |seed: &str| {
        rd!(
            "robustness",
            model,
            "--json",
            "--samples",
            "200",
            "--draws",
            "40",
            "--seed",
            seed,
            "--vary",
            "coil.resistance=±10%",
            "--vary",
            "mechanics.stiffness=±20%"
        )
    };
    let (a, b, c) = (json(&args("3")), json(&args("3")), json(&args("4")));
    assert_eq!(a, b, "same seed, same answer");
    let mc = &a["monte_carlo"];
    assert_ne!(mc, &c["monte_carlo"]);
    assert_eq!(mc["draws"], 40);
    let worst = mc["worst_draw"].as_object().unwrap();
    assert_eq!(worst.len(), 2);
    let r = worst["coil.resistance"].as_f64().unwrap();
    assert!((45.0..=55.0).contains(&r), "{r}");
    let share = mc["share_met"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&share));
    let nominal: f64 = a["operations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o["required_u_max"].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!(mc["worst_required_u_max"].as_f64().unwrap() >= nominal);
}

#[test]
fn text_names_the_infeasible_operation() {
    let dir = TempDir::new("robustness-text");
    let text = std::fs::read_to_string(example_path("sliding-mode-valve.toml"))
        .unwrap()
        .replace("takeoff = 1e-3", "takeoff = 0.75e-3")
        .replace("landing = 5e-3", "landing = 3.75e-3");
    let model = dir.write("three-ms.toml", text);
    let out = rd!("robustness", model).ok();
    let opening = &out[out.find("opening:").expect("opening block")..];
    assert!(opening.contains("INFEASIBLE between"), "{out}");
    assert!(out.contains("NOT met"), "{out}");
}

#[test]
fn bad_input_is_named() {
    let dir = TempDir::new("robustness-bad");
    let sm = example_path("sliding-mode-valve.toml");
    rd!("robustness", sm, "--vary", "coil.resistence=±10%")
        .rejected(&["coil.resistence", "coil.resistance"]);
    rd!("robustness", sm, "--vary", "coil.resistance=10").rejected(&["±P%"]);
    rd!(
        "robustness",
        sm,
        "--vary",
        "coil.resistance=±5%",
        "--draws",
        "0"
    )
    .rejected(&["--draws"]);
    rd!("robustness", sm, "--velocity-error=-5").rejected(&["--velocity-error"]);
    rd!("robustness", example_path("perfect-tracking-valve.toml")).rejected(&[
        "perfect-tracking-valve.toml",
        "sliding-mode",
        "feedback-linearization",
    ]);
    rd!("robustness", example_path("semera-valve.toml")).rejected(&["[controller]"]);
    let broken = std::fs::read_to_string(&sm)
        .unwrap()
        .replace("eta = 1e5", "eta = -1e5");
    let broken = dir.write("broken.toml", broken);
    rd!("robustness", broken).rejected(&["broken.toml", "controller.eta", "> 0"]);
    assert_eq!(dir.files(), ["broken.toml"], "nothing written");
}
