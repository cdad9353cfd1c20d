//! Physical constants by name: the model builds μ0 and the McLyman
//! regularisation Z_EPS as numbers, and the symbolic core folds them into
//! the coefficients (1/(2μ0) = 397887.36…), where a reader cannot recognise
//! them. Before an expression is emitted, every constant c = k·μ0ᵉ
//! (e = ±1, ±2, k a short decimal such as 0.5 or −2) becomes k·MU0ᵉ and
//! every ±Z_EPS becomes ±Z_EPS, with `MU0` and `Z_EPS` emitted as documented
//! consts. The compiler folds `0.5 / MU0 * …` back into one constant, so
//! this costs nothing at run time.
//!
//! A short decimal k has at most 3 significant digits and matches c/μ0ᵉ to
//! 10⁻¹² relative: a coincidence would need a coefficient that is neither
//! short itself nor unrelated to μ0 to within 12 digits.

use std::collections::HashMap;

use designer::model::{MU0, Z_EPS};
use designer::sym::{Graph, Id, Node};

use crate::param::Param;

/// One named physical constant.
pub(crate) struct Constant {
    /// Symbol name (the const is its upper snake case).
    pub symbol: &'static str,
    pub value: f64,
    /// Doc of the emitted const.
    pub doc: &'static str,
}

const MU0_CONST: Constant = Constant {
    symbol: "mu0",
    value: MU0,
    doc: "μ0 = 4π·10⁻⁷ H/m, the vacuum permeability (the compiler folds it into the coefficients)",
};

const Z_EPS_CONST: Constant = Constant {
    symbol: "z_eps",
    value: Z_EPS,
    doc: "Z_EPS [m], the regularisation of the McLyman logarithm ln(k/(z + Z_EPS))",
};

/// The graph with the named constants substituted.
pub(crate) struct Named {
    pub graph: Graph,
    /// Image of every root passed to [`name_constants`].
    pub roots: Vec<Id>,
    /// The constants used, as parameters (symbol, value), with their docs.
    pub used: Vec<(Param<'static>, &'static str)>,
}

/// Rewrites the constants of `roots` that are k·μ0ᵉ or ±Z_EPS in terms of
/// the symbols `mu0` and `z_eps`; `None` when there are none (or when such a
/// symbol, or a parameter with the const name `MU0` or `Z_EPS`, exists: the
/// constants then stay numbers).
pub(crate) fn name_constants(graph: &Graph, roots: &[Id], params: &[Param]) -> Option<Named> {
    let taken = |c: &Constant| {
        graph.find_symbol(c.symbol).is_some()
            || params.iter().any(|p| p.name.eq_ignore_ascii_case(c.symbol))
    };
    if taken(&MU0_CONST) || taken(&Z_EPS_CONST) {
        return None;
    }
    let rewrites: Vec<(Id, Rewrite)> = graph
        .postorder(roots)
        .into_iter()
        .filter_map(|id| match graph.node(id) {
            Node::Const(bits) => recognise(f64::from_bits(*bits)).map(|r| (id, r)),
            _ => None,
        })
        .collect();
    if rewrites.is_empty() {
        return None;
    }
    let mut g = graph.clone();
    let mut used = Vec::new();
    let mut symbol_of = |g: &mut Graph, c: &'static Constant| {
        let id = g.symbol(c.symbol);
        if !used.iter().any(|(p, _): &(Param, _)| p.symbol == id) {
            used.push((Param::from((c.symbol, id, c.value)), c.doc));
        }
        id
    };
    let mut map = HashMap::new();
    for (id, rewrite) in rewrites {
        let image = match rewrite {
            Rewrite::Mu0 { k, e } => {
                let mu0 = symbol_of(&mut g, &MU0_CONST);
                let power = g.powi(mu0, e);
                g.scale(k, power)
            }
            Rewrite::ZEps { sign } => {
                let z_eps = symbol_of(&mut g, &Z_EPS_CONST);
                g.scale(sign, z_eps)
            }
        };
        map.insert(id, image);
    }
    let roots = g.substitute_all(roots, &map);
    Some(Named {
        graph: g,
        roots,
        used,
    })
}

enum Rewrite {
    /// c = k·μ0ᵉ
    Mu0 { k: f64, e: i32 },
    /// c = sign·Z_EPS
    ZEps { sign: f64 },
}

fn recognise(c: f64) -> Option<Rewrite> {
    if c.abs() == Z_EPS {
        return Some(Rewrite::ZEps { sign: c.signum() });
    }
    if !c.is_finite() || c == 0.0 || short(c).is_some() {
        return None;
    }
    [1, -1, 2, -2]
        .into_iter()
        .find_map(|e| short(c / MU0.powi(e)).map(|k| Rewrite::Mu0 { k, e }))
}

/// `x` as a decimal of at most 3 significant digits, if it is one (to 10⁻¹²).
fn short(x: f64) -> Option<f64> {
    let r: f64 = format!("{x:.2e}").parse().ok()?;
    ((x - r).abs() <= 1e-12 * r.abs() && r != 0.0).then_some(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mu0_multiples_and_z_eps_are_recognised_other_constants_are_not() {
        let half_inv = 0.5 / MU0;
        assert!(matches!(recognise(half_inv), Some(Rewrite::Mu0 { k, e: -1 }) if k == 0.5));
        assert!(matches!(recognise(-MU0), Some(Rewrite::Mu0 { k, e: 1 }) if k == -1.0));
        assert!(matches!(recognise(2.0 * MU0 * MU0), Some(Rewrite::Mu0 { k, e: 2 }) if k == 2.0));
        assert!(matches!(recognise(1e-9), Some(Rewrite::ZEps { sign }) if sign == 1.0));
        assert!(matches!(recognise(-1e-9), Some(Rewrite::ZEps { sign }) if sign == -1.0));
        for c in [
            0.0,
            1.0,
            -0.5,
            2.0,
            1e-6,
            397887.0,
            1.234567,
            f64::NAN,
            0.1 / 3.0,
        ] {
            assert!(recognise(c).is_none(), "{c}");
        }
    }

    #[test]
    fn the_rewritten_graph_has_the_same_value() {
        let mut g = Graph::new();
        let z = g.symbol("z");
        let eps = g.constant(Z_EPS);
        let ze = g.add(z, eps);
        let c = g.constant(-0.5 / MU0);
        let root = g.mul(c, ze);
        let Some(n) = name_constants(&g, &[root], &[]) else {
            panic!("μ0 and Z_EPS must be named");
        };
        assert_eq!(n.used.len(), 2);
        let text = n.graph.display(n.roots[0]);
        assert!(text.contains("mu0") && text.contains("z_eps"), "{text}");
        let value = |name: &str| match name {
            "z" => 3e-4,
            "mu0" => MU0,
            "z_eps" => Z_EPS,
            _ => f64::NAN,
        };
        let want = g.eval(root, &value);
        let got = n.graph.eval(n.roots[0], &value);
        assert!((got - want).abs() <= 1e-15 * want.abs(), "{got} vs {want}");
    }
}
