//! The emitted controller: determinism, one changed line per changed
//! parameter, compilation as a `#![no_std]` crate under clippy's panic lints
//! (f64 and f32), the law against the designer's tape, and finite saturated
//! outputs at φ = 0, z = 0 and NaN inputs.
//!
//! The check crate is the scratch crate `target/codegen-check-controller/`
//! (`support::ScratchCrate`, built in the scratch crates' shared target dir).

use std::collections::HashMap;
use std::fmt::Write as _;

use designer::description::{parse_str, Gains, Operation};
use designer::design::{
    check_feasibility, gains, ControllerDesign, ControllerSpec, DesignedOperation, Flat, LawDesign,
    Linearization, Polynomial, Reference, Segments,
};
use designer::model::Model;
use designer::sym::{Id, Tape};
use reldesign_build::{emit_controller, params_macro, ControllerInput, Float, Header};
use support::{assert_close, example_path, ScratchCrate, Tol};

const VALVE: &str = "perfect-tracking-valve.toml";
const T0: f64 = 1e-3;
const TF: f64 = 6e-3;

fn valve_text() -> String {
    std::fs::read_to_string(example_path(VALVE)).unwrap()
}

/// The quintic z0 → zf of (52)–(53) as one exact table segment.
fn quintic_reference(z0: f64, zf: f64) -> (Polynomial, Segments) {
    let p = Polynomial {
        z0,
        zf,
        t0: T0,
        tf: TF,
    };
    let h = TF - T0;
    // s'''(0) = s'''(1) = 60: the jerk at both ends of the quintic
    let jerk = 60.0 * (zf - z0) / (h * h * h);
    let at_t0 = Flat {
        z: z0,
        v: 0.0,
        a: 0.0,
        jerk,
    };
    let seg = Segments::segment(T0, h, at_t0, 0.0, jerk);
    let s = Segments {
        segments: vec![seg],
        end: TF,
        z_start: z0,
        z_end: zf,
    };
    (p, s)
}

struct Valve {
    model: Model,
    lin: Linearization,
    segments: Segments,
    opening: Segments,
    polynomial: Polynomial,
    text: String,
}

fn valve(text: &str) -> Valve {
    let d = parse_str(text, VALVE).unwrap_or_else(|e| panic!("{e}"));
    let mut model = Model::build(&d);
    let lin = Linearization::derive(&mut model).unwrap();
    let (z_min, z_max) = (d.mechanics.z_min, d.mechanics.z_max);
    let (polynomial, segments) = quintic_reference(z_max, z_min);
    let (_, opening) = quintic_reference(z_min, z_max);
    Valve {
        model,
        lin,
        segments,
        opening,
        polynomial,
        text: text.to_owned(),
    }
}

fn emit(v: &Valve, floats: &[Float]) -> String {
    emit_ops(v, floats, false)
}

