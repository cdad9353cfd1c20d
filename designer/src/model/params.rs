//! Named model parameters: symbols that stay symbolic in derivations (so
//! generated code can keep them as named consts, and identification can treat
//! them as unknowns) and carry the value of the description.

use std::collections::HashMap;

use crate::description::schema;
use crate::sym::{Graph, Id};

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Params {
    entries: Vec<(String, Id, f64)>,
}

impl Params {
    /// Registers the parameter `name` with `value` and returns its symbol.
    pub fn add(&mut self, g: &mut Graph, name: &str, value: f64) -> Id {
        let id = g.symbol(name);
        match self.entries.iter_mut().find(|(n, _, _)| n == name) {
            Some(entry) => entry.2 = value,
            None => self.entries.push((name.to_owned(), id, value)),
        }
        id
    }

    /// Registers the description key `path` (`coil.resistance`) under its
    /// schema symbol (`R`) with `value` and returns the symbol.
    pub fn key(&mut self, g: &mut Graph, path: &str, value: f64) -> Id {
        let key = schema::key(path);
        let symbol = key
            .symbol
            .unwrap_or_else(|| unreachable!("`{path}` is not a model parameter in the schema"));
        self.add(g, symbol, value)
    }

    pub fn iter(&self) -> impl Iterator<Item = (&str, Id, f64)> {
        self.entries.iter().map(|(n, id, v)| (n.as_str(), *id, *v))
    }

    pub fn value(&self, name: &str) -> Option<f64> {
        self.entries.iter().find(|(n, _, _)| n == name).map(|e| e.2)
    }

    pub fn symbol(&self, name: &str) -> Option<Id> {
        self.entries.iter().find(|(n, _, _)| n == name).map(|e| e.1)
    }

    /// Substitution map symbol → constant value, for every parameter.
    pub fn bindings(&self, g: &mut Graph) -> HashMap<Id, Id> {
        self.entries
            .iter()
            .map(|(_, id, v)| (*id, g.constant(*v)))
            .collect()
    }
}
