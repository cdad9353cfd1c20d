//! Emitter properties that need no compiler: byte-identical output across
//! independent builds, one changed line per changed parameter, the shape of
//! the emitted arithmetic, and refused inputs.

use designer::description::parse_str;
use designer::design::Linearization;
use designer::model::Model;
use designer::sym::{Graph, Id};
use reldesign_build::{emit_function, emit_params, EmitError, Float, FunctionSpec, Param};
use support::example_path;

const VALVE: &str = "perfect-tracking-valve.toml";

fn valve_text() -> String {
    std::fs::read_to_string(example_path(VALVE)).unwrap()
}

fn valve(text: &str) -> Model {
    Model::build(&parse_str(text, VALVE).unwrap_or_else(|e| panic!("{e}")))
}

/// α, β of the valve as emitted code: (params block, function).
fn alpha_beta_code(text: &str, float: Float) -> (String, String) {
    let mut m = valve(text);
    let lin = Linearization::derive(&mut m).unwrap();
    let params: Vec<_> = m.params.iter().map(Param::from).collect();
    let s = &m.states;
    let spec = FunctionSpec {
        name: "linearizing_law",
        doc: "Exact feedback linearization of the valve for y = z.",
        inputs: vec![("z", s[0]), ("v", s[1]), ("phi", s[2])],
        outputs: vec![
            ("alpha", lin.alpha, "(32) α(x)"),
            ("beta", lin.beta, "(32) β(x)"),
        ],
        named: vec![("r_gap", m.r_gap), ("r_gap_dz", m.r_gap_dz)],
        output_symbols: vec![],
        float,
    };
    let p = emit_params(&m.graph, &params, float).unwrap();
    let f = emit_function(&m.graph, &spec, &params).unwrap();
    (p, f)
}

#[test]
fn output_is_byte_identical_across_independent_builds() {
    let text = valve_text();
    for float in [Float::F64, Float::F32] {
        let first = alpha_beta_code(&text, float);
        let second = alpha_beta_code(&text, float);
        assert_eq!(first, second, "{float:?}");
    }
}

#[test]
fn one_parameter_change_is_one_changed_line() {
    let text = valve_text();
    let changed = text.replacen("resistance = 75.0", "resistance = 80.5", 1);
    assert_ne!(text, changed);
    for float in [Float::F64, Float::F32] {
        let (p0, f0) = alpha_beta_code(&text, float);
        let (p1, f1) = alpha_beta_code(&changed, float);
        assert_eq!(f0, f1, "parameters must stay symbolic in the function");
        let diff = support::changed_lines(&p0, &p1);
        let ty = if float == Float::F64 { "f64" } else { "f32" };
        assert_eq!(
            diff,
            [(
                format!("pub const R: {ty} = 75.0;").as_str(),
                format!("pub const R: {ty} = 80.5;").as_str()
            )]
        );
    }
}

#[test]
fn emitted_function_reads_like_hand_written_code() {
    let (params, f) = alpha_beta_code(&valve_text(), Float::F64);
    assert!(params.contains("pub const K_E: f64 = 1500.0;\n"));
    assert!(params.contains("pub const F0: f64 = -0.75;\n"));
    assert!(params.contains("pub const PHI_SAT: f64 = 2.5e-5;\n"));
    assert!(
        f.contains("pub fn linearizing_law(z: f64, v: f64, phi: f64) -> LinearizingLawOutput {")
    );
    assert!(f.contains("    // (32) α(x)\n    let alpha = "));
    assert!(f.contains("    // (32) β(x)\n    let beta = "));
    assert!(f.contains("    /// (32) α(x)\n    pub alpha: f64,"));
    assert!(f.contains("let r_gap_dz = "), "caller-named subexpression");
    assert!(f.contains("let phi_sq = phi * phi;"));
    assert!(f.contains("let inv_m = 1.0_f64 / M;"));
    assert!(f.contains("Real::ln("));
    // μ0 and Z_EPS by name, folded by the compiler, not by the generator
    assert!(f.contains("const MU0: f64 = 1.2566370614359173e-6;"), "{f}");
    assert!(f.contains("1.0_f64 / MU0 * "), "{f}");
    assert!(f.contains(" + Z_EPS;"), "{f}");
    assert!(!f.contains("795774.7") && !f.contains("397887.3"), "{f}");
    let body: String = f[f.find("pub fn").unwrap()..]
        .lines()
        .filter(|l| !l.trim_start().starts_with("///"))
        .collect();
    for banned in ["unwrap", "expect", " as ", "[", "panic", "unsafe", "f32"] {
        assert!(!body.contains(banned), "`{banned}` in emitted code:\n{f}");
    }
    let (_, f32_code) = alpha_beta_code(&valve_text(), Float::F32);
    assert!(f32_code.contains("let inv_m = 1.0_f32 / M;"));
    assert!(!f32_code.contains("f64"));
}