/// The design of the closing quintic, with the opening one too if `both`.
fn design(v: &Valve, both: bool) -> ControllerDesign {
    let mut model = v.model.clone();
    let d = &v.model.description;
    let (z_min, z_max) = (d.mechanics.z_min, d.mechanics.z_max);
    let bounds = (d.supply.u_min, d.supply.u_max);
    let mut operation = |operation, z0, zf, table: &Segments| {
        let (reference, _) = quintic_reference(z0, zf);
        DesignedOperation {
            operation,
            z0,
            zf,
            feasibility: check_feasibility(&mut model, &v.lin, &reference, bounds, 100),
            table: table.clone(),
            optimal: None,
            takeoff: None,
        }
    };
    let mut operations = vec![operation(Operation::Closing, z_max, z_min, &v.segments)];
    if both {
        operations.push(operation(Operation::Opening, z_min, z_max, &v.opening));
    }
    let spec = ControllerSpec {
        law: LawDesign::FeedbackLinearization {
            gains: gains(&Gains::SettlingTime(1e-3)),
        },
        sample_period: 1e-5,
        u_min: d.supply.u_min,
        u_max: d.supply.u_max,
        takeoff: T0,
        landing: TF,
        creep_speed: None,
        landed_band: None,
        estimated: false,
    };
    ControllerDesign::decide(&v.model, v.lin.clone(), &spec, operations)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The emitted file as `reldesign build` composes it: header, `params!`, the
/// float modules.
fn emit_ops(v: &Valve, floats: &[Float], both: bool) -> String {
    let design = design(v, both);
    let input = ControllerInput {
        model: &v.model,
        design: &design,
        floats: floats.to_vec(),
        calibration: None,
    };
    let header = Header {
        what: "controller",
        generator_version: env!("CARGO_PKG_VERSION"),
        source_file: "perfect-tracking-valve.toml",
        source_text: &v.text,
    };
    format!(
        "{}\n{}\n{}",
        header.text(),
        params_macro(&v.model).unwrap_or_else(|e| panic!("{e}")),
        emit_controller(&input).unwrap_or_else(|e| panic!("{e}"))
    )
}

#[test]
fn the_table_reproduces_the_quintic() {
    let v = valve(&valve_text());
    for k in 0..=50 {
        let t = T0 + (TF - T0) * k as f64 / 50.0;
        let seg = &v.segments.segments[0];
        let got = Segments::eval_segment(seg, t - seg[0]);
        let want = v.polynomial.at(t);
        assert_close(got.z, want.z, Tol::abs(1e-15), format!("z at {t}"));
        assert_close(got.v, want.v, Tol::abs(1e-12), format!("v at {t}"));
        assert_close(got.a, want.a, Tol::abs(1e-8 * 240.0), format!("a at {t}"));
    }
}

#[test]
fn output_is_byte_identical_across_runs() {
    let text = valve_text();
    let floats = [Float::F64, Float::F32];
    assert_eq!(emit(&valve(&text), &floats), emit(&valve(&text), &floats));
}

#[test]
fn one_parameter_change_is_one_params_line_and_the_hash_line() {
    let text = valve_text();
    let changed = text.replacen("resistance = 75.0", "resistance = 80.5", 1);
    assert_ne!(text, changed);
    let floats = [Float::F64, Float::F32];
    let (a, b) = (
        emit(&valve(&text), &floats),
        emit(&valve(&changed), &floats),
    );
    let diff = support::changed_lines(&a, &b);
    assert_eq!(diff.len(), 2, "{diff:#?}");
    assert!(diff[0].0.starts_with("// source sha256: "), "{diff:?}");
    assert_eq!(
        diff[1],
        (
            "        pub const R: $f = 75.0;",
            "        pub const R: $f = 80.5;"
        )
    );
}

#[test]
fn header_and_sections_are_there() {
    let text = valve_text();
    let code = emit(&valve(&text), &[Float::F64, Float::F32]);
    let hash = reldesign_build::sha256_hex(&text);
    assert!(code.starts_with("// @generated by reldesign-build "));
    assert!(code.contains("DO NOT EDIT"));
    assert!(code.contains(&format!("// source sha256: {hash}\n")));
    assert!(code.contains("macro_rules! params"));
    // the law's functions once, in `law!`, whatever the floats
    assert_eq!(code.matches("macro_rules! law {").count(), 1);
    assert_eq!(code.matches("pub fn law_terms(").count(), 1);
    for needle in [
        "law!(f64);",
        "law!(f32);",
        "pub mod f64 {",
        "pub mod f32 {",
        "pub fn law(",
        "pub fn guarded_law(",
        "pub const REFERENCE_CLOSING: [[f64; 7]; 1]",
        "pub const REFERENCE_CLOSING: [[f32; 7]; 1]",
        "pub type Controller = control::SoftLanding<Design, f64>;",
        "impl control::Law<f32> for Design {",
        "// [PT 50] u = α + β·w",
        // physical constants and the model's subexpressions by name
        "pub const MU0: $f = 4e-7 * ::core::$f::consts::PI;",
        "let z_reg = z + Z_EPS;",
        "let fringe_den = ",
        "let f_net = f_mag - f_passive;",
        // the end stops by name
        "z0: Z_MAX,",
        "zf: Z_MIN,",
    ] {
        assert!(code.contains(needle), "missing {needle}");
    }
    for folded in ["795774.7", "397887.3", "1e-9_f"] {
        assert!(
            !code.contains(folded),
            "a folded physical constant: {folded}"
        );
    }
    for forbidden in [
        ".unwrap()",
        ".expect(",
        "panic!",
        " as f",
        " as usize",
        "unsafe",
    ] {
        assert!(
            !code.contains(forbidden),
            "emitted code contains {forbidden}"
        );
    }
}

/// States x = [z, v, φ] in D₀⁺ and references [z_r, v_r, a_r, j_r].
fn law_points() -> Vec<[f64; 7]> {
    (0..8)
        .map(|k| {
            let f = (k as f64 + 0.5) / 8.0;
            [
                1e-3 * (0.05 + 0.9 * f),
                0.3 * (3.7 * f).sin(),
                2e-6 + 1.5e-5 * f,
                1e-3 * (0.9 - 0.8 * f),
                -0.2 * f,
                50.0 * (2.1 * f).cos(),
                -3e5 * (1.0 - 2.0 * f),
            ]
        })
        .collect()
}

/// α + β·(K·(ξ_r − T(x)) + j_r) by the designer's tape, parameters bound.
fn law_by_tape(v: &mut Valve, k: [f64; 3], points: &[[f64; 7]]) -> Vec<f64> {
    let g = &mut v.model.graph;
    let refs: Vec<Id> = ["t_zr", "t_vr", "t_ar", "t_jr"]
        .iter()
        .map(|n| g.symbol(n))
        .collect();
    let mut terms = Vec::new();
    for i in 0..3 {
        let e = g.sub(refs[i], v.lin.transform[i]);
        terms.push(g.scale(k[i], e));
    }
    terms.push(refs[3]);
    let w = g.sum(&terms);
    let bw = g.mul(v.lin.beta, w);
    let u = g.add(v.lin.alpha, bw);
    let map: HashMap<Id, Id> = v
        .model
        .params
        .iter()
        .map(|(_, id, val)| (id, g.constant(val)))
        .collect();
    let bound = g.substitute_all(&[u], &map);
    let s = &v.model.states;
    let inputs = [s[0], s[1], s[2], refs[0], refs[1], refs[2], refs[3]];
    let tape = Tape::compile(g, &inputs, &bound).unwrap();
    points
        .iter()
        .map(|p| {
            let mut out = [0.0];
            tape.eval(p, &mut tape.scratch(), &mut out);
            out[0]
        })
        .collect()
}

/// (t, z, v, φ) of the robustness checks: φ = 0, z = 0, NaN, ±∞, every stage.
fn edge_points() -> Vec<[f64; 4]> {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let mut pts = Vec::new();
    for t in [0.0, 0.5e-3, 2e-3, 4e-3, 7e-3, nan] {
        for (z, v, phi) in [
            (1e-3, 0.0, 0.0),
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 1e-5),
            (0.0, 0.0, -1e-5),
            (5e-4, -0.1, 1e-5),
            (nan, 0.0, 1e-5),
            (5e-4, nan, 1e-5),
            (5e-4, 0.0, nan),
            (nan, nan, nan),
            (inf, -inf, inf),
            (-1e-4, 0.0, 1e-5),
        ] {
            pts.push([t, z, v, phi]);
        }
    }
    pts
}

