//! Property tests of the symbolic core against independent oracles:
//! - simplification, tape compilation and CSE against a direct f64 evaluation
//!   of the same random recipe (which never touches the graph);
//! - printing against parsing: the text parses back to the same node;
//! - derivatives (first and second order) against central finite differences;
//! - `factor_sums` (common factors out of sums) keeps the values of an
//!   expression and of its derivatives, where sums share the most factors.

use proptest::prelude::*;
use reldesign_sym::{Graph, Id, Scope, Tape, E};

/// A random expression in x and y, evaluated two ways: directly in f64 and
/// through the graph. Every operation is smooth and defined on all of R².
#[derive(Debug, Clone)]
enum Recipe {
    X,
    Y,
    Const(f64),
    Add(Box<Recipe>, Box<Recipe>),
    Sub(Box<Recipe>, Box<Recipe>),
    Mul(Box<Recipe>, Box<Recipe>),
    /// a / (1 + b²)
    DivSafe(Box<Recipe>, Box<Recipe>),
    /// a^n, n in -2..=4 with a^-n taken as 1/(1 + a²)^n
    Powi(Box<Recipe>, i32),
    /// sqrt(1 + a²)
    SqrtSafe(Box<Recipe>),
    /// exp(tanh(a))
    ExpTanh(Box<Recipe>),
    /// ln(1 + a²)
    LnSafe(Box<Recipe>),
    /// (1 + a²)^(real p)
    PowReal(Box<Recipe>, f64),
    /// coth(1 + a²)
    CothSafe(Box<Recipe>),
}

fn recipe() -> impl Strategy<Value = Recipe> {
    let leaf = prop_oneof![
        Just(Recipe::X),
        Just(Recipe::Y),
        (-3.0f64..3.0).prop_map(|c| Recipe::Const((c * 4.0).round() / 4.0)),
    ];
    leaf.prop_recursive(5, 40, 2, |inner| {
        let b = |r: Recipe| Box::new(r);
        prop_oneof![
            (inner.clone(), inner.clone()).prop_map(move |(a, c)| Recipe::Add(b(a), b(c))),
            (inner.clone(), inner.clone()).prop_map(move |(a, c)| Recipe::Sub(b(a), b(c))),
            (inner.clone(), inner.clone()).prop_map(move |(a, c)| Recipe::Mul(b(a), b(c))),
            (inner.clone(), inner.clone()).prop_map(move |(a, c)| Recipe::DivSafe(b(a), b(c))),
            (inner.clone(), -2i32..=4).prop_map(move |(a, n)| Recipe::Powi(b(a), n)),
            inner.clone().prop_map(move |a| Recipe::SqrtSafe(b(a))),
            inner.clone().prop_map(move |a| Recipe::ExpTanh(b(a))),
            inner.clone().prop_map(move |a| Recipe::LnSafe(b(a))),
            (inner.clone(), -1.5f64..1.5).prop_map(move |(a, p)| Recipe::PowReal(b(a), p)),
            inner.prop_map(move |a| Recipe::CothSafe(b(a))),
        ]
    })
}

fn value(r: &Recipe, x: f64, y: f64) -> f64 {
    let v = |r: &Recipe| value(r, x, y);
    match r {
        Recipe::X => x,
        Recipe::Y => y,
        Recipe::Const(c) => *c,
        Recipe::Add(a, b) => v(a) + v(b),
        Recipe::Sub(a, b) => v(a) - v(b),
        Recipe::Mul(a, b) => v(a) * v(b),
        Recipe::DivSafe(a, b) => v(a) / (1.0 + v(b) * v(b)),
        Recipe::Powi(a, n) if *n >= 0 => v(a).powi(*n),
        Recipe::Powi(a, n) => (1.0 + v(a) * v(a)).powi(*n),
        Recipe::SqrtSafe(a) => (1.0 + v(a) * v(a)).sqrt(),
        Recipe::ExpTanh(a) => v(a).tanh().exp(),
        Recipe::LnSafe(a) => (1.0 + v(a) * v(a)).ln(),
        Recipe::PowReal(a, p) => (1.0 + v(a) * v(a)).powf(*p),
        Recipe::CothSafe(a) => 1.0 / (1.0 + v(a) * v(a)).tanh(),
    }
}

