//! The actuator description: rejections as data, and the bundled examples.
//!
//! Every `tests/data/bad/NAME.toml` is a broken description whose first line
//! is `# expect: FRAGMENT | FRAGMENT …`: parsing it must fail, and the
//! one-line message must contain the file name and every fragment.
//! Every `examples/*.toml` must parse; a few values are spot-checked.

use std::path::Path;

use designer::description::{
    parse_file, parse_str, Controller, Core, Description, Drive, FloatType, Gains, Gap, Law,
    Operation, Shape, Trajectory,
};
use support::{assert_close, example_path, example_paths, replaced_once, root, toml_files, Tol};

/// The fragments of the `# expect:` first line.
fn expectations(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).expect("readable test file");
    let first = text.lines().next().unwrap_or_default();
    let list = first
        .strip_prefix("# expect:")
        .unwrap_or_else(|| panic!("{}: first line must be `# expect: …`", path.display()));
    let fragments: Vec<String> = list
        .split(" | ")
        .map(|f| f.trim().to_string())
        .filter(|f| !f.is_empty())
        .collect();
    assert!(
        !fragments.is_empty(),
        "{}: no expected fragment",
        path.display()
    );
    fragments
}

/// Checks one bad file; returns a description of the failure, if any.
fn check_bad(path: &Path) -> Option<String> {
    let name = path.file_name().unwrap().to_string_lossy().to_string();
    let err = match parse_file(path) {
        Ok(_) => return Some(format!("{name}: accepted, but it must be rejected")),
        Err(err) => err,
    };
    let message = err.to_string();
    let mut problems = Vec::new();
    if message.contains('\n') {
        problems.push("message is not one line".to_string());
    }
    if !message.contains(&name) {
        problems.push("message does not name the file".to_string());
    }
    if err.line() == 0 || err.column() == 0 {
        problems.push(format!(
            "no position (line {}, column {})",
            err.line(),
            err.column()
        ));
    }
    for fragment in expectations(path) {
        if !message.contains(&fragment) {
            problems.push(format!("missing fragment `{fragment}`"));
        }
    }
    (!problems.is_empty()).then(|| format!("{name}: {}\n    got: {message}", problems.join("; ")))
}