#[test]
fn emitted_controller_compiles_passes_clippy_and_matches_the_tape() {
    let mut v = valve(&valve_text());
    let code = emit_ops(&v, &[Float::F64, Float::F32], true);
    let krate = ScratchCrate::new("codegen-check-controller");
    krate.write(
        "src/lib.rs",
        "//! Emitted by codegen/tests/controller.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n\npub mod valve;\n",
    );
    krate.write("src/valve.rs", &code);

    let points = law_points();
    let edges = edge_points();
    let mut main = String::from("use codegen_check_controller::valve;\n\nfn main() {\n");
    for module in ["f64", "f32"] {
        for p in &points {
            let a: Vec<String> = p.iter().map(|x| format!("{x:?}")).collect();
            writeln!(
                main,
                "    println!(\"{{:?}}\", valve::{module}::law({}));",
                a.join(", ")
            )
            .unwrap();
        }
        writeln!(
            main,
            "    let mut c = valve::{module}::Controller::new(valve::{module}::Operation::Closing);\n    c.start(0.0);"
        )
        .unwrap();
        for e in &edges {
            let a: Vec<String> = e
                .iter()
                .map(|x| format!("{module}::from({}f32)", x))
                .collect();
            let a: Vec<String> = a
                .into_iter()
                .map(|s| {
                    s.replace("NaNf32", "f32::NAN")
                        .replace("-inff32", "f32::NEG_INFINITY")
                        .replace("inff32", "f32::INFINITY")
                })
                .collect();
            writeln!(main, "    println!(\"{{:?}}\", c.step({}));", a.join(", ")).unwrap();
        }
        for k in 0..=20 {
            let t = 7e-3 * k as f64 / 20.0;
            writeln!(main, "    println!(\"{{:?}}\", c.reference({t:?}));").unwrap();
        }
    }
    main.push_str("}\n");
    krate.write("src/main.rs", &main);

    let text = krate.run_panic_free(&[]);
    let mut lines = text.lines();

    let k = gains(&Gains::SettlingTime(1e-3));
    let want = law_by_tape(&mut v, k, &points);
    for (float, tol) in [("f64", 1e-12), ("f32", 2e-3)] {
        for (p, w) in points.iter().zip(&want) {
            let got: f64 = lines.next().unwrap().parse().unwrap();
            // relative to the size of the terms, at least 1 (u = α + β·w may cancel)
            let what = format!("{float} law at {p:?} (emitted, tape)");
            assert_close(got, *w, Tol::rel(tol).or_abs(tol), what);
        }
        for e in &edges {
            let got: f64 = lines.next().unwrap().parse().unwrap();
            assert!(
                got.is_finite() && (-24.0..=24.0).contains(&got),
                "{float} step at {e:?} = {got}"
            );
            let [t, z, _, phi] = *e;
            if t < T0 && phi == 0.0 && z.is_finite() {
                assert_eq!(got, 24.0, "{float}: the guard at φ = 0 commands u_max");
            }
            if t > TF && z == 0.0 && phi != 0.0 && phi.is_finite() {
                assert_eq!(
                    got,
                    24.0 * phi.signum(),
                    "{float}: expert rule [SM 43] at z_min"
                );
            }
        }
        for kk in 0..=20 {
            let t = 7e-3 * kk as f64 / 20.0;
            let line = lines.next().unwrap();
            let got: Vec<f64> = line
                .trim_matches(|c| c == '[' || c == ']')
                .split(", ")
                .map(|x| x.parse().unwrap())
                .collect();
            let mut r = v.polynomial.at(t);
            if t > TF {
                // after t_f the reference lies PRESS = 1e-6 of the stroke beyond the
                // stop and creeps on at CREEP = 2.5e-3 stroke per (t_f − t₀)
                let stroke = v.polynomial.zf - v.polynomial.z0;
                let creep = 2.5e-3 / (TF - T0);
                r.z += stroke * (1e-6 + creep * (t - TF));
                r.v = stroke * creep;
            }
            let ztol = if float == "f64" { 1e-15 } else { 1e-9 };
            assert_close(got[0], r.z, Tol::abs(ztol), format!("{float} z_r({t})"));
            assert_close(
                got[1],
                r.v,
                Tol::abs(1e3 * ztol),
                format!("{float} v_r({t})"),
            );
        }
    }
    assert!(lines.next().is_none());
}

/// `controller.compensate_resistance`: the emitted controller's docs tell
/// firmware to pass u through the runtime's correction; without the key
/// they do not.
#[test]
fn the_resistance_compensation_is_documented_where_set() {
    let path = support::root().join("tests/data/sensorless-ja-valve.toml");
    let text = std::fs::read_to_string(path).unwrap();
    for (on, text) in [
        (true, text.clone()),
        (false, text.replacen("compensate_resistance = true", "", 1)),
    ] {
        let d = parse_str(&text, "sensorless-ja-valve.toml").unwrap_or_else(|e| panic!("{e}"));
        let design = designer::design::Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
        let code = reldesign_build::emit(&design).unwrap_or_else(|e| panic!("{e}"));
        let says = code.contains("reldesign_runtime::resistance::compensate_resistance(u, r̂, R,");
        assert_eq!(says, on, "compensate_resistance = {on}");
    }
}
