//! The self-calibrating file (`[controller] self_calibration`, the example
//! `examples/self-calibrating-valve.toml`): it compiles as a `#![no_std]`
//! crate against the runtime, passes clippy with the panic lints denied, and
//! is total: the law at every odd state and θ (inside and outside its
//! domain) gives a finite input within the supply, the filter's estimate at
//! odd measurements and θ stays finite or is repaired, and the update on odd
//! records refuses or keeps θ in its domain. Without the key the file is the
//! one of every parameter a folded const: no θ anywhere.

use std::fmt::Write as _;

use support::{example_path, ScratchCrate, ODD_FLOATS};

fn emitted(text: &str) -> String {
    let d = designer::description::parse_str(text, "self-calibrating-valve.toml")
        .unwrap_or_else(|e| panic!("{e}"));
    let design = designer::design::Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    reldesign_build::emit(&design).unwrap_or_else(|e| panic!("{e}"))
}

fn example_text() -> String {
    std::fs::read_to_string(example_path("self-calibrating-valve.toml")).expect("the example")
}

#[test]
fn without_the_key_no_parameter_is_read_at_run_time() {
    let text = example_text().replace("self_calibration = true", "self_calibration = false");
    let code = emitted(&text);
    for absent in ["theta", "calibration!", "THETA_DESIGN", "fn calibrate"] {
        assert!(
            !code.contains(absent),
            "`{absent}` in the file without self_calibration"
        );
    }
}

