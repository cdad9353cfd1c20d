//! The expression layer: `Copy` handles with arithmetic operators, so that
//! model code reads like the equation it cites, e.g. a clamped derivative:
//! `let dbc = (1.0 + MU0 * (1.0 - alpha) * dmc).max(eps);`.
//!
//! Every operator and method calls the one smart constructor of `build.rs`
//! that the same step written out with `Graph` calls (`a - b` is
//! [`Graph::sub`], `2.0 * x` is [`Graph::constant`] then [`Graph::mul`]), so
//! both spellings build the same nodes in the same order: same ids, hence the
//! same printed and generated code.
//!
//! **Construction order.** Node ids follow construction order, and the order
//! of sums, products and CSE temporaries follows the ids, so byte-identical
//! generated code needs a fixed order. The layer adds none of its own: Rust
//! evaluates operands left to right (the receiver of a method first), then
//! runs the operator; an `f64` operand becomes a constant node when its
//! operator runs, after both operands.
//!
//! Handles borrow a [`Scope`] (the graph in a `RefCell`) lent by
//! [`Graph::with`]; they cannot outlive it. Each operation borrows the graph
//! only while it runs.

use std::cell::RefCell;
use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::graph::{Graph, Id};

/// A graph lent to expression handles: see [`Graph::with`].
pub struct Scope {
    graph: RefCell<Graph>,
}

/// An expression: a node of the graph of a [`Scope`], with operators.
#[derive(Clone, Copy)]
pub struct E<'s> {
    scope: &'s Scope,
    id: Id,
}

/// What an operator or method takes beside an [`E`]: another expression, or
/// an `f64` (a constant node, interned when the operation runs).
pub trait Operand<'s>: Copy {
    /// The node of this operand in `scope`'s graph `g`.
    fn node(self, scope: &Scope, g: &mut Graph) -> Id;
}

impl<'s> Operand<'s> for E<'s> {
    fn node(self, scope: &Scope, _: &mut Graph) -> Id {
        assert!(
            std::ptr::eq(self.scope, scope),
            "expressions of two different graphs combined"
        );
        self.id
    }
}

impl Operand<'_> for f64 {
    fn node(self, _: &Scope, g: &mut Graph) -> Id {
        g.constant(self)
    }
}

impl Graph {
    /// Lends the graph to expression handles for the duration of `f`:
    /// `let r = g.with(|s| { let [z, a] = s.exprs([z, a]); (z / (MU0 * a)).id() });`.
    /// The graph is back in `self` when `f` returns (or panics).
    pub fn with<R>(&mut self, f: impl FnOnce(&Scope) -> R) -> R {
        let lent = Lent {
            scope: Scope::new(std::mem::take(self)),
            home: self,
        };
        f(&lent.scope)
    }
}

/// Puts the lent graph back on drop, so a panic in the closure loses nothing.
struct Lent<'g> {
    home: &'g mut Graph,
    scope: Scope,
}

impl Drop for Lent<'_> {
    fn drop(&mut self) {
        *self.home = std::mem::take(self.scope.graph.get_mut());
    }
}

impl Scope {
    /// A scope owning `graph` (see also [`Graph::with`]).
    pub fn new(graph: Graph) -> Self {
        Scope {
            graph: RefCell::new(graph),
        }
    }

    pub fn into_graph(self) -> Graph {
        self.graph.into_inner()
    }

