//! Physical constants by name: the model builds μ0 and the McLyman
//! regularisation Z_EPS as numbers, and the symbolic core folds them into
//! the coefficients (1/(2μ0) = 397887.36…), where a reader cannot recognise
//! them. Before an expression is emitted, every constant c = k·μ0ᵉ
//! (e = ±1, ±2, k a short decimal such as 0.5 or −2) becomes k·MU0ᵉ and
//! every ±Z_EPS becomes ±Z_EPS. The compiler folds `0.5 * inv_mu0 * …` back
//! into one constant, so this costs nothing at run time.
//!
//! `MU0` and `Z_EPS` are declared once per file, in its `params!` macro,
//! when the model's equations use them ([`of_model`]); a function whose
//! caller passes them as parameters ([`in_scope`]) refers to those, any
//! other declares the ones it uses as local consts.
//!
//! A short decimal k has at most 3 significant digits and matches c/μ0ᵉ to
//! 10⁻¹² relative: a coincidence would need a coefficient that is neither
//! short itself nor unrelated to μ0 to within 12 digits.

use std::collections::HashMap;

use designer::model::{Model, MU0, Z_EPS};
use designer::sym::{Graph, Id, Node};

use crate::param::Param;

/// One named physical constant.
pub(crate) struct Constant {
    /// Symbol name (the const is its upper snake case).
    pub symbol: &'static str,
    pub value: f64,
    /// Its definition in the `params!` macro (`$f` the float type).
    pub definition: &'static str,
    /// Doc of the emitted const.
    pub doc: &'static str,
}

const MU0_CONST: Constant = Constant {
    symbol: "mu0",
    value: MU0,
    definition: "4e-7 * ::core::$f::consts::PI",
    doc: "μ0 = 4π·10⁻⁷ H/m, the vacuum permeability",
};

const Z_EPS_CONST: Constant = Constant {
    symbol: "z_eps",
    value: Z_EPS,
    definition: "1e-9",
    doc: "Z_EPS [m], the regularisation of the McLyman logarithm ln(k/(z + Z_EPS))",
};

/// The physical constants the model's equations (ẋ = f, the coil current)
/// use, in a fixed order: what the file's `params!` declares. A constant
/// whose name a model parameter already has is left out (it stays a number).
pub(crate) fn of_model(model: &Model) -> Vec<&'static Constant> {
    let mut roots = model.f.clone();
    roots.push(model.current);
    let found: Vec<Rewrite> = constants_under(&model.graph, &roots)
        .into_iter()
        .map(|(_, r)| r)
        .collect();
    let clash = |c: &Constant| {
        model.graph.find_symbol(c.symbol).is_some()
            || model
                .params
                .iter()
                .any(|(name, _, _)| name.eq_ignore_ascii_case(c.symbol))
    };
    let mu0 = found.iter().any(|r| matches!(r, Rewrite::Mu0 { .. }));
    let z_eps = found.iter().any(|r| matches!(r, Rewrite::ZEps { .. }));
    [(mu0, &MU0_CONST), (z_eps, &Z_EPS_CONST)]
        .into_iter()
        .filter(|&(used, c)| used && !clash(c))
        .map(|(_, c)| c)
        .collect()
}

/// Symbols in `graph` for `constants`, as parameters: passed to the
/// expression emitter, they tell it that the consts are in scope.
pub(crate) fn in_scope(graph: &mut Graph, constants: &[&'static Constant]) -> Vec<Param<'static>> {
    constants
        .iter()
        .map(|c| Param::from((c.symbol, graph.symbol(c.symbol), c.value)))
        .collect()
}

/// The graph with the named constants substituted.
pub(crate) struct Named {
    pub graph: Graph,
    /// Image of every root passed to [`name_constants`].
    pub roots: Vec<Id>,
    /// The constants not in scope, as parameters (symbol, value), with their
    /// docs: the function declares them.
    pub local: Vec<(Param<'static>, &'static str)>,
}

/// Rewrites the constants of `roots` that are k·μ0ᵉ or ±Z_EPS in terms of
/// the symbols `mu0` and `z_eps`: those of `params` (in scope), else fresh
/// ones ([`Named::local`]). `None` when there are none; a constant whose name
/// is taken otherwise (a symbol or a parameter of that name) stays a number.
pub(crate) fn name_constants(graph: &Graph, roots: &[Id], params: &[Param]) -> Option<Named> {
    let rewrites = constants_under(graph, roots);
    if rewrites.is_empty() {
        return None;
    }
    let mut g = graph.clone();
    let mut local = Vec::new();
    // the symbol of `c`, or None when its name is taken by something else
    let mut symbol_of = |g: &mut Graph, c: &'static Constant| -> Option<Id> {
        if let Some(p) = params.iter().find(|p| p.name == c.symbol) {
            return Some(p.symbol);
        }
        if let Some((p, _)) = local.iter().find(|(p, _): &&(Param, _)| p.name == c.symbol) {
            return Some(p.symbol);
        }
        let taken = g.find_symbol(c.symbol).is_some()
            || params.iter().any(|p| p.name.eq_ignore_ascii_case(c.symbol));
        if taken {
            return None;
        }
        let id = g.symbol(c.symbol);
        local.push((Param::from((c.symbol, id, c.value)), c.doc));
        Some(id)
    };
    let mut map = HashMap::new();
    for (id, rewrite) in rewrites {
        let image = match rewrite {
            Rewrite::Mu0 { k, e } => symbol_of(&mut g, &MU0_CONST).map(|mu0| {
                let power = g.powi(mu0, e);
                g.scale(k, power)
            }),
            Rewrite::ZEps { sign } => {
                symbol_of(&mut g, &Z_EPS_CONST).map(|z_eps| g.scale(sign, z_eps))
            }
        };
        if let Some(image) = image {
            map.insert(id, image);
        }
    }
    if map.is_empty() {
        return None;
    }
    let roots = g.substitute_all(roots, &map);
    Some(Named {
        graph: g,
        roots,
        local,
    })
}

/// The recognised constants under `roots`, in the deterministic post-order.
fn constants_under(graph: &Graph, roots: &[Id]) -> Vec<(Id, Rewrite)> {
    graph
        .postorder(roots)
        .into_iter()
        .filter_map(|id| match graph.node(id) {
            Node::Const(bits) => recognise(f64::from_bits(*bits)).map(|r| (id, r)),
            _ => None,
        })
        .collect()
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
        assert_eq!(n.local.len(), 2);
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
