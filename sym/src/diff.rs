//! Symbolic differentiation and substitution.
//!
//! `diff` applies the textbook rules node by node with memoisation, so the
//! derivative of a DAG is a DAG of comparable size (shared subterms are
//! differentiated once). Piecewise nodes differentiate branch-wise:
//! `d select(c, a, b) = select(c, da, db)`, `d min(a, b) = select(b − a, da, db)`.

use std::collections::HashMap;

use super::graph::{Func, Graph, Id, Node};

impl Graph {
    /// ∂e/∂x, where `x` is a symbol node.
    pub fn diff(&mut self, e: Id, x: Id) -> Id {
        assert!(
            matches!(self.node(x), Node::Sym(_)),
            "diff: the variable must be a symbol"
        );
        let mut memo = HashMap::new();
        for id in self.postorder(&[e]) {
            let d = self.diff_node(id, x, &memo);
            memo.insert(id, d);
        }
        memo[&e]
    }

    /// The `order`-th derivative ∂ⁿe/∂xⁿ.
    pub fn diff_n(&mut self, e: Id, x: Id, order: usize) -> Id {
        (0..order).fold(e, |acc, _| self.diff(acc, x))
    }

    /// Gradient of `e` with respect to each of `xs`.
    pub fn gradient(&mut self, e: Id, xs: &[Id]) -> Vec<Id> {
        xs.iter().map(|&x| self.diff(e, x)).collect()
    }

    /// Jacobian rows ∂fᵢ/∂xⱼ.
    pub fn jacobian(&mut self, fs: &[Id], xs: &[Id]) -> Vec<Vec<Id>> {
        fs.iter().map(|&f| self.gradient(f, xs)).collect()
    }

    fn diff_node(&mut self, id: Id, x: Id, memo: &HashMap<Id, Id>) -> Id {
        let d = |c: Id| memo[&c];
        match self.node(id).clone() {
            Node::Const(_) => self.zero(),
            Node::Sym(_) => {
                if id == x {
                    self.one()
                } else {
                    self.zero()
                }
            }
            Node::Add(xs) => {
                let ds: Vec<Id> = xs.iter().map(|&t| d(t)).collect();
                self.sum(&ds)
            }
            Node::Mul(xs) => self.diff_product(&xs, memo),
            Node::Pow(b, e) => self.diff_pow(id, b, e, d(b), d(e)),
            Node::Func(f, a) => {
                let outer = self.func_derivative(f, id, a);
                self.mul(outer, d(a))
            }
            Node::Min(a, b) => {
                let c = self.sub(b, a);
                self.select(c, d(a), d(b))
            }
            Node::Max(a, b) => {
                let c = self.sub(a, b);
                self.select(c, d(a), d(b))
            }
            Node::Select(c, a, b) => self.select(c, d(a), d(b)),
        }
    }

    /// Product rule: Σᵢ dfᵢ · Πⱼ≠ᵢ fⱼ.
    fn diff_product(&mut self, xs: &[Id], memo: &HashMap<Id, Id>) -> Id {
        let zero = self.zero();
        let mut terms = Vec::new();
        for (i, &fi) in xs.iter().enumerate() {
            let dfi = memo[&fi];
            if dfi == zero {
                continue;
            }
            let mut factors: Vec<Id> = xs
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, &f)| f)
                .collect();
            factors.push(dfi);
            terms.push(self.product(&factors));
        }
        self.sum(&terms)
    }

    /// d(b^e) = e·b^(e−1)·db when e is constant in x, else b^e·(de·ln b + e·db/b).
    fn diff_pow(&mut self, id: Id, b: Id, e: Id, db: Id, de: Id) -> Id {
        let zero = self.zero();
        if de == zero {
            if db == zero {
                return zero;
            }
            let m1 = self.constant(-1.0);
            let e1 = self.add(e, m1);
            let p = self.pow(b, e1);
            return self.product(&[e, p, db]);
        }
        let lnb = self.ln(b);
        let t1 = self.mul(de, lnb);
        let rb = self.recip(b);
        let t2 = self.product(&[e, db, rb]);
        let inner = self.add(t1, t2);
        self.mul(id, inner)
    }

    /// f'(a), given the node `fa` = f(a).
    fn func_derivative(&mut self, f: Func, fa: Id, a: Id) -> Id {
        match f {
            Func::Sqrt => {
                let r = self.recip(fa);
                self.scale(0.5, r)
            }
            Func::Exp => fa,
            Func::Ln => self.recip(a),
            Func::Abs => self.sign(a),
            Func::Sign => self.zero(),
            // 1 − tanh², 1 − coth²
            Func::Tanh | Func::Coth => {
                let sq = self.powi(fa, 2);
                let one = self.one();
                self.sub(one, sq)
            }
        }
    }

    /// Replaces nodes by others (typically symbols by values or expressions),
    /// rebuilding everything above them through the simplifying constructors.
    pub fn substitute(&mut self, e: Id, map: &HashMap<Id, Id>) -> Id {
        let mut memo: HashMap<Id, Id> = HashMap::new();
        for id in self.postorder(&[e]) {
            let new = match map.get(&id) {
                Some(&r) => r,
                None => self.rebuild(id, &memo),
            };
            memo.insert(id, new);
        }
        memo[&e]
    }

    /// Substitutes several roots at once (shared work, consistent results).
    pub fn substitute_all(&mut self, roots: &[Id], map: &HashMap<Id, Id>) -> Vec<Id> {
        let mut memo: HashMap<Id, Id> = HashMap::new();
        for id in self.postorder(roots) {
            let new = match map.get(&id) {
                Some(&r) => r,
                None => self.rebuild(id, &memo),
            };
            memo.insert(id, new);
        }
        roots.iter().map(|r| memo[r]).collect()
    }

    /// Rebuilds `id` from the (possibly replaced) images of its children.
    pub(crate) fn rebuild(&mut self, id: Id, memo: &HashMap<Id, Id>) -> Id {
        let m = |c: &Id| memo[c];
        match self.node(id).clone() {
            Node::Const(_) | Node::Sym(_) => id,
            Node::Add(xs) => {
                let ys: Vec<Id> = xs.iter().map(m).collect();
                self.sum(&ys)
            }
            Node::Mul(xs) => {
                let ys: Vec<Id> = xs.iter().map(m).collect();
                self.product(&ys)
            }
            Node::Pow(b, e) => self.pow(m(&b), m(&e)),
            Node::Func(f, a) => self.func(f, m(&a)),
            Node::Min(a, b) => self.min(m(&a), m(&b)),
            Node::Max(a, b) => self.max(m(&a), m(&b)),
            Node::Select(c, a, b) => self.select(m(&c), m(&a), m(&b)),
        }
    }
}