/// x, y and the emitted text of `outputs` as functions of them.
fn emit_xy(build: impl FnOnce(&mut Graph, Id, Id) -> Vec<Id>) -> Result<String, EmitError> {
    let mut g = Graph::new();
    let (x, y) = (g.symbol("x"), g.symbol("y"));
    let k = g.symbol("k");
    let outs = build(&mut g, x, y);
    let names = ["a", "b", "c", "d", "e", "f"];
    let spec = FunctionSpec {
        name: "f",
        doc: "",
        inputs: vec![("x", x), ("y", y)],
        outputs: outs.iter().zip(names).map(|(&o, n)| (n, o, "")).collect(),
        named: vec![],
        output_symbols: vec![],
        float: Float::F64,
    };
    emit_function(&g, &spec, &[("k", k, 2.0).into()])
}

#[test]
fn arithmetic_is_written_as_a_person_would() {
    let f = emit_xy(|g, x, y| {
        let rx = g.recip(x);
        let d = g.sub(x, y);
        let k = g.find_symbol("k").unwrap();
        let ky = g.mul(k, y);
        let q = g.div(ky, x);
        let x3 = g.powi(x, 3);
        let x4 = g.powi(x, 4);
        let zero = g.zero();
        let s = g.sign(x);
        let m = g.min(x, zero);
        let sel = g.select(d, s, m);
        let half = g.constant(-0.5);
        let xh = g.pow(x, half);
        let sum = g.sum(&[x4, xh, sel]);
        vec![rx, d, q, x3, sum]
    })
    .unwrap();
    assert!(f.contains("let a = 1.0_f64 / x;"), "{f}");
    assert!(f.contains("let b = x - y;"), "{f}");
    assert!(
        f.contains("let c = K * y * a;"),
        "outputs are reused by name, parameters first: {f}"
    );
    assert!(f.contains("let d = x * x * x;"), "{f}");
    assert!(f.contains("Real::powi(x, 4)"), "{f}");
    assert!(f.contains("1.0_f64 / Real::sqrt(x)"), "{f}");
    assert!(
        f.contains(
            "let sel = if b >= 0.0_f64 { Real::signum0(x) } else { Real::min(x, 0.0_f64) };"
        ),
        "{f}"
    );
    assert!(
        !f.contains("use reldesign_runtime")
            || f.contains("    use reldesign_runtime::math::Real;\n")
    );
}

#[test]
fn parameter_factors_lead_and_inverse_powers_reuse_lets() {
    let f = emit_xy(|g, x, y| {
        let k = g.find_symbol("k").unwrap();
        let rx = g.recip(x);
        let rk = g.recip(k);
        let xm2 = g.powi(x, -2);
        let xm3 = g.powi(x, -3);
        // 3·y·k / (k·x² ... ): k⁻¹·y·x⁻² and 2·k·y·x⁻³
        let a = g.product(&[rk, y, xm2]);
        let two = g.constant(2.0);
        let b = g.product(&[two, k, y, xm3]);
        let e = g.add(rx, y); // x⁻¹ used twice: it gets its `let` first
        vec![rx, xm2, a, b, e]
    })
    .unwrap();
    assert!(f.contains("let a = 1.0_f64 / x;"), "{f}");
    assert!(f.contains("let b = a * a;"), "x⁻² through x⁻¹: {f}");
    assert!(
        f.contains("let c = 1.0_f64 / K * y * b;"),
        "parameters first: {f}"
    );
    assert!(f.contains("let d = 2.0_f64 * K * y * (b * a);"), "{f}");
}