fn build(g: &mut Graph, r: &Recipe) -> Id {
    g.with(|s| build_expr(s, r).id())
}

/// The recipe with the expression layer; `sq1(a)` is 1 + a².
fn build_expr<'s>(s: &'s Scope, r: &Recipe) -> E<'s> {
    let b = |r: &Recipe| build_expr(s, r);
    let sq1 = |a: &Recipe| 1.0 + b(a).powi(2);
    match r {
        Recipe::X => s.symbol("x"),
        Recipe::Y => s.symbol("y"),
        Recipe::Const(c) => s.constant(*c),
        Recipe::Add(x, y) => b(x) + b(y),
        Recipe::Sub(x, y) => b(x) - b(y),
        Recipe::Mul(x, y) => b(x) * b(y),
        Recipe::DivSafe(x, y) => b(x) / sq1(y),
        Recipe::Powi(a, n) if *n >= 0 => b(a).powi(*n),
        Recipe::Powi(a, n) => sq1(a).powi(*n),
        Recipe::SqrtSafe(a) => sq1(a).sqrt(),
        Recipe::ExpTanh(a) => b(a).tanh().exp(),
        Recipe::LnSafe(a) => sq1(a).ln(),
        Recipe::PowReal(a, p) => sq1(a).pow(*p),
        Recipe::CothSafe(a) => sq1(a).coth(),
    }
}

fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs || (a.is_nan() && b.is_nan())
}

fn eval_tape(g: &Graph, e: Id, x: f64, y: f64) -> f64 {
    let (sx, sy) = (g.find_symbol("x"), g.find_symbol("y"));
    let inputs: Vec<Id> = [sx, sy].into_iter().flatten().collect();
    let tape = Tape::compile(g, &inputs, &[e]).expect("only x and y are free");
    let vals: Vec<f64> = [sx.map(|_| x), sy.map(|_| y)]
        .into_iter()
        .flatten()
        .collect();
    let mut out = [0.0];
    tape.eval(&vals, &mut tape.scratch(), &mut out);
    out[0]
}