#[test]
fn emitted_module_compiles_passes_clippy_and_is_total() {
    let krate = ScratchCrate::new("codegen-check-calibration");
    krate.write(
        "src/lib.rs",
        "//! Emitted by codegen/tests/calibration.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n\npub mod valve;\n",
    );
    krate.write("src/valve.rs", &emitted(&example_text()));
    let odd = ODD_FLOATS.join(", ");
    let mut main = String::from(
        "use codegen_check_calibration::valve;\nuse reldesign_runtime::calibrate::Outcome;\n\nfn main() {\n",
    );
    for module in ["f64", "f32"] {
        writeln!(
            main,
            "    {{
        use valve::{module}::*;
        type F = {module};
        let odd: [F; 9] = [{odd}];
        // θ: the design's, its domain's ends, and each entry odd in turn
        let mut thetas = vec![THETA_DESIGN, valve::ukf::{module}::THETA_LOWER, valve::ukf::{module}::THETA_UPPER];
        for (k, x) in odd.iter().enumerate() {{
            let mut t = THETA_DESIGN;
            t[k % t.len()] = *x;
            thetas.push(t);
        }}
        for theta in &thetas {{
            for z in [Z_MIN, Z_MAX, 5e-4, odd[2], odd[8]] {{
                for phi in [PHI_GUARD, 8e-6, -1e-5, odd[0], odd[4], odd[8]] {{
                    for t in [0.0, T_TAKEOFF, 0.5 * (T_TAKEOFF + T_LANDING), T_LANDING + 2.0 * ARRIVAL_MARGIN, odd[8]] {{
                        let mut c = Controller::with(Design {{ theta: *theta }}, Operation::Closing);
                        c.start(0.0);
                        let u = c.step(t, z, 0.1, phi);
                        println!(\"law {module} {{u:e}}\");
                    }}
                }}
            }}
            let mut f = valve::ukf::{module}::Filter::new();
            f.model_mut().theta = *theta;
            for (u, i) in [(24.0, 0.1), (odd[4], 0.1), (0.0, odd[8]), (odd[8], odd[6]), (-24.0, 0.05)] {{
                let e = f.step(u, i);
                println!(\"filter {module} {{:e}} {{:e}}\", e.z, e.phi);
            }}
        }}
        use valve::ukf::{module} as k;
        for fill in [0.0, 0.1, odd[6], odd[8]] {{
            let mut record = k::Record::new();
            record.start(Z_MAX);
            for _ in 0..k::RECORD_CAPACITY {{
                record.push(&k::CALIBRATION, 24.0, 24.0, fill);
            }}
            let mut calibration = k::Calibration::new(&k::CALIBRATION);
            let outcome = k::calibrate(&mut calibration, &record);
            let inside = calibration.theta.iter().zip(k::THETA_LOWER.iter().zip(&k::THETA_UPPER))
                .all(|(t, (lo, hi))| lo.min(*hi) <= *t && *t <= lo.max(*hi));
            let updated = matches!(outcome, Outcome::Updated {{ .. }});
            println!(\"update {module} {{inside}} {{updated}}\");
        }}
    }}"
        )
        .unwrap();
    }
    main.push_str("}\n");
    krate.write("src/main.rs", &main);
    let text = krate.run_panic_free(&[]);
    let (laws, filters, updates) = tally(&text, |f| match f {
        ["filter", _, z, phi] => {
            let (z, phi): (f64, f64) = (z.parse().unwrap(), phi.parse().unwrap());
            z.is_finite() && (0.0..=1e-3).contains(&z) && phi.is_finite()
        }
        _ => panic!("{f:?}"),
    });
    let thetas = 3 + 9;
    assert_eq!(laws, 2 * thetas * 5 * 6 * 5);
    assert_eq!(filters, 2 * thetas * 5);
    assert_eq!(updates, 2 * 4);
}

#[test]
fn a_self_calibration_without_the_ukf_is_refused_naming_the_key() {
    let text = example_text()
        .replace("estimator = \"ukf\"", "estimator = \"ekf\"")
        .replace("estimators = [\"ukf\"]", "estimators = [\"ekf\"]");
    let d =
        designer::description::parse_str(&text, "ekf-valve.toml").unwrap_or_else(|e| panic!("{e}"));
    let design = designer::design::Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let message = match reldesign_build::emit(&design) {
        Ok(_) => panic!("a self-calibrating design without a UKF was emitted"),
        Err(e) => e.to_string(),
    };
    for part in [
        "ekf-valve.toml",
        "self_calibration",
        "[observer] estimators",
        "ukf",
    ] {
        assert!(message.contains(part), "`{part}` not in: {message}");
    }
}

/// The replay self-calibration of a design on sensors
/// (`examples/self-calibrating-sensor-valve.toml`): the file compiles
/// `no_std`, passes clippy's panic lints, and is total: the law at odd θ
/// gives a finite input within the supply, the model and its Jacobians at
/// odd states do not panic, and the update on odd records refuses or keeps θ
/// in its domain.
#[test]
fn the_replay_update_compiles_passes_clippy_and_is_total() {
    let text = std::fs::read_to_string(example_path("self-calibrating-sensor-valve.toml"))
        .expect("the example");
    let krate = ScratchCrate::new("codegen-check-replay");
    krate.write(
        "src/lib.rs",
        "//! Emitted by codegen/tests/calibration.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n\npub mod valve;\n",
    );
    krate.write("src/valve.rs", &emitted(&text));
    let odd = ODD_FLOATS.join(", ");
    let mut main = String::from(
        "use codegen_check_replay::valve;\nuse reldesign_runtime::calibrate::{Outcome, Predictor};\n\nfn main() {\n",
    );
    for module in ["f64", "f32"] {
        writeln!(
            main,
            "    {{
        use valve::{module}::*;
        type F = {module};
        let odd: [F; 9] = [{odd}];
        let mut thetas = vec![THETA_DESIGN, THETA_LOWER, THETA_UPPER];
        for (k, x) in odd.iter().enumerate() {{
            let mut t = THETA_DESIGN;
            t[k % t.len()] = *x;
            thetas.push(t);
        }}
        for theta in &thetas {{
            for z in [Z_MIN, Z_MAX, 5e-4, odd[2], odd[8]] {{
                for phi in [PHI_GUARD, 8e-6, odd[0], odd[8]] {{
                    let mut c = Controller::with(Design {{ theta: *theta }}, Operation::Opening);
                    c.start(0.0);
                    let u = c.step(0.5 * (T_TAKEOFF + T_LANDING), z, 0.1, phi);
                    println!(\"law {module} {{u:e}}\");
                    let d = Model.derivative(theta, &[z, 0.1, phi], odd[3]);
                    let i = Model.current(theta, &[z, 0.1, phi], odd[5]);
                    println!(\"model {module} {{}}\", d.dx[0].is_nan() && i.i.is_nan());
                }}
            }}
        }}
        for (u, fill) in [(24.0, 0.1), (12.0, 0.0), (odd[4], odd[6]), (5.0, odd[8])] {{
            let mut record = Record::new();
            record.start(Z_MAX);
            for k in 0..RECORD_CAPACITY * CALIBRATION.decimation as usize {{
                let i = fill * (1.0 + (k % 7) as F / 10.0);
                record.push(&CALIBRATION, u, u, i);
            }}
            let mut calibration = Calibration::new(&CALIBRATION);
            let outcome = calibrate(&mut calibration, &record);
            let inside = calibration.theta.iter().zip(THETA_LOWER.iter().zip(&THETA_UPPER))
                .all(|(t, (lo, hi))| lo.min(*hi) <= *t && *t <= lo.max(*hi));
            let updated = matches!(outcome, Outcome::Updated {{ .. }});
            println!(\"update {module} {{inside}} {{updated}}\");
        }}
    }}"
        )
        .unwrap();
    }
    main.push_str("}\n");
    krate.write("src/main.rs", &main);
    let text = krate.run_panic_free(&[]);
    let (laws, models, updates) = tally(&text, |f| match f {
        ["model", _, _] => true,
        _ => panic!("{f:?}"),
    });
    let thetas = 3 + 9;
    assert_eq!(laws, 2 * thetas * 5 * 4);
    assert_eq!(models, 2 * thetas * 5 * 4);
    assert_eq!(updates, 2 * 4);
}

/// The counts of the scratch program's `law`, other and `update` lines:
/// every law's input finite within the supply, every update's θ within its
/// domain, and `other` true of every other line.
fn tally(text: &str, other: impl Fn(&[&str]) -> bool) -> (usize, usize, usize) {
    let (mut laws, mut others, mut updates) = (0, 0, 0);
    for line in text.lines() {
        let f: Vec<&str> = line.split(' ').collect();
        match f[..] {
            ["law", _, u] => {
                let u: f64 = u.parse().unwrap();
                assert!(u.is_finite() && (-24.0..=24.0).contains(&u), "{line}");
                laws += 1;
            }
            ["update", _, inside, _] => {
                assert_eq!(inside, "true", "θ left its domain: {line}");
                updates += 1;
            }
            _ => {
                assert!(other(&f), "{line}");
                others += 1;
            }
        }
    }
    (laws, others, updates)
}