#[test]
fn outputs_build_on_earlier_outputs_through_their_symbols() {
    let mut g = Graph::new();
    let (x, y) = (g.symbol("x"), g.symbol("y"));
    let (sa, sb) = (g.symbol("a_value"), g.symbol("b_value"));
    let a = g.mul(x, y);
    let b = g.add(x, y);
    let ab = g.mul(sa, sb);
    let c = g.add(ab, x);
    let spec = |outputs: Vec<(&'static str, Id, &'static str)>| FunctionSpec {
        name: "f",
        doc: "",
        inputs: vec![("x", x), ("y", y)],
        outputs,
        named: vec![],
        output_symbols: vec![("a", sa), ("b", sb)],
        float: Float::F64,
    };
    let f = emit_function(
        &g,
        &spec(vec![("a", a, ""), ("b", b, ""), ("c", c, "")]),
        &[],
    )
    .unwrap();
    assert!(f.contains("let a = x * y;"), "{f}");
    assert!(f.contains("let b = x + y;"), "{f}");
    assert!(
        f.contains("let c = x + a * b;") || f.contains("let c = a * b + x;"),
        "{f}"
    );
    // c before a: its symbol is used before the output is computed
    let err = emit_function(
        &g,
        &spec(vec![("c", c, ""), ("a", a, ""), ("b", b, "")]),
        &[],
    )
    .unwrap_err();
    assert_eq!(err, EmitError::OutputUsedEarly("a".into()));
}

#[test]
fn unused_inputs_are_underscored_and_outputs_may_be_inputs() {
    let f = emit_xy(|_, x, _| vec![x]).unwrap();
    assert!(f.contains("pub fn f(x: f64, _y: f64) -> FOutput {"), "{f}");
    assert!(f.contains("let a = x;"), "{f}");
    assert!(
        !f.contains("use reldesign_runtime"),
        "no math, no import:\n{f}"
    );
}

#[test]
fn bad_requests_are_refused_with_the_name() {
    let err = emit_xy(|g, x, _| {
        let free = g.symbol("free");
        vec![g.add(x, free)]
    })
    .unwrap_err();
    assert_eq!(err, EmitError::UnboundSymbol("free".into()));

    let mut g = Graph::new();
    let x = g.symbol("x");
    for (input, output) in [("X", "a"), ("x", "fn"), ("x", "x"), ("x", "a b")] {
        let spec = FunctionSpec {
            name: "f",
            doc: "",
            inputs: vec![(input, x)],
            outputs: vec![(output, x, "")],
            named: vec![],
            output_symbols: vec![],
            float: Float::F64,
        };
        let err = emit_function(&g, &spec, &[]).unwrap_err();
        assert!(
            matches!(
                err,
                EmitError::InvalidName(..) | EmitError::DuplicateName(_)
            ),
            "{err}"
        );
    }
    let (a, b) = (g.symbol("k_e"), g.symbol("K_e"));
    let err = emit_params(
        &g,
        &[("k_e", a, 1.0).into(), ("K_e", b, 2.0).into()],
        Float::F64,
    )
    .unwrap_err();
    assert_eq!(err, EmitError::DuplicateName("K_E".into()));
    let err = emit_params(&g, &[("k_e", a, 1e300).into()], Float::F32).unwrap_err();
    assert!(matches!(err, EmitError::NonFinite { .. }), "{err}");
}