fn point() -> impl Strategy<Value = (f64, f64)> {
    (-1.5f64..1.5, -1.5f64..1.5)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    /// Simplification and tape compilation keep the value of the recipe.
    #[test]
    fn simplified_graph_and_tape_match_direct_evaluation(r in recipe(), (x, y) in point()) {
        let direct = value(&r, x, y);
        prop_assume!(direct.is_finite() && direct.abs() < 1e8);
        let mut g = Graph::new();
        let e = build(&mut g, &r);
        let tree = g.eval(e, &|s| if s == "x" { x } else { y });
        let tape = eval_tape(&g, e, x, y);
        prop_assert!(close(tree, direct, 1e-9, 1e-12), "tree {tree} vs direct {direct}: {}", g.display(e));
        prop_assert!(close(tape, direct, 1e-9, 1e-12), "tape {tape} vs direct {direct}");
    }

    /// The printed text of an expression and of its derivative parses back
    /// to the same node.
    #[test]
    fn printed_text_parses_back_to_the_same_node(r in recipe()) {
        let mut g = Graph::new();
        let e = build(&mut g, &r);
        let x = g.symbol("x");
        let d = g.diff(e, x);
        for node in [e, d] {
            let text = g.display(node);
            prop_assert_eq!(g.parse(&text, &[]), Ok(node), "{}", text);
        }
    }

    /// ∂/∂x and ∂/∂y against central differences of the direct evaluation.
    #[test]
    fn first_derivatives_match_central_differences(r in recipe(), (x, y) in point()) {
        let direct = value(&r, x, y);
        prop_assume!(direct.is_finite() && direct.abs() < 1e6);
        let mut g = Graph::new();
        let e = build(&mut g, &r);
        let (sx, sy) = (g.symbol("x"), g.symbol("y"));
        let h = 1e-6;
        for (var, fd) in [
            (sx, (value(&r, x + h, y) - value(&r, x - h, y)) / (2.0 * h)),
            (sy, (value(&r, x, y + h) - value(&r, x, y - h)) / (2.0 * h)),
        ] {
            let d = g.diff(e, var);
            let sym = eval_tape(&g, d, x, y);
            let scale = direct.abs().max(1.0);
            prop_assert!(close(sym, fd, 1e-5, 1e-6 * scale), "d/d{} = {sym}, FD {fd}", g.display(var));
        }
    }

    /// ∂²/∂x∂y and ∂²/∂x² against central differences of the symbolic first derivative.
    #[test]
    fn second_derivatives_match_differences_of_first(r in recipe(), (x, y) in point()) {
        prop_assume!(value(&r, x, y).is_finite());
        let mut g = Graph::new();
        let e = build(&mut g, &r);
        let (sx, sy) = (g.symbol("x"), g.symbol("y"));
        let dx = g.diff(e, sx);
        let dxx = g.diff(dx, sx);
        let dxy = g.diff(dx, sy);
        let h = 1e-5;
        let fd_xx = (eval_tape(&g, dx, x + h, y) - eval_tape(&g, dx, x - h, y)) / (2.0 * h);
        let fd_xy = (eval_tape(&g, dx, x, y + h) - eval_tape(&g, dx, x, y - h)) / (2.0 * h);
        prop_assume!(fd_xx.abs() < 1e6 && fd_xy.abs() < 1e6);
        let (sxx, sxy) = (eval_tape(&g, dxx, x, y), eval_tape(&g, dxy, x, y));
        prop_assert!(close(sxx, fd_xx, 1e-4, 1e-5 * fd_xx.abs().max(1.0)), "xx {sxx} vs {fd_xx}");
        prop_assert!(close(sxy, fd_xy, 1e-4, 1e-5 * fd_xy.abs().max(1.0)), "xy {sxy} vs {fd_xy}");
    }

    /// CSE rewrites keep values: evaluate temporaries in order, then outputs.
    #[test]
    fn cse_preserves_values(r in recipe(), (x, y) in point()) {
        let direct = value(&r, x, y);
        prop_assume!(direct.is_finite() && direct.abs() < 1e8);
        let mut g = Graph::new();
        let e = build(&mut g, &r);
        let sx = g.symbol("x");
        let d = g.diff(e, sx);
        let cse = g.cse(&[e, d], "t");
        let mut env: Vec<(String, f64)> = vec![("x".into(), x), ("y".into(), y)];
        for &(temp, def) in &cse.temps {
            let v = g.eval(def, &|s| env.iter().find(|(n, _)| n == s).map(|p| p.1).unwrap_or(f64::NAN));
            env.push((g.name_of(temp).unwrap_or("?").to_owned(), v));
        }
        let lookup = |s: &str| env.iter().find(|(n, _)| n == s).map(|p| p.1).unwrap_or(f64::NAN);
        let via_cse = g.eval(cse.outputs[0], &lookup);
        let d_direct = eval_tape(&g, d, x, y);
        let d_cse = g.eval(cse.outputs[1], &lookup);
        prop_assert!(close(via_cse, direct, 1e-9, 1e-12));
        prop_assert!(close(d_cse, d_direct, 1e-9, 1e-12) || !d_direct.is_finite());
    }

    /// Pulling common factors out of sums keeps values, on the recipe and on
    /// its first and second x-derivatives (quotient-rule sums, which share
    /// factors such as (1 + a²)⁻ⁿ).
    #[test]
    fn factor_sums_preserves_values(r in recipe(), (x, y) in point()) {
        let direct = value(&r, x, y);
        prop_assume!(direct.is_finite() && direct.abs() < 1e6);
        let mut g = Graph::new();
        let e = build(&mut g, &r);
        let sx = g.symbol("x");
        let d = g.diff(e, sx);
        let dd = g.diff(d, sx);
        let factored = g.factor_sums(&[e, d, dd]);
        for (&before, &after) in [e, d, dd].iter().zip(&factored) {
            let (want, got) = (eval_tape(&g, before, x, y), eval_tape(&g, after, x, y));
            prop_assume!(want.is_finite() && want.abs() < 1e8);
            let scale = want.abs().max(1.0);
            prop_assert!(close(got, want, 1e-9, 1e-11 * scale),
                "factored {got} vs {want}: {} vs {}", g.display(after), g.display(before));
        }
    }
}
