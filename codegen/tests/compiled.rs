//! The emitted code compiles as a `#![no_std]`, `#![forbid(unsafe_code)]`
//! crate against `reldesign-runtime`, passes clippy with the panic lints
//! denied, and evaluates like the designer's tape: to 1e-12 relative in f64
//! and 1e-5 in f32.
//!
//! The check crate is the scratch crate `target/codegen-check/`
//! (`support::ScratchCrate`, built in the scratch crates' shared target dir,
//! reused across runs).

use std::collections::HashMap;
use std::fmt::Write as _;

use support::{assert_close, example_path, ScratchCrate, Tol};

use designer::description::parse_file;
use designer::design::Linearization;
use designer::model::Model;
use designer::sym::{Graph, Id, Tape};
use reldesign_build::{emit_function, emit_params, Float, FunctionSpec, Param};

/// One function to emit, with the reference points it is evaluated at.
struct Case {
    graph: Graph,
    params: Vec<(String, Id, f64)>,
    name: &'static str,
    inputs: Vec<(&'static str, Id)>,
    outputs: Vec<(&'static str, Id, &'static str)>,
    named: Vec<(&'static str, Id)>,
    /// (output, symbol standing for it in later outputs)
    output_symbols: Vec<(&'static str, Id)>,
    points: Vec<Vec<f64>>,
}

impl Case {
    fn params(&self) -> Vec<Param<'_>> {
        self.params
            .iter()
            .map(|(n, id, v)| Param::from((n.as_str(), *id, *v)))
            .collect()
    }

    fn code(&self, float: Float) -> (String, String) {
        let spec = FunctionSpec {
            name: self.name,
            doc: "Test function.",
            inputs: self.inputs.clone(),
            outputs: self.outputs.clone(),
            named: self.named.clone(),
            output_symbols: self.output_symbols.clone(),
            float,
        };
        let params = self.params();
        (
            emit_params(&self.graph, &params, float).unwrap(),
            emit_function(&self.graph, &spec, &params).unwrap(),
        )
    }

    /// Reference values by the designer's tape, parameters bound to values.
    fn reference(&mut self) -> Vec<Vec<f64>> {
        let map: HashMap<Id, Id> = self
            .params
            .iter()
            .map(|(_, id, v)| (*id, self.graph.constant(*v)))
            .collect();
        // outputs in order; an output's symbol stands for its value after it
        let mut map = map;
        let mut bound = Vec::new();
        for &(name, root, _) in &self.outputs {
            let b = self.graph.substitute(root, &map);
            if let Some(&(_, sym)) = self.output_symbols.iter().find(|o| o.0 == name) {
                map.insert(sym, b);
            }
            bound.push(b);
        }
        let roots = &bound;
        let inputs: Vec<Id> = self.inputs.iter().map(|i| i.1).collect();
        let tape = Tape::compile(&self.graph, &inputs, &bound).unwrap();
        self.points
            .iter()
            .map(|p| {
                let mut out = vec![0.0; roots.len()];
                tape.eval(p, &mut tape.scratch(), &mut out);
                out
            })
            .collect()
    }
}

/// Expressions exercising every node kind and printing rule.
fn synthetic() -> Case {
    let mut g = Graph::new();
    let (x, y, w) = (g.symbol("x"), g.symbol("y"), g.symbol("w"));
    let (p, q) = (g.symbol("P"), g.symbol("q_gain"));
    // e1 = select(x − 0.3, P·ln y, q·√w) + min(x, y) − max(w, 2)
    let c = g.constant(-0.3);
    let cond = g.add(x, c);
    let ly = g.ln(y);
    let a = g.mul(p, ly);
    let sw = g.sqrt(w);
    let b = g.mul(q, sw);
    let sel = g.select(cond, a, b);
    let mn = g.min(x, y);
    let two = g.constant(2.0);
    let mx = g.max(w, two);
    let e1 = g.sum(&[sel, mn]);
    let e1 = g.sub(e1, mx);
    // e2 = sign(x − 0.5)·y^1.7/(1 + x²) − 3·coth(w) + sign(y − x)
    let half = g.constant(-0.5);
    let xm = g.add(x, half);
    let sg = g.sign(xm);
    let e17 = g.constant(1.7);
    let yp = g.pow(y, e17);
    let x2 = g.powi(x, 2);
    let one = g.one();
    let den = g.add(one, x2);
    let num = g.mul(sg, yp);
    let frac = g.div(num, den);
    let ct = g.coth(w);
    let ct3 = g.scale(3.0, ct);
    let dyx = g.sub(y, x);
    let sg2 = g.sign(dyx);
    let e2 = g.sub(frac, ct3);
    let e2 = g.add(e2, sg2);
    // e3 = (x+y)³ − (x+y)⁻² + e^(−x)·tanh y − |x − w| + y⁵ + x^(−½) + x^y + P/(q·x) − y⁻⁷ + w^−1.5
    let s = g.add(x, y);
    let s3 = g.powi(s, 3);
    let sm2 = g.powi(s, -2);
    let nx = g.neg(x);
    let ex = g.exp(nx);
    let th = g.tanh(y);
    let et = g.mul(ex, th);
    let xw = g.sub(x, w);
    let ab = g.abs(xw);
    let y5 = g.powi(y, 5);
    let mh = g.constant(-0.5);
    let xmh = g.pow(x, mh);
    let xy = g.pow(x, y);
    let qx = g.mul(q, x);
    let pqx = g.div(p, qx);
    let ym7 = g.powi(y, -7);
    let m15 = g.constant(-1.5);
    let wm15 = g.pow(w, m15);
    let t1 = g.sub(s3, sm2);
    let t2 = g.sub(et, ab);
    let t3 = g.sub(pqx, ym7);
    let e3 = g.sum(&[t1, t2, y5, xmh, xy, t3, wm15]);
    // e4 = e1² + y (reuses the output e1), e5 = −x − y − 1 (all terms negative)
    let e1sq = g.powi(e1, 2);
    let e4 = g.add(e1sq, y);
    let m1 = g.constant(-1.0);
    let ny = g.neg(y);
    let e5 = g.sum(&[nx, ny, m1]);
    // e6 = e1·y + x through the symbol standing for the output e1
    let e1_value = g.symbol("e1_value");
    let e1y = g.mul(e1_value, y);
    let e6 = g.add(e1y, x);
    let points = [
        [0.7, 1.3, 2.5],
        [0.2, 0.9, 1.1],
        [0.5, 2.0, 3.0], // sign(x − 0.5) = 0
        [1.5, 1.5, 0.4], // sign(y − x) = 0, select boundary
        [0.3, 0.6, 2.0], // select at c = 0
    ];
    Case {
        graph: g,
        params: vec![("P".into(), p, 1.25), ("q_gain".into(), q, -0.8)],
        name: "synthetic",
        inputs: vec![("x", x), ("y", y), ("w", w)],
        outputs: vec![
            ("e1", e1, "select, min, max"),
            ("e2", e2, "sign, powf, coth, division"),
            ("e3", e3, "powers, exp, tanh, abs"),
            ("e4", e4, "reuses e1"),
            ("e5", e5, "negative terms only"),
            ("same_x", x, "an input"),
            ("e6", e6, "uses the output e1 by its symbol"),
        ],
        named: vec![("sum_xy", s)],
        output_symbols: vec![("e1", e1_value)],
        points: points.iter().map(|p| p.to_vec()).collect(),
    }
}

/// α, β of the perfect-tracking valve.
fn valve_law() -> Case {
    let path = example_path("perfect-tracking-valve.toml");
    let mut m = Model::build(&parse_file(&path).unwrap());
    let lin = Linearization::derive(&mut m).unwrap();
    let s = m.states.clone();
    let points = (0..8)
        .map(|k| {
            let f = (k as f64 + 0.5) / 8.0;
            vec![1e-3 * (0.05 + 0.9 * f), (3.7 * f).sin(), 2e-6 + 1.5e-5 * f]
        })
        .collect();
    Case {
        params: m
            .params
            .iter()
            .map(|(n, id, v)| (n.to_owned(), id, v))
            .collect(),
        graph: m.graph,
        name: "linearizing_law",
        inputs: vec![("z", s[0]), ("v", s[1]), ("phi", s[2])],
        outputs: vec![
            ("alpha", lin.alpha, "(32) α(x)"),
            ("beta", lin.beta, "(32) β(x)"),
        ],
        named: vec![("r_gap", m.r_gap), ("r_gap_dz", m.r_gap_dz)],
        output_symbols: vec![],
        points,
    }
}

/// Writes the check crate's sources: lib = params + functions in `double`
/// and `single`; main = prints every output at every point, one line each.
fn write_crate(krate: &ScratchCrate, cases: &[Case]) {
    let mut lib = String::from(
        "//! Emitted by codegen/tests/compiled.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n",
    );
    for (module, float) in [("double", Float::F64), ("single", Float::F32)] {
        for case in cases {
            let (params, function) = case.code(float);
            writeln!(
                lib,
                "\npub mod {module}_{} {{\n{params}\n{function}}}",
                case.name
            )
            .unwrap();
        }
    }
    krate.write("src/lib.rs", &lib);
    let mut main = String::from("fn main() {\n");
    for module in ["double", "single"] {
        for case in cases {
            for p in &case.points {
                let args: Vec<String> = p.iter().map(|v| format!("{v:?}")).collect();
                let fields: Vec<String> =
                    case.outputs.iter().map(|o| format!("o.{}", o.0)).collect();
                writeln!(
                    main,
                    "    let o = codegen_check::{module}_{}::{}({});\n    println!(\"{}\", {});",
                    case.name,
                    case.name,
                    args.join(", "),
                    vec!["{:?}"; fields.len()].join(" "),
                    fields.join(", ")
                )
                .unwrap();
            }
        }
    }
    main.push_str("}\n");
    krate.write("src/main.rs", &main);
}

#[test]
fn emitted_code_compiles_passes_clippy_and_matches_the_tape() {
    let mut cases = [synthetic(), valve_law()];
    let krate = ScratchCrate::new("codegen-check");
    write_crate(&krate, &cases);
    let text = krate.run_panic_free(&[]);
    let mut lines = text.lines();
    for (float, tol) in [("f64", 1e-12), ("f32", 1e-5)] {
        for case in &mut cases {
            let reference = case.reference();
            for (p, want) in case.points.iter().zip(&reference) {
                let line = lines.next().expect("one line per point");
                let got: Vec<f64> = line.split(' ').map(|v| v.parse().unwrap()).collect();
                assert_eq!(got.len(), want.len());
                for ((&g, &w), o) in got.iter().zip(want).zip(&case.outputs) {
                    let what = format!("{float} {}::{} at {p:?} (emitted, tape)", case.name, o.0);
                    assert_close(g, w, Tol::rel(tol), what);
                }
            }
        }
    }
    assert!(lines.next().is_none());
}
