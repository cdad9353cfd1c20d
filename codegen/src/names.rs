//! Rust names of emitted items: validation of caller-given names, the const
//! name of a parameter, and readable, unique names for temporaries.
//!
//! Locals (inputs, outputs, temporaries) are lower snake case and consts upper
//! snake case, so a local can never be mistaken for a const pattern.

use std::collections::BTreeSet;

use designer::sym::{Graph, Id, Node};
use proc_macro2::{Ident, Span};

use crate::error::EmitError;

const KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern",
    "false", "fn", "for", "gen", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut",
    "pub", "ref", "return", "self", "static", "struct", "super", "trait", "true", "type", "unsafe",
    "use", "where", "while", "abstract", "become", "box", "do", "final", "macro", "override",
    "priv", "try", "typeof", "unsized", "virtual", "yield", "union",
];

pub(crate) fn ident(name: &str) -> Ident {
    Ident::new(name, Span::call_site())
}

/// Checks a caller-given local name: `[a-z_][a-z0-9_]*`, not a keyword, not `_`.
pub(crate) fn check_local(name: &str) -> Result<(), EmitError> {
    let mut chars = name.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_lowercase() || c == '_');
    let rest_ok = chars.all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
    if !(first_ok && rest_ok) || name == "_" {
        return Err(EmitError::InvalidName(
            name.to_owned(),
            "expected a lower snake case identifier ([a-z_][a-z0-9_]*)",
        ));
    }
    if KEYWORDS.contains(&name) {
        return Err(EmitError::InvalidName(name.to_owned(), "a Rust keyword"));
    }
    Ok(())
}

/// The const name of a parameter: its symbol name in upper snake case
/// (`k_e` → `K_E`, `R_core0` → `R_CORE0`).
pub fn const_name(param: &str) -> Result<String, EmitError> {
    let upper = param.to_ascii_uppercase();
    let mut chars = upper.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_uppercase() || c == '_');
    let rest_ok = chars.all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_');
    if !(first_ok && rest_ok) || upper.chars().all(|c| c == '_') || upper == "SELF" {
        return Err(EmitError::InvalidName(
            param.to_owned(),
            "parameter names must be ASCII identifiers ([A-Za-z_][A-Za-z0-9_]*)",
        ));
    }
    Ok(upper)
}

/// `perfect_tracking` → `PerfectTracking`.
pub(crate) fn camel(snake: &str) -> String {
    snake
        .split('_')
        .filter(|w| !w.is_empty())
        .map(|w| {
            let mut cs = w.chars();
            match cs.next() {
                Some(c) => c.to_ascii_uppercase().to_string() + cs.as_str(),
                None => String::new(),
            }
        })
        .collect()
}

/// Lower snake text of a symbol name for use inside a temporary's name
/// (`A_gap` → `a_gap`, `φ` → none).
fn snake_fragment(name: &str) -> Option<String> {
    let s = name.to_ascii_lowercase();
    let ok = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
    ok.then_some(s)
}

/// Longest automatic name; longer descriptions fall back to their head.
const MAX_NAME: usize = 20;

/// Allocates unique local names.
#[derive(Default)]
pub(crate) struct Namer {
    used: BTreeSet<String>,
    next_t: usize,
}

impl Namer {
    /// Reserves a caller-given name; fails if it is taken.
    pub fn reserve(&mut self, name: &str) -> Result<(), EmitError> {
        check_local(name)?;
        if !self.used.insert(name.to_owned()) {
            return Err(EmitError::DuplicateName(name.to_owned()));
        }
        Ok(())
    }

    /// A fresh name from `base` (`base`, `base_2`, …), or `tN` without a base.
    pub fn fresh(&mut self, base: Option<&str>) -> String {
        let name = match base.filter(|b| check_local(b).is_ok()) {
            Some(b) => {
                let mut name = b.to_owned();
                let mut k = 2;
                while self.used.contains(&name) {
                    name = format!("{b}_{k}");
                    k += 1;
                }
                name
            }
            None => loop {
                let name = format!("t{}", self.next_t);
                self.next_t += 1;
                if !self.used.contains(&name) {
                    break name;
                }
            },
        };
        self.used.insert(name.clone());
        name
    }
}

/// A short readable name for the value of `id`, derived from its outermost
/// operation (`sqrt_a_gap`, `inv_t3`, `phi_sq`, `ln`); `None` for sums and
/// products, which get `tN`. `local` gives the names already bound.
pub(crate) fn describe(g: &Graph, id: Id, local: &dyn Fn(Id) -> Option<String>) -> Option<String> {
    let name = match g.node(id) {
        Node::Func(f, a) => match operand(g, *a, local) {
            Some(a) => format!("{}_{a}", f.name()),
            None => f.name().to_owned(),
        },
        Node::Pow(b, e) => {
            let b = operand(g, *b, local)?;
            let e = g.as_const(*e)?;
            let power = if e.abs() == 1.0 {
                ""
            } else if e.abs() == 2.0 {
                "_sq"
            } else if e.abs() == 3.0 {
                "_cube"
            } else {
                "_pow"
            };
            match (e < 0.0, e.abs() == 0.5) {
                (false, true) => format!("sqrt_{b}"),
                (true, true) => format!("inv_sqrt_{b}"),
                (false, false) => format!("{b}{power}"),
                (true, false) => format!("inv_{b}{power}"),
            }
        }
        Node::Min(..) => "min".to_owned(),
        Node::Max(..) => "max".to_owned(),
        Node::Select(..) => "sel".to_owned(),
        _ => return None,
    };
    Some(if name.len() <= MAX_NAME {
        name
    } else {
        // keep the head (the outermost operation)
        name.split('_').next().unwrap_or("t").to_owned()
    })
}

fn operand(g: &Graph, id: Id, local: &dyn Fn(Id) -> Option<String>) -> Option<String> {
    if let Some(name) = local(id) {
        return snake_fragment(&name);
    }
    match g.node(id) {
        Node::Sym(i) => snake_fragment(g.symbol_name(*i)),
        _ => describe(g, id, local).filter(|d| d.len() <= MAX_NAME),
    }
}
