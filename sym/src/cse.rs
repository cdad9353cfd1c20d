//! Deterministic common-subexpression elimination.
//!
//! The DAG is already hash-consed, so "common subexpression" means a node
//! reached more than once from the roots. `cse` names each such node (in
//! children-before-parents order, hence deterministic) as a temporary symbol
//! and rewrites everything above it in terms of those temporaries. Generated
//! code then reads as a list of `let tN = …;` lines followed by the outputs.

use std::collections::HashMap;

use super::graph::{Graph, Id, Node};

/// Result of [`Graph::cse`]: evaluate `temps` in order, then `outputs`.
#[derive(Debug, Clone, PartialEq)]
pub struct Cse {
    /// (temporary symbol, its definition in terms of inputs and earlier temporaries)
    pub temps: Vec<(Id, Id)>,
    /// The roots rewritten in terms of the temporaries.
    pub outputs: Vec<Id>,
}

impl Graph {
    /// Names every non-trivial node used at least twice under `roots` as a
    /// temporary `{prefix}{k}`.
    pub fn cse(&mut self, roots: &[Id], prefix: &str) -> Cse {
        let order = self.postorder(roots);
        let uses = self.use_counts(&order, roots);
        let mut map: HashMap<Id, Id> = HashMap::new();
        let mut temps = Vec::new();
        for &id in &order {
            if uses[&id] < 2 || self.is_trivial(id) {
                continue;
            }
            let definition = self.substitute(id, &map);
            let temp = self.symbol(&format!("{prefix}{}", temps.len()));
            temps.push((temp, definition));
            map.insert(id, temp);
        }
        let outputs = self.substitute_all(roots, &map);
        Cse { temps, outputs }
    }

    /// How many times each node is an operand (roots count once more).
    fn use_counts(&self, order: &[Id], roots: &[Id]) -> HashMap<Id, usize> {
        let mut uses: HashMap<Id, usize> = order.iter().map(|&id| (id, 0)).collect();
        for &id in order {
            for c in self.children(id) {
                *uses.entry(c).or_insert(0) += 1;
            }
        }
        for r in roots {
            *uses.entry(*r).or_insert(0) += 1;
        }
        uses
    }

    /// Constants, symbols and negated symbols are never worth a temporary.
    fn is_trivial(&self, id: Id) -> bool {
        match self.node(id) {
            Node::Const(_) | Node::Sym(_) => true,
            Node::Mul(xs) => {
                xs.len() == 2
                    && self.as_const(xs[0]).is_some()
                    && matches!(self.node(xs[1]), Node::Sym(_))
            }
            _ => false,
        }
    }
}
