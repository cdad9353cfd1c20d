//! The evaluation plan of one function: which nodes become `let` bindings,
//! in which order, under which names.
//!
//! The order is the deterministic children-before-parents post-order of the
//! outputs (the order of `Graph::cse`), so the same graph gives the same
//! plan on every run; maps are only used for lookup, never iterated.
//! A node gets its own `let` when it is
//! - used more than once and not trivial (the CSE rule of `Graph::cse`),
//!   counting the base of x² and x³ as used two and three times, since they
//!   are written `x * x` and `x * x * x`;
//! - named by the caller (`named`), or an output that other outputs reuse
//!   (it then takes the output's name);
//! - a `select`, so that every `if … else …` is a statement of its own;
//! - an output that later outputs use through its symbol (`output_symbols`).

use std::collections::HashMap;

use designer::sym::{Graph, Id, Node};

use crate::error::EmitError;
use crate::names::{describe, Namer};

/// One `let` of the plan.
pub(crate) struct Binding {
    pub id: Id,
    pub name: String,
}

pub(crate) struct Plan {
    /// Temporaries and shared outputs, in evaluation order.
    pub lets: Vec<Binding>,
    /// Names of bound nodes (inputs, parameters, lets).
    pub bound: HashMap<Id, String>,
    /// Which inputs the outputs use (by input position).
    pub input_used: Vec<bool>,
}

pub(crate) struct PlanRequest<'a> {
    pub inputs: &'a [(String, Id)],
    /// parameter symbol → const name
    pub params: &'a HashMap<Id, String>,
    /// (name, root) of the outputs
    pub outputs: &'a [(String, Id)],
    pub named: &'a [(String, Id)],
    /// (output name, symbol standing for that output in later outputs)
    pub output_symbols: &'a [(String, Id)],
}

pub(crate) fn plan(g: &Graph, req: &PlanRequest, namer: &mut Namer) -> Result<Plan, EmitError> {
    let roots: Vec<Id> = req.outputs.iter().map(|o| o.1).collect();
    let order = g.postorder(&roots);
    let mut bound: HashMap<Id, String> = HashMap::new();
    for (name, id) in req.inputs {
        if g.name_of(*id).is_none() {
            return Err(EmitError::NotASymbol(name.clone()));
        }
        bound.insert(*id, name.clone());
    }
    for (&id, name) in req.params {
        // lookup table only; params never shadow inputs
        bound.entry(id).or_insert_with(|| name.clone());
    }

    let uses = use_counts(g, &order, &roots);
    let named: HashMap<Id, &str> = req
        .named
        .iter()
        .rev() // the first name given for a node wins
        .map(|(n, id)| (*id, n.as_str()))
        .collect();
    let mut output_name: HashMap<Id, &str> = HashMap::new();
    for (n, id) in req.outputs.iter().rev() {
        output_name.insert(*id, n.as_str());
    }

    let staged: HashMap<&str, Id> = req
        .output_symbols
        .iter()
        .map(|(n, id)| (n.as_str(), *id))
        .collect();
    let mut input_used = vec![false; req.inputs.len()];
    let mut lets = Vec::new();
    for &id in &order {
        if let Node::Sym(i) = g.node(id) {
            if let Some((name, _)) = req.output_symbols.iter().find(|(_, s)| *s == id) {
                // an earlier output's value: its `let` must already exist
                if !lets.iter().any(|b: &Binding| &b.name == name) {
                    return Err(EmitError::OutputUsedEarly(name.clone()));
                }
                bound.insert(id, name.clone());
                continue;
            }
            match req.inputs.iter().position(|(_, s)| *s == id) {
                Some(k) => input_used[k] = true,
                None if req.params.contains_key(&id) => {}
                None => return Err(EmitError::UnboundSymbol(g.symbol_name(*i).to_owned())),
            }
            continue;
        }
        if matches!(g.node(id), Node::Const(_)) {
            continue;
        }
        let is_root = output_name.contains_key(&id);
        let is_staged = output_name.get(&id).is_some_and(|n| staged.contains_key(n));
        let shared = uses.get(&id).copied().unwrap_or(0) >= 2 && !is_trivial(g, id);
        let is_select = matches!(g.node(id), Node::Select(..));
        let wanted = named.contains_key(&id) || shared || is_staged || (is_select && !is_root);
        if !wanted {
            continue;
        }
        let name = if let Some(&n) = named.get(&id) {
            n.to_owned()
        } else if let Some(&n) = output_name.get(&id) {
            // an output reused by others: bind it once, under its own name
            n.to_owned()
        } else {
            let lookup = |x: Id| bound.get(&x).cloned();
            let base = describe(g, id, &lookup);
            namer.fresh(base.as_deref())
        };
        bound.insert(id, name.clone());
        lets.push(Binding { id, name });
    }
    Ok(Plan {
        lets,
        bound,
        input_used,
    })
}

/// Operand counts; roots count once more, bases of x², x³ two and three times.
fn use_counts(g: &Graph, order: &[Id], roots: &[Id]) -> HashMap<Id, usize> {
    let mut uses: HashMap<Id, usize> = HashMap::new();
    for &id in order {
        for c in g.children(id) {
            *uses.entry(c).or_insert(0) += 1;
        }
        if let Node::Pow(b, e) = g.node(id) {
            let repeat = match g.as_const(*e) {
                Some(e) if e.abs() == 2.0 => 1,
                Some(e) if e.abs() == 3.0 => 2,
                _ => 0,
            };
            *uses.entry(*b).or_insert(0) += repeat;
        }
    }
    for r in roots {
        *uses.entry(*r).or_insert(0) += 1;
    }
    uses
}

/// Constants, symbols and c·symbol are never worth a temporary (as in `Graph::cse`).
fn is_trivial(g: &Graph, id: Id) -> bool {
    match g.node(id) {
        Node::Const(_) | Node::Sym(_) => true,
        Node::Mul(xs) => {
            xs.len() == 2
                && xs.first().and_then(|&c| g.as_const(c)).is_some()
                && xs
                    .get(1)
                    .is_some_and(|&s| matches!(g.node(s), Node::Sym(_)))
        }
        _ => false,
    }
}
