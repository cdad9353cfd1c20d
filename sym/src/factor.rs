//! Common factors out of sums: Σ cᵢ·F·Rᵢ = c·F·Σ (cᵢ/c)·Rᵢ.
//!
//! Differentiation leaves sums whose terms share factors (the quotient rule
//! gives `c·z·t⁻³·a − c·z·t⁻²·b`); written out as they are, each term pays
//! for the shared factors again. Pulling them out is what a person does by
//! hand and what makes emitted code short. The rewrite keeps the value
//! (up to rounding) and the DAG's sharing; it is deterministic.
//!
//! A factor is common when every term has its base with exponents of one
//! sign that are integers (or all equal): the one nearest zero is taken out
//! (t⁻² from t⁻² and t⁻³). A coefficient is common when every other is an
//! exact integer multiple of the smallest.

use std::collections::HashMap;

use super::{Graph, Id, Node};

/// A sum term as coefficient · Π baseᵉ.
struct Monomial {
    coefficient: f64,
    factors: Vec<(Id, f64)>,
}

impl Graph {
    /// `roots` with common factors pulled out of every sum they reach.
    pub fn factor_sums(&mut self, roots: &[Id]) -> Vec<Id> {
        let mut memo: HashMap<Id, Id> = HashMap::new();
        for id in self.postorder(roots) {
            let rebuilt = self.rebuild(id, &memo);
            let new = self.factor_sum(rebuilt);
            memo.insert(id, new);
        }
        roots.iter().map(|r| memo[r]).collect()
    }

    /// One sum with its common factors out (anything else unchanged).
    fn factor_sum(&mut self, s: Id) -> Id {
        let Node::Add(terms) = self.node(s).clone() else {
            return s;
        };
        if terms.iter().any(|&t| self.as_const(t).is_some()) {
            return s; // a constant term shares nothing
        }
        let monomials: Vec<Monomial> = terms.iter().map(|&t| self.monomial(t)).collect();
        let common = common_factors(&monomials);
        let scale = common_coefficient(&monomials);
        if common.is_empty() && scale == 1.0 {
            return s;
        }
        let mut inner = Vec::with_capacity(monomials.len());
        for m in &monomials {
            let mut factors = vec![self.constant(m.coefficient / scale)];
            for &(base, e) in &m.factors {
                let taken = common.iter().find(|c| c.0 == base).map_or(0.0, |c| c.1);
                let power = self.constant(e - taken);
                factors.push(self.pow(base, power));
            }
            inner.push(self.product(&factors));
        }
        let mut outer = vec![self.constant(scale), self.sum(&inner)];
        for &(base, e) in &common {
            let power = self.constant(e);
            outer.push(self.pow(base, power));
        }
        self.product(&outer)
    }

    fn monomial(&mut self, t: Id) -> Monomial {
        let (coefficient, rest) = self.split_coefficient(t);
        let operands = match self.node(rest) {
            Node::Mul(xs) => xs.to_vec(),
            _ => vec![rest],
        };
        let factors = operands
            .into_iter()
            .map(|x| match self.node(x) {
                Node::Pow(b, e) => match self.as_const(*e) {
                    Some(e) => (*b, e),
                    None => (x, 1.0),
                },
                _ => (x, 1.0),
            })
            .collect();
        Monomial {
            coefficient,
            factors,
        }
    }
}

/// (base, exponent) present in every term, exponent nearest zero, in the
/// order of the first term.
fn common_factors(terms: &[Monomial]) -> Vec<(Id, f64)> {
    let Some((first, rest)) = terms.split_first() else {
        return Vec::new();
    };
    let mut common = Vec::new();
    for &(base, e0) in &first.factors {
        let mut taken = e0;
        let mut shared = true;
        for t in rest {
            match t.factors.iter().find(|f| f.0 == base) {
                Some(&(_, e)) if e == e0 => {}
                Some(&(_, e)) if e.signum() == e0.signum() && is_integer(e) && is_integer(e0) => {
                    if e.abs() < taken.abs() {
                        taken = e;
                    }
                }
                _ => {
                    shared = false;
                    break;
                }
            }
        }
        if shared {
            common.push((base, taken));
        }
    }
    common
}

/// The smallest coefficient's magnitude when all others are exact integer
/// multiples of it, else 1.
fn common_coefficient(terms: &[Monomial]) -> f64 {
    let smallest = terms
        .iter()
        .map(|t| t.coefficient.abs())
        .fold(f64::INFINITY, f64::min);
    if !smallest.is_finite() || smallest == 0.0 || smallest == 1.0 {
        return 1.0;
    }
    let exact_multiple = |c: f64| {
        let k = c / smallest;
        is_integer(k) && k * smallest == c
    };
    if terms.iter().all(|t| exact_multiple(t.coefficient)) {
        smallest
    } else {
        1.0
    }
}

fn is_integer(x: f64) -> bool {
    x.fract() == 0.0 && x.abs() <= 64.0
}
