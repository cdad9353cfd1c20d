//! Smart constructors: the only way nodes are made, and where simplification
//! lives. Every constructor returns a canonical node:
//!
//! - constants are folded (when the result is finite);
//! - sums and products are flattened, their operands sorted (constants first,
//!   then symbols, then compound nodes, each by id) and like terms collected
//!   (`2·x + 3·x → 5·x`, `x²·x⁻¹ → x`);
//! - identities: `x + 0`, `x·1`, `x·0 → 0`, `x¹`, `x⁰ → 1`, `(x^a)^n → x^(a·n)`
//!   for integer n, `(a·b)^n → aⁿ·bⁿ` for integer n, `select(c, a, a) → a`.
//!
//! Canonical forms make equal expressions share one node, which is what makes
//! hash-consing an effective common-subexpression eliminator.

use std::collections::BTreeMap;

use super::graph::{Func, Graph, Id, Node};

impl Graph {
    pub fn zero(&mut self) -> Id {
        self.constant(0.0)
    }

    pub fn one(&mut self) -> Id {
        self.constant(1.0)
    }

    pub fn add(&mut self, a: Id, b: Id) -> Id {
        self.sum(&[a, b])
    }

    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        let nb = self.neg(b);
        self.sum(&[a, nb])
    }

    pub fn mul(&mut self, a: Id, b: Id) -> Id {
        self.product(&[a, b])
    }

    pub fn div(&mut self, a: Id, b: Id) -> Id {
        let rb = self.recip(b);
        self.product(&[a, rb])
    }

    pub fn neg(&mut self, a: Id) -> Id {
        let m1 = self.constant(-1.0);
        self.product(&[m1, a])
    }

    pub fn recip(&mut self, a: Id) -> Id {
        let m1 = self.constant(-1.0);
        self.pow(a, m1)
    }

    /// `c·a` for a numeric `c`.
    pub fn scale(&mut self, c: f64, a: Id) -> Id {
        let c = self.constant(c);
        self.product(&[c, a])
    }

    pub fn powi(&mut self, a: Id, n: i32) -> Id {
        let n = self.constant(f64::from(n));
        self.pow(a, n)
    }

    pub fn sqrt(&mut self, a: Id) -> Id {
        self.func(Func::Sqrt, a)
    }

    pub fn exp(&mut self, a: Id) -> Id {
        self.func(Func::Exp, a)
    }

    pub fn ln(&mut self, a: Id) -> Id {
        self.func(Func::Ln, a)
    }

    pub fn abs(&mut self, a: Id) -> Id {
        self.func(Func::Abs, a)
    }

    pub fn sign(&mut self, a: Id) -> Id {
        self.func(Func::Sign, a)
    }

    pub fn tanh(&mut self, a: Id) -> Id {
        self.func(Func::Tanh, a)
    }

    pub fn coth(&mut self, a: Id) -> Id {
        self.func(Func::Coth, a)
    }

    /// Sort key: constants, then symbols, then compound nodes; each by id.
    fn rank(&self, id: Id) -> (u8, Id) {
        let class = match self.node(id) {
            Node::Const(_) => 0,
            Node::Sym(_) => 1,
            _ => 2,
        };
        (class, id)
    }

    /// Σ terms.
    pub fn sum(&mut self, terms: &[Id]) -> Id {
        let mut constant = 0.0;
        // rest-of-term → accumulated coefficient; BTreeMap keeps the order deterministic.
        let mut coefficients: BTreeMap<Id, f64> = BTreeMap::new();
        let mut flat = Vec::with_capacity(terms.len());
        self.flatten_sum(terms, &mut flat);
        for t in flat {
            if let Some(c) = self.as_const(t) {
                constant += c;
                continue;
            }
            let (c, rest) = self.split_coefficient(t);
            *coefficients.entry(rest).or_insert(0.0) += c;
        }
        let mut out = Vec::with_capacity(coefficients.len() + 1);
        for (rest, c) in coefficients {
            if c != 0.0 {
                let term = if c == 1.0 { rest } else { self.scale(c, rest) };
                out.push(term);
            }
        }
        if constant != 0.0 || out.is_empty() {
            let c = self.constant(constant);
            out.push(c);
        }
        self.finish_nary(out, true)
    }

    fn flatten_sum(&self, terms: &[Id], flat: &mut Vec<Id>) {
        for &t in terms {
            match self.node(t) {
                Node::Add(xs) => flat.extend(xs.iter().copied()),
                _ => flat.push(t),
            }
        }
    }

    /// `c·rest` decomposition of a term: `Mul([Const c, …])` → (c, Π…).
    pub(crate) fn split_coefficient(&mut self, t: Id) -> (f64, Id) {
        if let Node::Mul(xs) = self.node(t) {
            if let Some(c) = self.as_const(xs[0]) {
                let rest: Vec<Id> = xs[1..].to_vec();
                let rest = if rest.len() == 1 {
                    rest[0]
                } else {
                    self.intern(Node::Mul(rest.into()))
                };
                return (c, rest);
            }
        }
        (1.0, t)
    }

    /// Π factors.
    pub fn product(&mut self, factors: &[Id]) -> Id {
        let mut flat = Vec::with_capacity(factors.len());
        for &f in factors {
            match self.node(f) {
                Node::Mul(xs) => flat.extend(xs.iter().copied()),
                _ => flat.push(f),
            }
        }
        let mut coefficient = 1.0;
        // base → exponent terms
        let mut exponents: BTreeMap<Id, Vec<Id>> = BTreeMap::new();
        for f in flat {
            if let Some(c) = self.as_const(f) {
                coefficient *= c;
                continue;
            }
            let (base, exponent) = match self.node(f) {
                Node::Pow(b, e) => (*b, *e),
                _ => (f, self.one()),
            };
            exponents.entry(base).or_default().push(exponent);
        }
        if coefficient == 0.0 {
            return self.zero();
        }
        let mut out = Vec::with_capacity(exponents.len() + 1);
        for (base, es) in exponents {
            let e = if es.len() == 1 { es[0] } else { self.sum(&es) };
            let factor = self.pow(base, e);
            match self.as_const(factor) {
                Some(c) => coefficient *= c,
                None => match self.node(factor) {
                    // pow may distribute over a product: re-flatten.
                    Node::Mul(xs) => {
                        let xs = xs.to_vec();
                        for x in xs {
                            match self.as_const(x) {
                                Some(c) => coefficient *= c,
                                None => out.push(x),
                            }
                        }
                    }
                    _ => out.push(factor),
                },
            }
        }
        if !coefficient.is_finite() {
            // Do not fold to a non-finite constant; keep the factors apart.
            coefficient = 1.0;
        }
        if coefficient == 0.0 {
            return self.zero();
        }
        if coefficient != 1.0 || out.is_empty() {
            let c = self.constant(coefficient);
            out.push(c);
        }
        self.finish_nary(out, false)
    }

    fn finish_nary(&mut self, mut ops: Vec<Id>, is_sum: bool) -> Id {
        if ops.len() == 1 {
            return ops[0];
        }
        ops.sort_by_key(|&id| self.rank(id));
        let ops: Box<[Id]> = ops.into();
        self.intern(if is_sum {
            Node::Add(ops)
        } else {
            Node::Mul(ops)
        })
    }

    /// `base ^ exponent`.
    pub fn pow(&mut self, base: Id, exponent: Id) -> Id {
        let e = self.as_const(exponent);
        match e {
            Some(0.0) => return self.one(),
            Some(1.0) => return base,
            _ => {}
        }
        if let (Some(b), Some(e)) = (self.as_const(base), e) {
            let v = if e.fract() == 0.0 && e.abs() < 64.0 {
                b.powi(e as i32)
            } else {
                b.powf(e)
            };
            if v.is_finite() {
                return self.constant(v);
            }
        }
        if let Some(b) = self.as_const(base) {
            if b == 1.0 {
                return self.one();
            }
        }
        if let Some(e) = e.filter(|e| e.fract() == 0.0) {
            match self.node(base).clone() {
                // (x^a)^n = x^(a·n) for integer n
                Node::Pow(b, a) => {
                    let n = self.constant(e);
                    let an = self.mul(a, n);
                    return self.pow(b, an);
                }
                // (Π xᵢ)^n = Π xᵢ^n for integer n
                Node::Mul(xs) => {
                    let n = self.constant(e);
                    let factors: Vec<Id> = xs.iter().map(|&x| self.pow(x, n)).collect();
                    return self.product(&factors);
                }
                _ => {}
            }
        }
        self.intern(Node::Pow(base, exponent))
    }

    pub fn func(&mut self, f: Func, a: Id) -> Id {
        if let Some(x) = self.as_const(a) {
            let v = f.apply(x);
            if v.is_finite() {
                return self.constant(v);
            }
        }
        match (f, self.node(a)) {
            (Func::Abs, Node::Func(Func::Abs | Func::Sqrt | Func::Exp, _)) => return a,
            (Func::Sign, Node::Func(Func::Sign, _)) => return a,
            (Func::Ln, Node::Func(Func::Exp, x)) => return *x,
            _ => {}
        }
        self.intern(Node::Func(f, a))
    }

    pub fn min(&mut self, a: Id, b: Id) -> Id {
        if a == b {
            return a;
        }
        if let (Some(x), Some(y)) = (self.as_const(a), self.as_const(b)) {
            return self.constant(x.min(y));
        }
        self.intern(Node::Min(a, b))
    }

    pub fn max(&mut self, a: Id, b: Id) -> Id {
        if a == b {
            return a;
        }
        if let (Some(x), Some(y)) = (self.as_const(a), self.as_const(b)) {
            return self.constant(x.max(y));
        }
        self.intern(Node::Max(a, b))
    }

    /// `a` where `cond ≥ 0`, else `b`.
    pub fn select(&mut self, cond: Id, a: Id, b: Id) -> Id {
        if a == b {
            return a;
        }
        if let Some(c) = self.as_const(cond) {
            return if c >= 0.0 { a } else { b };
        }
        self.intern(Node::Select(cond, a, b))
    }

    /// Piecewise definition over breakpoints: `pieces[k]` holds on
    /// `[breaks[k-1], breaks[k])`; `pieces.len() == breaks.len() + 1`.
    pub fn piecewise(&mut self, x: Id, breaks: &[f64], pieces: &[Id]) -> Id {
        assert_eq!(
            pieces.len(),
            breaks.len() + 1,
            "piecewise: one more piece than breakpoints"
        );
        let mut acc = pieces[pieces.len() - 1];
        for k in (0..breaks.len()).rev() {
            let c = self.constant(-breaks[k]);
            let cond = self.add(x, c);
            acc = self.select(cond, acc, pieces[k]);
        }
        acc
    }

    /// Numeric value of an expression under an assignment of symbols
    /// (tree evaluation with memoisation: for tests and one-off values; use a
    /// [`super::Tape`] for repeated evaluation).
    pub fn eval(&self, root: Id, value_of: &dyn Fn(&str) -> f64) -> f64 {
        let order = self.postorder(&[root]);
        let mut values = vec![0.0; self.len()];
        for id in order {
            let v = match self.node(id) {
                Node::Const(bits) => f64::from_bits(*bits),
                Node::Sym(i) => value_of(self.symbol_name(*i)),
                Node::Add(xs) => xs.iter().map(|x| values[x.index()]).sum(),
                Node::Mul(xs) => xs.iter().map(|x| values[x.index()]).product(),
                Node::Pow(b, e) => pow_value(values[b.index()], values[e.index()]),
                Node::Func(f, a) => f.apply(values[a.index()]),
                Node::Min(a, b) => values[a.index()].min(values[b.index()]),
                Node::Max(a, b) => values[a.index()].max(values[b.index()]),
                Node::Select(c, a, b) => {
                    if values[c.index()] >= 0.0 {
                        values[a.index()]
                    } else {
                        values[b.index()]
                    }
                }
            };
            values[id.index()] = v;
        }
        values[root.index()]
    }
}

/// `b^e` with the integer fast path used everywhere (evaluator, tape, codegen).
pub fn pow_value(b: f64, e: f64) -> f64 {
    if e.fract() == 0.0 && e.abs() <= 64.0 {
        b.powi(e as i32)
    } else if e == 0.5 {
        b.sqrt()
    } else {
        b.powf(e)
    }
}
