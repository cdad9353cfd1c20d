//! Parameter-only subexpressions that need a math call (√A_gap, ln(2·l_w),
//! exp, powf, min, …) are evaluated when the code is generated and emitted
//! as derived consts, because the compiler folds `1.0 / A_GAP` but never
//! `Real::sqrt(A_GAP)` (a libm call): left in the function, the call would
//! be paid on every evaluation.
//!
//! Each maximal such subexpression becomes a fresh parameter symbol (so the
//! lowering treats it like any other const: parameter-only factors first, to
//! be folded with them) whose value is computed with the runtime's own math
//! (`reldesign_runtime::math::Real`, the functions the emitted code would
//! have called). Subexpressions the compiler folds by itself (sums,
//! products, x⁻¹, x², x³) stay symbolic, so a parameter change still changes
//! one line there; a derived const's line changes with the parameters it is
//! computed from, which its doc comment says.

use std::collections::{HashMap, HashSet};

use designer::sym::{Func, Graph, Id, Node};
use reldesign_runtime::math::Real;

use crate::error::EmitError;
use crate::names::{const_name, describe};
use crate::param::Param;

/// One derived const: a parameter-only subexpression replaced by a symbol.
pub(crate) struct Derived {
    /// Symbol name (the const is its upper snake case).
    pub name: String,
    pub symbol: Id,
    /// Value from the parameters' values.
    pub value: f64,
    /// The replaced expression, printed with the parameters' names.
    pub formula: String,
}

/// The graph with the derived symbols substituted.
pub(crate) struct Folded {
    pub graph: Graph,
    pub derived: Vec<Derived>,
    /// Image of every root passed to [`fold`].
    pub roots: Vec<Id>,
}

/// Replaces the maximal parameter-only subexpressions of `roots` that need
/// a math call by derived parameter symbols; `None` when there are none (the
/// graph is then used as it is).
pub(crate) fn fold(
    graph: &Graph,
    params: &[Param],
    roots: &[Id],
) -> Result<Option<Folded>, EmitError> {
    let param_ids: HashSet<Id> = params.iter().map(|p| p.symbol).collect();
    let sites = fold_sites(graph, &param_ids, roots);
    if sites.is_empty() {
        return Ok(None);
    }
    let values: HashMap<Id, f64> = params.iter().map(|p| (p.symbol, p.value)).collect();
    let mut taken: HashSet<String> = params
        .iter()
        .map(|p| const_name(p.name))
        .collect::<Result<_, _>>()?;
    let mut g = graph.clone();
    let mut derived = Vec::with_capacity(sites.len());
    let mut map = HashMap::new();
    for &site in &sites {
        let name = fresh_name(&g, site, &mut taken);
        let value = evaluate(graph, site, &values);
        if !value.is_finite() {
            return Err(EmitError::NonFinite {
                name: const_name(&name)?,
                value: format!("{value:?}"),
                float: "f64",
            });
        }
        let symbol = g.symbol(&name);
        map.insert(site, symbol);
        derived.push(Derived {
            name,
            symbol,
            value,
            formula: graph.display(site),
        });
    }
    let roots = g.substitute_all(roots, &map);
    Ok(Some(Folded {
        graph: g,
        derived,
        roots,
    }))
}

/// The maximal parameter-only nodes under `roots` that contain a math call,
/// in the deterministic post-order.
fn fold_sites(g: &Graph, params: &HashSet<Id>, roots: &[Id]) -> Vec<Id> {
    let order = g.postorder(roots);
    // (parameter-only, contains a call) per node, children first.
    let mut info: HashMap<Id, (bool, bool)> = HashMap::with_capacity(order.len());
    for &id in &order {
        let kids = g.children(id);
        let own = match g.node(id) {
            Node::Const(_) => (true, false),
            Node::Sym(_) => (params.contains(&id), false),
            _ => (true, needs_call(g, id)),
        };
        let s = own.0 && kids.iter().all(|c| info[c].0);
        let calls = own.1 || kids.iter().any(|c| info[c].1);
        info.insert(id, (s, calls));
    }
    let foldable = |id: &Id| info[id] == (true, true);
    let mut inner: HashSet<Id> = HashSet::new();
    for &id in &order {
        if foldable(&id) {
            inner.extend(g.children(id));
        }
    }
    order
        .into_iter()
        .filter(|id| foldable(id) && !inner.contains(id))
        .collect()
}

/// Whether the lowering writes `id` itself as a `Real::…` call (a function,
/// `min`/`max`, a power other than x^±1, x^±2, x^±3).
fn needs_call(g: &Graph, id: Id) -> bool {
    match g.node(id) {
        Node::Func(..) | Node::Min(..) | Node::Max(..) => true,
        Node::Pow(_, e) => !matches!(g.as_const(*e), Some(e) if e.fract() == 0.0 && e.abs() <= 3.0),
        _ => false,
    }
}

