//! One model parameter as the emitters see it: its symbol name, its symbol
//! node and its value. Emitted code refers to it by the const name of
//! [`crate::const_name`] (`k_e` → `K_E`), never by its value.

use designer::sym::Id;

/// One parameter (e.g. from `model.params.iter().map(Param::from)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param<'a> {
    /// The symbol's name in the graph (`k_e`).
    pub name: &'a str,
    /// The symbol node.
    pub symbol: Id,
    pub value: f64,
}

impl<'a> From<(&'a str, Id, f64)> for Param<'a> {
    /// From the `(name, symbol, value)` items of `designer::model::Params::iter`.
    fn from((name, symbol, value): (&'a str, Id, f64)) -> Self {
        Param {
            name,
            symbol,
            value,
        }
    }
}