#[test]
fn every_bad_description_is_rejected_with_its_expected_message() {
    let files = toml_files(&root().join("tests/data/bad"));
    assert!(
        files.len() >= 24,
        "expected at least 24 bad descriptions, found {}",
        files.len()
    );
    let failures: Vec<String> = files.iter().filter_map(|p| check_bad(p)).collect();
    assert!(
        failures.is_empty(),
        "{} of {} bad files:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

/// The text of a bundled example, for tests that edit it.
/// The physics sections of a bundled example (its design sections, and the
/// comment lines that introduce them, are cut off so tests can add their own).
fn example_text(name: &str) -> String {
    let text = std::fs::read_to_string(example_path(name)).expect("example exists");
    let mut lines: Vec<&str> = text
        .lines()
        .take_while(|l| !l.starts_with("[trajectory]") && !l.starts_with("[controller]"))
        .collect();
    while lines
        .last()
        .is_some_and(|l| l.starts_with('#') || l.trim().is_empty())
    {
        lines.pop();
    }
    lines.join("\n") + "\n"
}

fn example(name: &str) -> Description {
    parse_file(&example_path(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// Values the parser computes from the description: exact but for rounding.
const EXACT: Tol = Tol::rel(1e-12);

#[test]
fn every_bundled_example_parses() {
    let files = example_paths();
    assert!(
        files.len() >= 5,
        "expected at least 5 examples, found {}",
        files.len()
    );
    for path in &files {
        let description = parse_file(path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(description.source.file_name, path.display().to_string());
        assert!(description.mechanics.z_min < description.mechanics.z_max);
    }
}

#[test]
fn perfect_tracking_valve_has_table_1_numbers() {
    let d = example("perfect-tracking-valve.toml");
    assert_eq!(d.name, "perfect_tracking_valve");
    assert_eq!(d.coil.turns, 1200.0);
    assert_eq!(d.coil.resistance, 75.0);
    assert_eq!(d.coil.eddy, 1500.0);
    assert_eq!(d.coil.resistance_drift, 0.0, "default of resistance_drift");
    assert_eq!(
        d.gap,
        Gap::McLyman {
            area: 20e-6,
            winding_length: 15e-3
        }
    );
    assert_eq!(
        d.core,
        Core::Saturating {
            r0: 3e6,
            phi_sat: 25e-6
        }
    );
    assert_eq!(d.mechanics.preload, -0.75);
    assert_eq!(d.mechanics.restitution, 0.5);
    assert_eq!(
        (d.supply.drive, d.supply.u_min, d.supply.u_max),
        (Drive::Voltage, -24.0, 24.0)
    );
}

#[test]
fn preload_is_resolved_from_rest_position() {
    let ja = example("jiles-atherton-valve.toml");
    assert_close(
        ja.mechanics.preload,
        -55.0 * 0.015,
        EXACT,
        "JA valve F0 = -k_s·z_s",
    );
    let sm = example("sliding-mode-valve.toml");
    assert_close(
        sm.mechanics.preload,
        -61.8 * 0.019,
        EXACT,
        "sliding-mode valve F0",
    );
    let semera = example("semera-valve.toml");
    assert_close(
        semera.mechanics.preload,
        -37.0 * 22.5e-3,
        EXACT,
        "semera valve F0",
    );
}

#[test]
fn jiles_atherton_valve_uses_the_errata_reading() {
    let d = example("jiles-atherton-valve.toml");
    assert_eq!(
        d.gap,
        Gap::McLymanFit {
            r0: 2.41e6,
            r0_prime: 7.94e10,
            k1: 1350.0,
            k2: 9.95e-3
        }
    );
    let Core::JilesAtherton(ja) = &d.core else {
        panic!("expected a Jiles–Atherton core, got {:?}", d.core)
    };
    assert_eq!(
        (ja.c, ja.kappa, ja.alpha, ja.epsilon),
        (0.736, 943.0, 3.66e-3, 1e-3)
    );
    assert_eq!(d.coil.resistance, 50.0);
    assert_eq!(d.mechanics.z_max, 9e-4);
}

#[test]
fn semera_valve_has_linear_gap_and_no_eddy() {
    let d = example("semera-valve.toml");
    assert_eq!(
        d.gap,
        Gap::Linear {
            slope: 2.7e10,
            offset: 0.0
        }
    );
    assert_close(
        match d.core {
            Core::Saturating { phi_sat, .. } => phi_sat,
            ref other => panic!("expected a saturating core, got {other:?}"),
        },
        0.024 / 1200.0,
        EXACT,
        "phi_sat = lambda_sat/N",
    );
    assert_eq!(d.coil.eddy, 0.0);
}

#[test]
fn table_gap_valve_reproduces_the_mclyman_formula() {
    let d = example("table-gap-valve.toml");
    let Gap::Table { z, r, r_prime } = &d.gap else {
        panic!("expected a table gap, got {:?}", d.gap)
    };
    let r_prime = r_prime.as_ref().expect("r_prime given");
    assert_eq!((z.len(), r.len(), r_prime.len()), (12, 12, 12));
    let (mu0, area, l_w) = (4e-7 * std::f64::consts::PI, 20e-6_f64, 15e-3_f64);
    assert_eq!(r[0], 0.0);
    assert!(
        (r_prime[0] * mu0 * area - 1.0).abs() < 1e-6,
        "R'(0) = 1/(mu0·A)"
    );
    for (zi, ri) in z.iter().zip(r).skip(1) {
        let mclyman = (zi / (mu0 * area)) / (1.0 + zi / area.sqrt() * (2.0 * l_w / zi).ln());
        assert!(
            (ri / mclyman - 1.0).abs() < 1e-6,
            "R({zi}) = {ri}, formula gives {mclyman}"
        );
    }
}

#[test]
fn optional_keys_take_their_defaults() {
    let text = example_text("jiles-atherton-valve.toml").replace("epsilon = 1e-3", "");
    let d = parse_str(&text, "ja.toml").unwrap_or_else(|e| panic!("{e}"));
    let Core::JilesAtherton(ja) = d.core else {
        panic!("expected a Jiles–Atherton core")
    };
    assert_eq!(ja.epsilon, 1e-3);
    let text = example_text("semera-valve.toml").replace("offset = 0.0", "");
    let d = parse_str(&text, "semera.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        d.gap,
        Gap::Linear {
            slope: 2.7e10,
            offset: 0.0
        }
    );
}

#[test]
fn integers_are_accepted_where_floats_are_expected() {
    let text =
        example_text("perfect-tracking-valve.toml").replace("stiffness = 50.0", "stiffness = 50");
    let d = parse_str(&text, "int.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(d.mechanics.stiffness, 50.0);
}

#[test]
fn error_accessors_give_key_file_and_position() {
    let text = example_text("perfect-tracking-valve.toml").replace("mass = 2e-3 ", "mass = -1e-3");
    let err = parse_str(&text, "valve.toml").expect_err("negative mass must be rejected");
    let line = text.lines().position(|l| l.starts_with("mass =")).unwrap() + 1;
    assert_eq!(
        (err.key(), err.file_name()),
        ("mechanics.mass", "valve.toml")
    );
    assert_eq!((err.line(), err.column()), (line, 1));
    assert!(
        err.to_string()
            .starts_with(&format!("valve.toml:{line}:1: mechanics.mass: ")),
        "{err}"
    );
    let span = err.span().expect("a span");
    assert!(text[span].starts_with("mass = -1e-3"));
}

#[test]
fn diagnostic_renders_file_position_and_label() {
    use miette::{GraphicalReportHandler, GraphicalTheme};
    let text =
        example_text("perfect-tracking-valve.toml").replace("phi_sat = 25e-6", "phi_sat = 0");
    let err = parse_str(&text, "valve.toml").expect_err("phi_sat = 0 must be rejected");
    let mut out = String::new();
    GraphicalReportHandler::new_themed(GraphicalTheme::unicode_nocolor())
        .render_report(&mut out, &err)
        .expect("render");
    let line = text.lines().position(|l| l.starts_with("phi_sat")).unwrap() + 1;
    assert!(out.contains(&format!("valve.toml:{line}:1")), "{out}");
    assert!(out.contains("phi_sat = 0"), "{out}");
    assert!(out.contains("expected a number > 0"), "{out}");
}

#[test]
fn unreadable_file_is_an_error_naming_it() {
    let path = root().join("tests/data/bad/does-not-exist.toml");
    let err = parse_file(&path).expect_err("missing file");
    assert!(err.to_string().contains("does-not-exist.toml"), "{err}");
    assert!(err.to_string().contains("cannot read"), "{err}");
}

#[test]
fn unknown_key_in_an_inline_table_points_at_its_column() {
    let coil = "[coil]\nturns = 1200\nresistance = 75.0\neddy = 1500.0\n";
    let inline = "coil = { turns = 1200, resistance = 75.0, eddy = 1500.0, wire = 2 }\n";
    let text = example_text("perfect-tracking-valve.toml").replace(
        "[coil]\nturns = 1200                # N, Table 1\nresistance = 75.0           # R = 75 Ω, Table 1\neddy = 1500.0               # k_ec = 1500 A/V, Table 1\n",
        coil,
    );
    assert!(
        text.contains(coil),
        "example layout changed: update this test"
    );
    let text = text
        .replace(coil, "")
        .replacen("\n[gap]", &format!("{inline}\n[gap]"), 1);
    let err = parse_str(&text, "inline.toml").expect_err("unknown key");
    assert_eq!(err.key(), "coil.wire");
    let line = text
        .lines()
        .position(|l| l.starts_with("coil = {"))
        .unwrap()
        + 1;
    assert_eq!(
        (err.line(), err.column()),
        (line, inline.find("wire").unwrap() + 1)
    );
}

// ------------------------------------------------- [trajectory], [controller]

/// The paper's design (perfect-tracking-soft-landing §4–5).
const TRAJECTORY: &str = r#"
[trajectory]
operations = ["closing", "opening"]
takeoff = 1e-3
landing = 6e-3
shape = "energy-optimal"
u_bound = 20.0
"#;

const CONTROLLER: &str = r#"
[controller]
law = "feedback-linearization"
settling_time = 1e-3
sample_period = 1e-5
"#;

/// `example` with `sections` appended, parsed.
fn with_sections(example: &str, sections: &str) -> Description {
    let text = example_text(example) + sections;
    parse_str(&text, "design.toml").unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_perfect_tracking_example_carries_the_papers_design() {
    for path in example_paths() {
        let d = parse_file(&path).unwrap_or_else(|e| panic!("{e}"));
        let designed = path.file_name().is_some_and(|n| {
            n == "perfect-tracking-valve.toml"
                || n == "sliding-mode-valve.toml"
                || n == "self-calibrating-valve.toml"
                || n == "self-calibrating-sensor-valve.toml"
                || n == "uncertain-stop-valve.toml"
        });
        assert_eq!(
            d.trajectory.is_some() && d.controller.is_some(),
            designed,
            "{}",
            path.display()
        );
        if path.ends_with("uncertain-stop-valve.toml") {
            // the perfect-tracking design with stops spread 1 % of the stroke
            let t = d.trajectory.as_ref().unwrap();
            assert_eq!(
                (t.shape, t.contact_uncertainty),
                (Shape::EnergyOptimal, 0.01 * d.mechanics.z_max)
            );
        } else if let Some(t) = &d.trajectory {
            assert_eq!(t.contact_uncertainty, 0.0, "{}", path.display());
        }
        if path.ends_with("sliding-mode-valve.toml") {
            // model-free-sliding-mode §4.2: τ_mov = 4 ms, λ₁ = λ₂ = 2000, η = 1e5
            let t = d.trajectory.unwrap();
            assert_eq!(
                (t.takeoff, t.landing, t.shape),
                (1e-3, 5e-3, Shape::Polynomial)
            );
            let Law::SlidingMode(s) = d.controller.unwrap().law else {
                panic!("sliding-mode-valve.toml: not the sliding-mode law");
            };
            assert_eq!((s.lambda1, s.lambda2, s.eta), (2000.0, 2000.0, 1e5));
        } else if path.ends_with("self-calibrating-valve.toml") {
            // sensorless at 50 µs, a longer motion under a lower bound, a move
            // of 7 ms ending 50 µm short of each stop, approached at 10 mm/s
            // (the guide)
            let t = d.trajectory.unwrap();
            assert_eq!(
                (t.takeoff, t.landing, t.u_bound, t.shape),
                (1e-3, 14.25e-3, 18.0, Shape::EnergyOptimal)
            );
            assert_eq!((t.standoff, t.approach_speed), (50e-6, Some(10e-3)));
            let c = d.controller.unwrap();
            assert!(c.self_calibration && c.estimator.is_some());
        } else if designed {
            if path.ends_with("self-calibrating-sensor-valve.toml") {
                // the paper's design on sensors, with the replay self-calibration
                let c = d.controller.as_ref().unwrap();
                assert!(c.self_calibration && c.estimator.is_none());
            }
            let t = d.trajectory.unwrap();
            assert_eq!(
                (t.takeoff, t.landing, t.u_bound, t.shape),
                (1e-3, 6e-3, 20.0, Shape::EnergyOptimal)
            );
            assert_eq!(
                d.controller.unwrap().law,
                Law::FeedbackLinearization(Gains::SettlingTime(1e-3))
            );
        }
    }
}

#[test]
fn both_sections_parse_into_the_expected_values() {
    let d = with_sections(
        "perfect-tracking-valve.toml",
        &format!("{TRAJECTORY}{CONTROLLER}"),
    );
    assert_eq!(
        d.trajectory,
        Some(Trajectory {
            operations: vec![Operation::Closing, Operation::Opening],
            takeoff: 1e-3,
            landing: 6e-3,
            shape: Shape::EnergyOptimal,
            u_bound: 20.0,
            contact_uncertainty: 0.0,
            standoff: 0.0,
            approach_speed: None,
        })
    );
    assert_eq!(
        d.controller,
        Some(Controller {
            law: Law::FeedbackLinearization(Gains::SettlingTime(1e-3)),
            sample_period: 1e-5,
            floats: vec![FloatType::F32, FloatType::F64],
            creep_speed: None,
            landed_band: None,
            estimator: None,
            compensate_resistance: false,
            self_calibration: false,
        }),
        "float defaults to both, creep_speed to the generator's"
    );
}

#[test]
fn sections_may_come_in_any_order_and_before_the_physics() {
    let text = format!("{CONTROLLER}{TRAJECTORY}",);
    let example = example_text("perfect-tracking-valve.toml");
    let (head, physics) = example.split_at(example.find("\n[coil]").unwrap());
    let d = parse_str(&format!("{head}\n{text}{physics}"), "order.toml")
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(d.trajectory.is_some() && d.controller.is_some());
}

#[test]
fn trajectory_alone_is_allowed_and_keeps_the_operation_order() {
    let traj = TRAJECTORY
        .replace(r#"["closing", "opening"]"#, r#"["opening", "closing"]"#)
        .replace(r#""energy-optimal""#, r#""polynomial""#);
    let d = with_sections("perfect-tracking-valve.toml", &traj);
    let t = d.trajectory.expect("trajectory");
    assert_eq!(t.operations, [Operation::Opening, Operation::Closing]);
    assert_eq!(t.shape, Shape::Polynomial);
    assert_eq!(d.controller, None);
    let single = TRAJECTORY.replace(r#"["closing", "opening"]"#, r#"["opening"]"#);
    let d = with_sections("perfect-tracking-valve.toml", &single);
    assert_eq!(d.trajectory.unwrap().operations, [Operation::Opening]);
}

#[test]
fn poles_are_an_alternative_to_the_settling_time() {
    let poles = CONTROLLER.replace(
        "settling_time = 1e-3",
        "poles = [-6296, -5000.5, -7000.0]  # integers accepted",
    );
    let d = with_sections(
        "perfect-tracking-valve.toml",
        &format!("{TRAJECTORY}{poles}"),
    );
    assert_eq!(
        d.controller.unwrap().law,
        Law::FeedbackLinearization(Gains::Poles([-6296.0, -5000.5, -7000.0])),
        "kept in the order given"
    );
}

#[test]
fn float_types_are_stored_sorted() {
    for (given, stored) in [
        (r#"["f64", "f32"]"#, vec![FloatType::F32, FloatType::F64]),
        (r#"["f32", "f64"]"#, vec![FloatType::F32, FloatType::F64]),
        (r#"["f64"]"#, vec![FloatType::F64]),
        (r#"["f32"]"#, vec![FloatType::F32]),
    ] {
        let controller = format!("{CONTROLLER}float = {given}\n");
        let d = with_sections(
            "perfect-tracking-valve.toml",
            &format!("{TRAJECTORY}{controller}"),
        );
        assert_eq!(d.controller.unwrap().floats, stored, "float = {given}");
    }
}

#[test]
fn u_bound_may_reach_u_max_and_the_sample_period_its_limit() {
    let traj = TRAJECTORY.replace("u_bound = 20.0", "u_bound = 24");
    let controller = CONTROLLER.replace("sample_period = 1e-5", "sample_period = 5e-4");
    let d = with_sections(
        "perfect-tracking-valve.toml",
        &format!("{traj}{controller}"),
    );
    assert_eq!(d.trajectory.unwrap().u_bound, 24.0);
    assert_eq!(d.controller.unwrap().sample_period, 5e-4);
}

#[test]
fn a_unipolar_supply_accepts_a_bound_above_u_min() {
    let text = example_text("perfect-tracking-valve.toml").replace("u_min = -24.0", "u_min = 0.0");
    let d = parse_str(&format!("{text}{TRAJECTORY}{CONTROLLER}"), "unipolar.toml")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(d.trajectory.unwrap().u_bound, 20.0);
}

/// The Jiles–Atherton example's physics (its own design sections cut).
fn ja_physics() -> String {
    example_text("jiles-atherton-valve.toml")
}

#[test]
fn jiles_atherton_core_refuses_only_the_energy_optimal_trajectory() {
    let text = ja_physics() + TRAJECTORY;
    let err = parse_str(&text, "ja.toml").expect_err("JA + energy-optimal");
    assert_eq!(err.key(), "trajectory.shape");
    assert!(
        err.message().contains("costate") && err.message().contains("polynomial"),
        "{err}"
    );
    // a polynomial reference, tracked by each law
    let polynomial = TRAJECTORY.replace("energy-optimal", "polynomial");
    for controller in [
        CONTROLLER.to_owned(),
        CONTROLLER.replace(
            "law = \"feedback-linearization\"\nsettling_time = 1e-3",
            "law = \"model-sliding-mode\"\np = 1e3\nk = 1e4",
        ),
    ] {
        let d = parse_str(&(ja_physics() + &polynomial + &controller), "ja.toml")
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(d.controller.is_some());
    }
}

#[test]
fn model_sliding_mode_holds_a_position_without_a_trajectory() {
    let hold = "\n[controller]\nlaw = \"model-sliding-mode\"\np = 1e3\nk = 1e4\nposition = 4.5e-4\nsample_period = 5e-5\n";
    let d = parse_str(&(ja_physics() + hold), "hold.toml").unwrap_or_else(|e| panic!("{e}"));
    let Some(Law::ModelSlidingMode(s)) = d.controller.map(|c| c.law) else {
        panic!("not the model-based sliding mode");
    };
    assert_eq!((s.p, s.k, s.position), (1e3, 1e4, Some(4.5e-4)));
    // the stops are holdable positions too ([JA 94])
    for z in ["0.0", "9e-4"] {
        let text = ja_physics() + &hold.replace("4.5e-4", z);
        assert!(parse_str(&text, "hold.toml").is_ok(), "{z}");
    }
}

#[test]
fn design_errors_point_at_their_key() {
    let controller = CONTROLLER.replace("sample_period = 1e-5", "sample_period = 2e-3");
    let text = example_text("perfect-tracking-valve.toml") + TRAJECTORY + &controller;
    let err = parse_str(&text, "ts.toml").expect_err("sample period too long");
    let line = text
        .lines()
        .position(|l| l.starts_with("sample_period"))
        .unwrap()
        + 1;
    assert_eq!(
        (err.key(), err.line(), err.column()),
        ("controller.sample_period", line, 1)
    );
    assert!(text[err.span().unwrap()].starts_with("sample_period = 2e-3"));

    let traj = TRAJECTORY.replace(r#"["closing", "opening"]"#, r#"["closing", "closing"]"#);
    let text = example_text("perfect-tracking-valve.toml") + &traj;
    let err = parse_str(&text, "dup.toml").expect_err("duplicate operation");
    let row = text
        .lines()
        .position(|l| l.starts_with("operations"))
        .unwrap();
    let col = text.lines().nth(row).unwrap().rfind("\"closing\"").unwrap() + 1;
    assert_eq!(
        (err.key(), err.line(), err.column()),
        ("trajectory.operations[1]", row + 1, col)
    );
}

#[test]
fn misspelt_design_keys_get_a_suggestion() {
    use miette::Diagnostic;
    let controller = CONTROLLER.replace("settling_time", "setling_time");
    let text = example_text("perfect-tracking-valve.toml") + TRAJECTORY + &controller;
    let err = parse_str(&text, "typo.toml").expect_err("unknown key");
    assert_eq!(err.key(), "controller.setling_time");
    let help = err.help().map(|h| h.to_string());
    assert_eq!(help.as_deref(), Some("did you mean `settling_time`?"));
}

/// `controller.estimator = "ekf"` on a soft-landing law parses, with a
/// warning that names the key and the evidence; the UKF, none.
#[test]
fn an_ekf_driven_soft_landing_is_warned_against() {
    let text = std::fs::read_to_string(root().join("tests/data/sensorless-valve.toml")).unwrap();
    let with = |estimator: &str| {
        let text = text.replacen(
            "[controller]\n",
            &format!("[controller]\nestimator = \"{estimator}\"\n"),
            1,
        );
        parse_str(&text, "sensorless.toml").unwrap_or_else(|e| panic!("{e}"))
    };
    let ekf = with("ekf");
    assert_eq!(ekf.warnings.len(), 1, "{:?}", ekf.warnings);
    let w = &ekf.warnings[0];
    assert!(
        w.starts_with("sensorless.toml:") && w.contains("controller.estimator"),
        "{w}"
    );
    assert!(w.contains("hovers") && w.contains("ukf"), "{w}");
    assert!(with("ukf").warnings.is_empty());
}

/// Feedback linearization whose gains would leave the armature more than
/// 2 % of the stroke from its stop where the spring is 10 % off parses,
/// with a warning at the gain's key that gives the steady error
/// ((k3 − c/m)/k1)·Δk_s·z/m and a settling time that keeps it within 2 %
/// (parsed back, it does); the perfect-tracking valve itself (its spring
/// soft against its gains: 0.19 µm at 1 ms) gets none, nor does the stiff
/// spring under the sliding-mode law, nor at a closing stop at z = 0.
#[test]
fn gains_too_slow_for_the_spring_are_warned_about() {
    let text = example_text("perfect-tracking-valve.toml") + TRAJECTORY + CONTROLLER;
    assert!(parse_str(&text, "design.toml").unwrap().warnings.is_empty());
    // k_s ×40 (the preload with it, so the spring still holds the valve
    // open): at 1 ms 7.6 µm, at 2 ms 30 µm of the 1 mm stroke
    let stiff = replaced_once(&text, "stiffness = 50.0", "stiffness = 2000.0");
    let stiff = replaced_once(&stiff, "preload = -0.75", "preload = -3.0");
    assert!(parse_str(&stiff, "design.toml")
        .unwrap()
        .warnings
        .is_empty());
    let slow = replaced_once(&stiff, "settling_time = 1e-3", "settling_time = 2e-3");
    let d = parse_str(&slow, "design.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(d.warnings.len(), 1, "{:?}", d.warnings);
    let w = &d.warnings[0];
    assert!(
        w.starts_with("design.toml:") && w.contains("controller.settling_time"),
        "{w}"
    );
    let lambda = designer::description::triple_pole_settling_product() / 2e-3;
    let (c_m, da) = (0.1 / 2e-3, 0.1 * 2000.0 * 1e-3 / 2e-3);
    let error = (3.0 * lambda - c_m) / lambda.powi(3) * da;
    assert!((error - 3.02e-5).abs() < 1e-7, "{error}");
    assert!(
        w.contains(&format!("{error:.3e} m")) && w.contains("z_max"),
        "{w}"
    );
    // the settling time it names keeps the error within 2 % of the stroke
    let named: f64 = w
        .split("a settling time ≤ ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("no settling time in {w}"));
    assert!(named > 1.5e-3 && named < 2e-3, "{named}");
    let at_named = replaced_once(
        &slow,
        "settling_time = 2e-3",
        &format!("settling_time = {named:e}"),
    );
    assert!(
        parse_str(&at_named, "design.toml")
            .unwrap()
            .warnings
            .is_empty(),
        "{named}"
    );
    // with poles the warning names `poles`
    let poles = replaced_once(
        &slow,
        "settling_time = 2e-3",
        "poles = [-3000.0, -3000.0, -3000.0]",
    );
    let d = parse_str(&poles, "design.toml").unwrap_or_else(|e| panic!("{e}"));
    assert!(
        d.warnings.iter().any(|w| w.contains("controller.poles")),
        "{:?}",
        d.warnings
    );
    // only the closing, whose stop z_min = 0 has no spring force to miss
    let closing = replaced_once(
        &slow,
        "operations = [\"closing\", \"opening\"]",
        "operations = [\"closing\"]",
    );
    assert!(parse_str(&closing, "design.toml")
        .unwrap()
        .warnings
        .is_empty());
    // another law: not checked
    let sliding = replaced_once(
        &slow,
        "law = \"feedback-linearization\"\nsettling_time = 2e-3",
        "law = \"sliding-mode\"\nlambda1 = 2000.0\nlambda2 = 2000.0\neta = 1e5",
    );
    let d = parse_str(&sliding, "design.toml").unwrap_or_else(|e| panic!("{e}"));
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
}