/// A const name from the expression (`inv_sqrt_A_gap` → `INV_SQRT_A_GAP`),
/// free among the parameters, the other derived consts and the symbols.
fn fresh_name(g: &Graph, id: Id, taken: &mut HashSet<String>) -> String {
    let no_local = |_: Id| None;
    let base = describe(g, id, &no_local).unwrap_or_else(|| "derived".to_owned());
    let mut name = base.clone();
    let mut k = 2;
    while taken.contains(&name.to_ascii_uppercase()) || g.find_symbol(&name).is_some() {
        name = format!("{base}_{k}");
        k += 1;
    }
    taken.insert(name.to_ascii_uppercase());
    name
}

/// The value of a parameter-only expression, computed as the emitted code
/// would compute it (the lowering's forms: 1/√x, x·x, `Real::powi`, …).
fn evaluate(g: &Graph, root: Id, params: &HashMap<Id, f64>) -> f64 {
    let mut values: HashMap<Id, f64> = HashMap::new();
    for id in g.postorder(&[root]) {
        let v = |c: &Id| values.get(c).copied().unwrap_or(f64::NAN);
        let x = match g.node(id) {
            Node::Const(bits) => f64::from_bits(*bits),
            Node::Sym(_) => params.get(&id).copied().unwrap_or(f64::NAN),
            Node::Add(xs) => xs.iter().map(v).fold(0.0, |a, b| a + b),
            Node::Mul(xs) => xs.iter().map(v).fold(1.0, |a, b| a * b),
            Node::Pow(b, e) => power(v(b), v(e)),
            Node::Func(f, a) => apply(*f, v(a)),
            Node::Min(a, b) => Real::min(v(a), v(b)),
            Node::Max(a, b) => Real::max(v(a), v(b)),
            Node::Select(c, a, b) => {
                if v(c) >= 0.0 {
                    v(a)
                } else {
                    v(b)
                }
            }
        };
        values.insert(id, x);
    }
    values.get(&root).copied().unwrap_or(f64::NAN)
}

/// bᵉ as the lowering writes it: negative powers as 1 / b^|e|.
fn power(b: f64, e: f64) -> f64 {
    let p = e.abs();
    let m = if p.fract() == 0.0 && p <= 64.0 {
        <f64 as Real>::powi(b, p as i32)
    } else if p == 0.5 {
        <f64 as Real>::sqrt(b)
    } else {
        return <f64 as Real>::powf(b, e);
    };
    if e < 0.0 {
        1.0 / m
    } else {
        m
    }
}

fn apply(f: Func, x: f64) -> f64 {
    match f {
        Func::Sqrt => <f64 as Real>::sqrt(x),
        Func::Exp => <f64 as Real>::exp(x),
        Func::Ln => <f64 as Real>::ln(x),
        Func::Abs => <f64 as Real>::abs(x),
        Func::Sign => <f64 as Real>::signum0(x),
        Func::Tanh => <f64 as Real>::tanh(x),
        Func::Coth => <f64 as Real>::coth(x),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x·ln(x)·ln(√a + b)/a with parameters a, b.
    fn example(g: &mut Graph) -> (Id, [Id; 3]) {
        let [x, a, b] = [g.symbol("x"), g.symbol("a"), g.symbol("b")];
        let sa = g.sqrt(a);
        let sum = g.add(sa, b);
        let l = g.ln(sum);
        let ia = g.recip(a);
        let lx = g.ln(x);
        (g.product(&[l, ia, lx, x]), [x, a, b])
    }

    #[test]
    fn folds_the_maximal_parameter_only_calls_and_evaluates_them() {
        let mut g = Graph::new();
        let (root, [_, a, b]) = example(&mut g);
        let params = [("a", a, 4.0).into(), ("b", b, 1.0).into()];
        let Ok(Some(f)) = fold(&g, &params, &[root]) else {
            panic!("ln(√a + b) must fold");
        };
        // one const for ln(√a + b), not one for √a inside it
        assert_eq!(f.derived.len(), 1);
        let d = &f.derived[0];
        assert!((d.value - 3f64.ln()).abs() < 1e-15, "{}", d.value);
        assert!(d.formula.contains("sqrt(a)"), "{}", d.formula);
        // ln(x) depends on the input and 1/a folds at compile time: both stay
        let text = f.graph.display(f.roots[0]);
        assert!(text.contains("ln(x)"), "{text}");
        assert!(text.contains(&d.name), "{text}");
        assert!(text.ends_with("/a"), "{text}");
        assert!(!text.contains("sqrt"), "{text}");
    }

    #[test]
    fn nothing_to_fold_leaves_the_graph_alone() {
        let mut g = Graph::new();
        let [x, a] = [g.symbol("x"), g.symbol("a")];
        let ia = g.recip(a);
        let sq = g.powi(a, 2);
        let root = g.product(&[x, ia, sq]);
        assert!(matches!(
            fold(&g, &[("a", a, 2.0).into()], &[root]),
            Ok(None)
        ));
    }

    #[test]
    fn a_non_finite_value_names_its_const() {
        let mut g = Graph::new();
        let [x, a] = [g.symbol("x"), g.symbol("a")];
        let sa = g.sqrt(a);
        let root = g.mul(x, sa);
        let err = fold(&g, &[("a", a, -1.0).into()], &[root]).err();
        assert!(
            matches!(&err, Some(EmitError::NonFinite { name, .. }) if name == "SQRT_A"),
            "{err:?}"
        );
    }
}
