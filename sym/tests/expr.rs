//! The expression layer builds exactly what the smart constructors build: each
//! expression is written with operators in one graph and step by step in
//! another, and the two graphs must hold the same nodes in the same order.

use std::panic::{catch_unwind, AssertUnwindSafe};

use reldesign_sym::{Graph, Id, Node, Scope, E};

const MU0: f64 = 4.0e-7 * std::f64::consts::PI;

/// `layer` (operators) and `steps` (constructors), each in a fresh graph in
/// which the symbols x, y, z are made first (the closures may name them
/// otherwise).
fn same<L>(layer: L, steps: impl FnOnce(&mut Graph, [Id; 3]) -> Id)
where
    L: for<'s> FnOnce(&'s Scope, [E<'s>; 3]) -> E<'s>,
{
    let xyz = |g: &mut Graph| [g.symbol("x"), g.symbol("y"), g.symbol("z")];
    let mut a = Graph::new();
    let vars = xyz(&mut a);
    let ea = a.with(|s| layer(s, s.exprs(vars)).id());
    let mut b = Graph::new();
    let vars = xyz(&mut b);
    let eb = steps(&mut b, vars);
    let text = b.display(eb);
    assert_eq!(ea, eb, "{} vs {text}", a.display(ea));
    assert_eq!(a.len(), b.len(), "node count of {text}");
    assert_eq!(nodes(&a, ea), nodes(&b, eb), "nodes of {text}");
}

fn nodes(g: &Graph, root: Id) -> Vec<Node> {
    g.postorder(&[root])
        .into_iter()
        .map(|n| g.node(n).clone())
        .collect()
}

#[test]
fn arithmetic_operators() {
    same(|_, [x, y, _]| x + y, |g, [x, y, _]| g.add(x, y));
    same(|_, [x, y, _]| x - y, |g, [x, y, _]| g.sub(x, y));
    same(
        |_, [x, y, z]| x * y * z,
        |g, [x, y, z]| {
            let xy = g.mul(x, y);
            g.mul(xy, z)
        },
    );
    same(|_, [x, y, _]| x / y, |g, [x, y, _]| g.div(x, y));
    same(|_, [x, ..]| -x, |g, [x, ..]| g.neg(x));
}

#[test]
fn f64_operands_on_both_sides() {
    same(
        |_, [x, ..]| 2.0 * x + 1.0,
        |g, [x, ..]| {
            let two = g.constant(2.0);
            let t = g.mul(two, x);
            let one = g.constant(1.0);
            g.add(t, one)
        },
    );
    same(
        |_, [x, ..]| 1.0 - x / 3.0,
        |g, [x, ..]| {
            let three = g.constant(3.0);
            let q = g.div(x, three);
            let one = g.constant(1.0);
            g.sub(one, q)
        },
    );
    same(
        |_, [x, ..]| 0.5 / x - x * 4.0,
        |g, [x, ..]| {
            let half = g.constant(0.5);
            let q = g.div(half, x);
            let four = g.constant(4.0);
            let p = g.mul(x, four);
            g.sub(q, p)
        },
    );
}

#[test]
fn functions_and_powers() {
    same(
        |_, [x, y, z]| x.powi(3) + y.pow(0.5) - z.pow(x),
        |g, [x, y, z]| {
            let x3 = g.powi(x, 3);
            let half = g.constant(0.5);
            let ry = g.pow(y, half);
            let s = g.add(x3, ry);
            let zx = g.pow(z, x);
            g.sub(s, zx)
        },
    );
    same(
        |_, [x, y, _]| (x * y).ln().sqrt().exp().abs().sign().recip(),
        |g, [x, y, _]| {
            let p = g.mul(x, y);
            let l = g.ln(p);
            let r = g.sqrt(l);
            let e = g.exp(r);
            let a = g.abs(e);
            let s = g.sign(a);
            g.recip(s)
        },
    );
    same(
        |_, [x, y, _]| x.tanh() * y.coth(),
        |g, [x, y, _]| {
            let t = g.tanh(x);
            let c = g.coth(y);
            g.mul(t, c)
        },
    );
}

#[test]
fn piecewise_nodes() {
    same(
        |_, [x, y, _]| x.max(y).min(0.0),
        |g, [x, y, _]| {
            let m = g.max(x, y);
            let zero = g.constant(0.0);
            g.min(m, zero)
        },
    );
    // the Langevin guard: |x| − 0.1 ≥ 0 selects the closed form
    same(
        |_, [x, y, _]| (x.abs() - 0.1).if_nonneg(x, y * y),
        |g, [x, y, _]| {
            let a = g.abs(x);
            let t = g.constant(0.1);
            let c = g.sub(a, t);
            let yy = g.mul(y, y);
            g.select(c, x, yy)
        },
    );
    same(
        |_, [x, ..]| x.piecewise(&[0.0, 1.0], &[-x, x * x, x]),
        |g, [x, ..]| {
            let n = g.neg(x);
            let xx = g.mul(x, x);
            g.piecewise(x, &[0.0, 1.0], &[n, xx, x])
        },
    );
}

#[test]
fn n_ary_sums_products_and_derivatives() {
    same(
        |s, [x, y, z]| s.sum(&[x, y, z]) * s.product(&[z, y]),
        |g, [x, y, z]| {
            let a = g.sum(&[x, y, z]);
            let b = g.product(&[z, y]);
            g.mul(a, b)
        },
    );
    same(
        |_, [x, ..]| (x.powi(3) + 2.0 * x).diff(x),
        |g, [x, ..]| {
            let x3 = g.powi(x, 3);
            let two = g.constant(2.0);
            let t = g.mul(two, x);
            let e = g.add(x3, t);
            g.diff(e, x)
        },
    );
}

/// McLyman (6), R_gap = (z/(μ0·A)) / (1 + z/√A · ln(2·l_w/(z + ε))), in the
/// order the operators build it.
#[test]
fn mclyman_reluctance() {
    same(
        |_, [z, a, lw]| z / (MU0 * a) / (1.0 + z / a.sqrt() * (2.0 * lw / (z + 1e-9)).ln()),
        |g, [z, a, lw]| {
            let mu0 = g.constant(MU0);
            let mu0_a = g.mul(mu0, a);
            let num = g.div(z, mu0_a);
            let sqrt_a = g.sqrt(a);
            let ratio = g.div(z, sqrt_a);
            let two = g.constant(2.0);
            let two_lw = g.mul(two, lw);
            let eps = g.constant(1e-9);
            let ze = g.add(z, eps);
            let q = g.div(two_lw, ze);
            let log = g.ln(q);
            let fringe = g.mul(ratio, log);
            let one = g.constant(1.0);
            let den = g.add(one, fringe);
            g.div(num, den)
        },
    );
}

/// JA (30) with the clamp (52): dB_c/dB_e = max(1 + μ0(1 − α)·dM_c/dB_e, ε).
#[test]
fn ja_clamped_flux_derivative() {
    same(
        |_, [alpha, dmc, eps]| (1.0 + MU0 * (1.0 - alpha) * dmc).max(eps),
        |g, [alpha, dmc, eps]| {
            let one = g.one();
            let one_minus_alpha = g.sub(one, alpha);
            let mu0 = g.constant(MU0);
            let k = g.mul(mu0, one_minus_alpha);
            let kd = g.mul(k, dmc);
            let raw = g.add(one, kd);
            g.max(raw, eps)
        },
    );
}

#[test]
fn handles_compare_and_print_as_their_nodes() {
    let mut g = Graph::new();
    g.with(|s| {
        let x = s.symbol("x");
        assert_eq!(x + x + x + x, 4.0 * x);
        assert_eq!((x * 2.5).to_string(), "2.5*x");
        assert_eq!(
            format!("{:?}", x - x),
            format!("{:?} = 0.0", s.constant(0.0).id())
        );
    });
}

#[test]
fn the_graph_is_back_after_with_even_on_panic() {
    let mut g = Graph::new();
    let x = g.with(|s| s.symbol("x").id());
    assert_eq!(g.find_symbol("x"), Some(x));
    let result = catch_unwind(AssertUnwindSafe(|| {
        g.with(|s| {
            s.symbol("y");
            panic!("inside with");
        })
    }));
    assert!(result.is_err());
    assert!(g.find_symbol("x").is_some() && g.find_symbol("y").is_some());
}

#[test]
#[should_panic(expected = "two different graphs")]
fn handles_of_two_graphs_do_not_mix() {
    let (mut a, mut b) = (Graph::new(), Graph::new());
    a.with(|sa| {
        b.with(|sb| {
            let _ = sa.symbol("x") + sb.symbol("x");
        })
    });
}