    /// The handle of an existing node.
    pub fn expr(&self, id: Id) -> E<'_> {
        E { scope: self, id }
    }

    /// Handles of existing nodes: `let [z, phi] = s.exprs([z, phi]);`.
    pub fn exprs<const N: usize>(&self, ids: [Id; N]) -> [E<'_>; N] {
        ids.map(|id| self.expr(id))
    }

    pub fn constant(&self, value: f64) -> E<'_> {
        self.make(|g| g.constant(value))
    }

    /// The symbol called `name` (created on first use).
    pub fn symbol(&self, name: &str) -> E<'_> {
        self.make(|g| g.symbol(name))
    }

    /// Σ terms, as one n-ary [`Graph::sum`] (not a chain of binary sums).
    pub fn sum(&self, terms: &[E<'_>]) -> E<'_> {
        let ids = self.ids(terms);
        self.make(|g| g.sum(&ids))
    }

    /// Π factors, as one n-ary [`Graph::product`].
    pub fn product(&self, factors: &[E<'_>]) -> E<'_> {
        let ids = self.ids(factors);
        self.make(|g| g.product(&ids))
    }

    /// Runs `f` on the graph itself, for what the layer does not cover. `f`
    /// must not use handles: the graph is borrowed while it runs.
    pub fn graph<R>(&self, f: impl FnOnce(&mut Graph) -> R) -> R {
        f(&mut self.graph.borrow_mut())
    }

    fn make(&self, f: impl FnOnce(&mut Graph) -> Id) -> E<'_> {
        let id = self.graph(f);
        self.expr(id)
    }

    fn ids(&self, es: &[E<'_>]) -> Vec<Id> {
        self.graph(|g| es.iter().map(|&e| e.node(self, g)).collect())
    }
}

impl<'s> E<'s> {
    /// The node, to leave the layer.
    pub fn id(self) -> Id {
        self.id
    }

    /// The scope of this expression, for constants and symbols in helpers
    /// that take only expressions.
    pub fn scope(self) -> &'s Scope {
        self.scope
    }

    fn unary(self, f: impl FnOnce(&mut Graph, Id) -> Id) -> Self {
        self.scope.make(|g| f(g, self.id))
    }

    fn binary(self, other: impl Operand<'s>, f: impl FnOnce(&mut Graph, Id, Id) -> Id) -> Self {
        self.scope.make(|g| {
            let b = other.node(self.scope, g);
            f(g, self.id, b)
        })
    }

    pub fn sqrt(self) -> Self {
        self.unary(Graph::sqrt)
    }

    pub fn exp(self) -> Self {
        self.unary(Graph::exp)
    }

    pub fn ln(self) -> Self {
        self.unary(Graph::ln)
    }

    pub fn abs(self) -> Self {
        self.unary(Graph::abs)
    }

    /// sign(0) = 0.
    pub fn sign(self) -> Self {
        self.unary(Graph::sign)
    }

    pub fn tanh(self) -> Self {
        self.unary(Graph::tanh)
    }

    pub fn coth(self) -> Self {
        self.unary(Graph::coth)
    }

    /// 1/self, as `self^-1`.
    pub fn recip(self) -> Self {
        self.unary(Graph::recip)
    }

    pub fn powi(self, n: i32) -> Self {
        self.unary(|g, a| g.powi(a, n))
    }

    /// self^exponent, e.g. `x.pow(0.5)` or `x.pow(y)`.
    pub fn pow(self, exponent: impl Operand<'s>) -> Self {
        self.binary(exponent, Graph::pow)
    }

    pub fn max(self, other: impl Operand<'s>) -> Self {
        self.binary(other, Graph::max)
    }

    pub fn min(self, other: impl Operand<'s>) -> Self {
        self.binary(other, Graph::min)
    }

    /// `a` where self ≥ 0, else `b` ([`Graph::select`] with self as the
    /// condition): `(x.abs() - 0.1).if_nonneg(closed_form, series)`.
    pub fn if_nonneg(self, a: impl Operand<'s>, b: impl Operand<'s>) -> Self {
        self.scope.make(|g| {
            let a = a.node(self.scope, g);
            let b = b.node(self.scope, g);
            g.select(self.id, a, b)
        })
    }

    /// `pieces[k]` on `[breaks[k-1], breaks[k])` of self ([`Graph::piecewise`]).
    pub fn piecewise(self, breaks: &[f64], pieces: &[E<'s>]) -> Self {
        let pieces = self.scope.ids(pieces);
        self.unary(|g, x| g.piecewise(x, breaks, &pieces))
    }

    /// ∂self/∂x, where `x` is a symbol.
    pub fn diff(self, x: E<'s>) -> Self {
        self.binary(x, Graph::diff)
    }
}

impl<'s, R: Operand<'s>> Add<R> for E<'s> {
    type Output = E<'s>;
    fn add(self, rhs: R) -> E<'s> {
        self.binary(rhs, Graph::add)
    }
}

impl<'s, R: Operand<'s>> Sub<R> for E<'s> {
    type Output = E<'s>;
    fn sub(self, rhs: R) -> E<'s> {
        self.binary(rhs, Graph::sub)
    }
}

impl<'s, R: Operand<'s>> Mul<R> for E<'s> {
    type Output = E<'s>;
    fn mul(self, rhs: R) -> E<'s> {
        self.binary(rhs, Graph::mul)
    }
}

impl<'s, R: Operand<'s>> Div<R> for E<'s> {
    type Output = E<'s>;
    fn div(self, rhs: R) -> E<'s> {
        self.binary(rhs, Graph::div)
    }
}

impl<'s> Neg for E<'s> {
    type Output = E<'s>;
    fn neg(self) -> E<'s> {
        self.unary(Graph::neg)
    }
}

/// `c ∘ e` for an `f64` on the left: the constant node, then the operation.
fn constant_first<'s>(c: f64, e: E<'s>, f: impl FnOnce(&mut Graph, Id, Id) -> Id) -> E<'s> {
    e.scope.make(|g| {
        let c = g.constant(c);
        f(g, c, e.id)
    })
}

impl<'s> Add<E<'s>> for f64 {
    type Output = E<'s>;
    fn add(self, rhs: E<'s>) -> E<'s> {
        constant_first(self, rhs, Graph::add)
    }
}

impl<'s> Sub<E<'s>> for f64 {
    type Output = E<'s>;
    fn sub(self, rhs: E<'s>) -> E<'s> {
        constant_first(self, rhs, Graph::sub)
    }
}

impl<'s> Mul<E<'s>> for f64 {
    type Output = E<'s>;
    fn mul(self, rhs: E<'s>) -> E<'s> {
        constant_first(self, rhs, Graph::mul)
    }
}

impl<'s> Div<E<'s>> for f64 {
    type Output = E<'s>;
    fn div(self, rhs: E<'s>) -> E<'s> {
        constant_first(self, rhs, Graph::div)
    }
}

/// Same graph and same node (hash-consing makes that expression equality).
impl PartialEq for E<'_> {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.scope, other.scope) && self.id == other.id
    }
}

impl Eq for E<'_> {}

/// The infix text of [`Graph::display`].
impl fmt::Display for E<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.scope.graph(|g| g.display(self.id)))
    }
}

impl fmt::Debug for E<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?} = {}", self.id, self)
    }
}
