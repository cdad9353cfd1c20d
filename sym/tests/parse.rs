//! The infix parser: precedence, literals, bindings, and its error messages.

use reldesign_sym::Graph;

#[test]
fn precedence_and_associativity() {
    let mut g = Graph::new();
    for (text, x, y, value) in [
        ("-x^2", 3.0, 0.0, -9.0),
        ("2^3^2", 0.0, 0.0, 512.0),
        ("x - y - 1", 5.0, 2.0, 2.0),
        ("x / y / 2", 12.0, 3.0, 2.0),
        ("x + y * 2", 1.0, 3.0, 7.0),
        ("(x + y) * 2", 1.0, 3.0, 8.0),
        ("x^-1 + -y", 4.0, 1.0, -0.75),
        ("2*-x", 1.5, 0.0, -3.0),
        ("1e-3*x + .5 + 2.5E+1", 1000.0, 0.0, 26.5),
        ("x·y − 1", 2.0, 3.0, 5.0),
        (
            "max(x, y) - min(x, y) + select(x - y, 1, 10)",
            2.0,
            5.0,
            13.0,
        ),
        (
            "sqrt(x) + exp(0) + ln(1) + abs(-y) + sign(-y)",
            9.0,
            2.0,
            5.0,
        ),
        ("tanh(0) + coth(x)*0 + 2", 1.0, 0.0, 2.0),
    ] {
        let e = g.parse(text, &[]).unwrap();
        let v = g.eval(e, &|s| if s == "x" { x } else { y });
        assert_eq!(v, value, "`{text}` at x = {x}, y = {y}: {}", g.display(e));
    }
}

#[test]
fn names_are_bindings_or_the_graphs_symbols() {
    let mut g = Graph::new();
    let x = g.symbol("x");
    assert_eq!(g.parse("x", &[]), Ok(x));
    let f = g.parse("x^2 + 1", &[]).unwrap();
    let bound = g.parse("2*f", &[("f", f)]).unwrap();
    assert_eq!(bound, g.parse("2*(x^2 + 1)", &[]).unwrap());
    assert_eq!(g.find_symbol("f"), None, "a bound name makes no symbol");
    let phi = g.parse("φ_c", &[]).unwrap();
    assert_eq!(g.name_of(phi), Some("φ_c"));
}

/// The printer's text parses back to the same node.
#[test]
fn printed_text_parses_back() {
    let mut g = Graph::new();
    for text in [
        "x*y - 2.5/y + ln(x)",
        "x^-0.5 - 3*x^2/(y*z)",
        "-2*x*select(x - 1, min(x, 0), max(y, -1))",
        "(1 + x)^0.5 * coth(y)^-2",
    ] {
        let e = g.parse(text, &[]).unwrap();
        let printed = g.display(e);
        assert_eq!(
            g.parse(&printed, &[]),
            Ok(e),
            "`{text}` printed `{printed}`"
        );
    }
}

#[test]
fn errors_say_where_and_what_was_expected() {
    let mut g = Graph::new();
    for (text, error) in [
        ("x +", "column 4: expected a number, a name, `(` or `-`, found the end"),
        ("(x + y", "column 7: expected `)`, found the end"),
        ("x y", "column 3: expected an operator or the end, found `y`"),
        ("2 * )", "column 5: expected a number, a name, `(` or `-`, found `)`"),
        ("x $ y", "column 3: expected an operand or an operator, found `$`"),
        ("1e999 * x", "column 1: expected a finite number, found `1e999`"),
        ("1.2.3", "column 4: expected an operator or the end, found `0.3`"),
        (
            "sqr(x)",
            "column 1: expected a function (sqrt, exp, ln, abs, sign, tanh, coth, min, max, select), found `sqr`",
        ),
        ("x + min(x)", "column 5: expected 2 argument(s) to `min`, found 1"),
        ("ln(x, y)", "column 1: expected 1 argument(s) to `ln`, found 2"),
        ("max(x, y", "column 9: expected `,` or `)`, found the end"),
    ] {
        let got = g.parse(text, &[]).map_err(|e| e.to_string());
        assert_eq!(got, Err(error.to_owned()), "`{text}`");
    }
}
