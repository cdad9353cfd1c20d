//! Canonical forms, derivatives, piecewise nodes, deterministic printing and
//! symbols of the symbolic core, as data: each row is an expression and what
//! it must become, both written as text (`Graph::parse`), compared by node
//! (hash-consing makes node equality canonical-form equality).

use reldesign_sym::{Graph, Id, SymbolTaken, Tape};

/// Runs every row, then fails once listing every row that failed.
fn table<R: std::fmt::Debug>(rows: &[R], check: impl Fn(&mut Graph, &R) -> Result<(), String>) {
    let failures: Vec<String> = rows
        .iter()
        .filter_map(|row| {
            check(&mut Graph::new(), row)
                .err()
                .map(|e| format!("{row:?}: {e}"))
        })
        .collect();
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

fn parse(g: &mut Graph, text: &str) -> Id {
    g.parse(text, &[])
        .unwrap_or_else(|e| panic!("`{text}`: {e}"))
}

/// `got` is the node `want` parses to.
fn same_node(g: &mut Graph, got: Id, want: &str) -> Result<(), String> {
    let want = parse(g, want);
    if got == want {
        Ok(())
    } else {
        Err(format!("got {}, want {}", g.display(got), g.display(want)))
    }
}

#[test]
fn canonical_forms() {
    table(
        &[
            // commutative operands share one node
            ("x + y + z", "z + x + y"),
            ("y*z*x", "x*y*z"),
            // like terms and powers collect
            ("2*x + 3*x", "5*x"),
            ("x + x + x + x", "4*x"),
            ("x - x", "0"),
            ("x/x", "1"),
            ("x^2 * x^3", "x^5"),
            ("x^2 * x^-1", "x"),
            ("(x*y)^2", "x^2 * y^2"),
            ("(x^3)^2", "x^6"),
            // identities
            ("x*y*0", "0"),
            ("x*y*1", "x*y"),
            ("x*y + 0", "x*y"),
            ("x^1", "x"),
            ("x^0", "1"),
            ("select(y, x, x)", "x"),
            ("min(x, x)", "x"),
            ("ln(exp(x))", "x"),
            ("abs(sqrt(x))", "sqrt(x)"),
            ("sign(sign(x))", "sign(x)"),
            // constants fold
            ("2 + 3", "5"),
            ("2^3", "8"),
            ("max(2, -1)", "2"),
            ("select(-1, x, y)", "y"),
        ],
        |g, &(input, canonical)| {
            let got = parse(g, input);
            same_node(g, got, canonical)
        },
    );
}

/// Folding that only a value can state, and folding that must not happen.
#[test]
fn constants_fold_only_to_finite_values() {
    table(
        &[
            ("ln(2)", Some(2f64.ln())),
            ("2.5e-3 * 4", Some(0.01)),
            // ln(0) is not finite: kept symbolic, never folded to -inf.
            ("ln(0)", None),
            ("0^-1", None),
        ],
        |g, &(input, value)| {
            let e = parse(g, input);
            match g.as_const(e) == value {
                true => Ok(()),
                false => Err(format!("folded to {}", g.display(e))),
            }
        },
    );
}

/// The n-ary constructors agree with the binary ones, whatever the order.
#[test]
fn n_ary_sums_and_products_are_canonical() {
    let mut g = Graph::new();
    let [x, y, z] = ["x", "y", "z"].map(|n| g.symbol(n));
    let sum = parse(&mut g, "x + y + z");
    assert_eq!(g.sum(&[z, x, y]), sum);
    let product = parse(&mut g, "x*y*z");
    assert_eq!(g.product(&[y, z, x]), product);
}

#[test]
fn derivatives() {
    table(
        &[
            ("x^3 + 2*x", "x", 1, "3*x^2 + 2"),
            ("x^3 + 2*x", "x", 2, "6*x"),
            ("x^3 + 2*x", "x", 4, "0"),
            ("x*y + y", "x", 1, "y"),
            ("x*y + y", "y", 1, "x + 1"),
            ("ln(x)", "x", 1, "1/x"),
            ("exp(2*x)", "x", 1, "2*exp(2*x)"),
            ("sqrt(x)", "x", 1, "0.5/sqrt(x)"),
            ("abs(x)", "x", 1, "sign(x)"),
            ("tanh(x)", "x", 1, "1 - tanh(x)^2"),
            ("1/x", "x", 1, "-1/x^2"),
            ("x^y", "y", 1, "x^y*ln(x)"),
            // piecewise nodes differentiate branch-wise
            ("max(x, y)", "x", 1, "select(x - y, 1, 0)"),
            ("min(x, y)", "x", 1, "select(y - x, 1, 0)"),
            ("select(y, x^2, x)", "x", 1, "select(y, 2*x, 1)"),
        ],
        |g, &(input, var, order, derivative)| {
            let e = parse(g, input);
            let x = g.symbol(var);
            let d = g.diff_n(e, x, order);
            same_node(g, d, derivative)
        },
    );
}

#[test]
fn piecewise_nodes_evaluate_and_differentiate_branchwise() {
    let mut g = Graph::new();
    let x = g.symbol("x");
    // |x| written three ways, then a clamp and a spline-like piecewise
    let [sel, abs, max, min, neg, x2] = [
        "select(x, x, -x)",
        "abs(x)",
        "max(x, -x)",
        "min(x, 2)",
        "-x",
        "x^2",
    ]
    .map(|t| parse(&mut g, t));
    let pw = g.piecewise(x, &[0.0, 1.0], &[neg, x2, x]);
    let tape = Tape::compile(&g, &[x], &[sel, abs, max, min, pw]).unwrap();
    let mut out = [0.0; 5];
    for (xv, expect) in [
        (-1.5, [1.5, 1.5, 1.5, -1.5, 1.5]),
        (0.5, [0.5, 0.5, 0.5, 0.5, 0.25]),
        (3.0, [3.0, 3.0, 3.0, 2.0, 3.0]),
    ] {
        tape.eval(&[xv], &mut tape.scratch(), &mut out);
        assert_eq!(out, expect, "x = {xv}");
    }
    let derivatives = [sel, max, pw].map(|e| g.diff(e, x));
    let tape = Tape::compile(&g, &[x], &derivatives).unwrap();
    tape.eval(&[0.5], &mut tape.scratch(), &mut out[..3]);
    assert_eq!(&out[..3], &[1.0, 1.0, 1.0]);
    tape.eval(&[-2.0], &mut tape.scratch(), &mut out[..3]);
    assert_eq!(&out[..3], &[-1.0, -1.0, -1.0]);
}

/// -0.5·y²·∂/∂z [(z/mu0) / (1 + z·x·ln(0.03/z))]: a derivative with shared
/// subterms.
fn sample_expression(g: &mut Graph) -> Id {
    let r = parse(g, "(z/mu0) / (1 + z*x*ln(0.03/z))");
    let z = g.symbol("z");
    let dr = g.diff(r, z);
    g.parse("-0.5 * dr * y^2", &[("dr", dr)]).unwrap()
}

#[test]
fn printing_is_byte_identical_across_graphs() {
    let mut a = Graph::new();
    let ea = sample_expression(&mut a);
    let mut b = Graph::new();
    let eb = sample_expression(&mut b);
    assert_eq!(a.display(ea), b.display(eb));
}

/// Golden texts guard against changes of ordering or number formatting.
#[test]
fn printing_golden_texts() {
    table(
        &[
            ("x*y - 2.5/y + ln(x)", "x*y - 2.5/y + ln(x)"),
            // operands in order of construction: y was made first
            ("y*x + 2*x*y", "3.0*y*x"),
            ("1 - x/y^2", "-x/y^2.0 + 1.0"),
            ("x^-0.5 - x^0.5", "x^(-0.5) - x^0.5"),
            ("-2*x*y", "(-2.0)*x*y"),
            (
                "select(x - 1, min(x, 0), sign(x))",
                "select(x - 1.0, min(x, 0.0), sign(x))",
            ),
        ],
        |g, &(input, text)| {
            let e = parse(g, input);
            match g.display(e) == text {
                true => Ok(()),
                false => Err(format!("printed {}", g.display(e))),
            }
        },
    );
}

/// The whole CSE listing of the sample expression, pinned.
#[test]
fn cse_output_is_deterministic() {
    let run = || {
        let mut g = Graph::new();
        let e = sample_expression(&mut g);
        let cse = g.cse(&[e], "t");
        let mut lines: Vec<String> = cse
            .temps
            .iter()
            .map(|&(t, d)| format!("{} = {}", g.display(t), g.display(d)))
            .collect();
        lines.push(g.display(cse.outputs[0]));
        lines.join("\n")
    };
    let first = run();
    assert_eq!(first, run());
    let pinned = "\
t0 = mu0^(-1.0)
t1 = ln(0.03/z)
t2 = z*x*t1 + 1.0
(-0.5)*y^2.0*(t0/t2 - z*t0*(-x + x*t1)/t2^2.0)";
    assert_eq!(first, pinned, "the CSE listing changed:\n{first}");
}

#[test]
fn unbound_symbols_are_reported_by_name() {
    let mut g = Graph::new();
    let x = g.symbol("x");
    let e = parse(&mut g, "x + y");
    let err = Tape::compile(&g, &[x], &[e]).unwrap_err();
    assert!(err.to_string().contains("`y`"), "{err}");
}

#[test]
fn fresh_symbols_must_not_exist_yet() {
    let mut g = Graph::new();
    let x = g.symbol("x");
    assert_eq!(g.fresh_symbol("x"), Err(SymbolTaken("x".to_owned())));
    let y = g.fresh_symbol("y").unwrap();
    assert_ne!(x, y);
    assert_eq!(g.find_symbol("y"), Some(y));
    assert_eq!(
        g.fresh_symbol("y").unwrap_err().to_string(),
        "the symbol `y` already exists"
    );
}
