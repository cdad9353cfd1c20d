//! Lowering of one expression to Rust tokens, with the arithmetic a person
//! would write:
//!
//! - sums with negative terms as subtractions, a positive term first and the
//!   constant last: `a + b - 2.0 * c - 1.5`;
//! - products with negative integer powers as a division, parameter-only
//!   factors first so that they fold to one constant: `c * K / M * a / (b * d)`;
//! - x² and x³ as `x * x`, `x * x * x` (the plan binds x first), other integer
//!   powers up to 64 as `Real::powi(x, n)`, x^½ as `Real::sqrt(x)`, x⁻¹ as
//!   `1.0 / x`, x⁻² and x⁻³ through the `let`s of x⁻¹ and x⁻² when there
//!   are any (`inv_x * inv_x`), anything else as `Real::powf(x, e)`;
//! - `select(c, a, b)` as `if c >= 0.0 { a } else { b }`;
//! - functions, `min`, `max` through `reldesign_runtime::math::Real`, with
//!   sign(0) = 0 (`Real::signum0`);
//! - constants that are multiples of μ0, and Z_EPS, by name: `0.5 / MU0`
//!   (`physical.rs`).
//!
//! Parentheses come from operator precedence, never from the tree shape.
//! Bound nodes (inputs, parameter consts, earlier `let`s) print as names.

use std::collections::{HashMap, HashSet};

use designer::sym::{Func, Graph, Id, Node};
use proc_macro2::TokenStream;
use quote::quote;

use crate::error::EmitError;
use crate::float::Scalar;
use crate::names::ident;
use crate::physical::{recognise, Constant, Named};

/// Precedence of the printed form (higher binds tighter).
const IF: u8 = 0;
const SUM: u8 = 1;
const PRODUCT: u8 = 2;
const UNARY: u8 = 3;
const ATOM: u8 = 4;

/// Integer exponents up to this magnitude use multiplication / `powi`
/// (as `designer::sym::pow_value`).
const MAX_POWI: f64 = 64.0;

struct Lowered {
    tokens: TokenStream,
    prec: u8,
    /// Starts with a unary minus (so it is never negated again without parentheses).
    negated: bool,
}

impl Lowered {
    fn new(tokens: TokenStream, prec: u8) -> Self {
        Lowered {
            tokens,
            prec,
            negated: false,
        }
    }

    /// The tokens, parenthesised unless they bind at least as tight as `min`.
    fn at(self, min: u8) -> TokenStream {
        let t = self.tokens;
        if self.prec >= min {
            t
        } else {
            quote!((#t))
        }
    }
}

pub(crate) struct Lowerer<'a> {
    pub graph: &'a Graph,
    pub bound: &'a HashMap<Id, String>,
    pub float: Scalar,
    /// Set when a `Real::…` call was emitted (the function then imports it).
    pub uses_real: bool,
    /// Set when a literal has more digits than the f32 instantiation of a
    /// macro holds (`Scalar::excessive`).
    pub excessive: bool,
    /// Parameter symbols (their consts are compile-time values).
    pub params: &'a HashSet<Id>,
    /// Memo of [`Lowerer::is_static`].
    pub statics: HashMap<Id, bool>,
    /// `let`s emitted so far (a node may be written through them).
    pub defined: HashSet<Id>,
    /// Physical constants that may be written by name (`physical.rs`).
    pub available: Vec<&'static Constant>,
    /// Those written by name so far.
    pub named: Vec<&'static Constant>,
}

impl Lowerer<'_> {
    /// The right-hand side of `let … = ` for `id` (not looked up as bound).
    pub fn definition(&mut self, id: Id) -> Result<TokenStream, EmitError> {
        Ok(self.node(id)?.tokens)
    }

    /// Tokens of `id`, as an operand.
    pub fn operand(&mut self, id: Id) -> Result<TokenStream, EmitError> {
        Ok(self.expr(id)?.tokens)
    }

    fn expr(&mut self, id: Id) -> Result<Lowered, EmitError> {
        if let Some(name) = self.bound.get(&id) {
            let name = ident(name);
            return Ok(Lowered::new(quote!(#name), ATOM));
        }
        self.node(id)
    }

    fn node(&mut self, id: Id) -> Result<Lowered, EmitError> {
        let g = self.graph;
        Ok(match g.node(id) {
            Node::Const(bits) => self.constant(f64::from_bits(*bits))?,
            Node::Sym(i) => {
                return match self.bound.get(&id) {
                    Some(name) => {
                        let name = ident(name);
                        Ok(Lowered::new(quote!(#name), ATOM))
                    }
                    None => Err(EmitError::UnboundSymbol(g.symbol_name(*i).to_owned())),
                }
            }
            Node::Add(xs) => self.sum(xs)?,
            Node::Mul(xs) => match xs.split_first() {
                Some((&c, rest)) if g.as_const(c).is_some() => {
                    self.product(g.as_const(c).unwrap_or(1.0), rest)?
                }
                _ => self.product(1.0, xs)?,
            },
            Node::Pow(b, e) => self.pow(*b, *e)?,
            Node::Func(f, a) => {
                let name = match f {
                    Func::Sqrt => "sqrt",
                    Func::Exp => "exp",
                    Func::Ln => "ln",
                    Func::Abs => "abs",
                    Func::Sign => "signum0",
                    Func::Tanh => "tanh",
                    Func::Coth => "coth",
                };
                self.call(name, &[*a])?
            }
            Node::Min(a, b) => self.call("min", &[*a, *b])?,
            Node::Max(a, b) => self.call("max", &[*a, *b])?,
            Node::Select(c, a, b) => {
                let c = self.expr(*c)?.at(SUM);
                let zero = self.literal(0.0)?;
                let a = self.expr(*a)?.tokens;
                let b = self.expr(*b)?.tokens;
                Lowered::new(quote!(if #c >= #zero { #a } else { #b }), IF)
            }
        })
    }

    fn literal(&mut self, value: f64) -> Result<TokenStream, EmitError> {
        self.excessive |= self.float.excessive(value);
        self.float
            .literal(value)
            .ok_or_else(|| EmitError::NonFinite {
                name: "a constant".to_owned(),
                value: format!("{value:?}"),
                float: self.float.name(),
            })
    }

    fn constant(&mut self, value: f64) -> Result<Lowered, EmitError> {
        if let Some(named) = self.named_constant(value.abs())? {
            return Ok(if value < 0.0 {
                Self::negate(named)
            } else {
                named
            });
        }
        let lit = self.literal(value)?;
        Ok(if value < 0.0 {
            Lowered {
                tokens: quote!(-#lit),
                prec: UNARY,
                negated: true,
            }
        } else {
            Lowered::new(lit, ATOM)
        })
    }

    /// `magnitude` (> 0) by name when it is k·μ0ᵉ or Z_EPS: `Z_EPS`,
    /// `k / MU0`, `k * MU0 * MU0`, … (`physical.rs`).
    fn named_constant(&mut self, magnitude: f64) -> Result<Option<Lowered>, EmitError> {
        let Some(named) = recognise(magnitude) else {
            return Ok(None);
        };
        let constant = named.constant();
        if !self.available.contains(&constant) {
            return Ok(None);
        }
        if !self.named.contains(&constant) {
            self.named.push(constant);
        }
        let name = ident(constant.name);
        Ok(Some(match named {
            Named::ZEps { .. } => Lowered::new(quote!(#name), ATOM),
            Named::Mu0 { k, e } => {
                let power = match e.abs() {
                    1 => Lowered::new(quote!(#name), ATOM),
                    _ => Lowered::new(quote!(#name * #name), PRODUCT),
                };
                if e < 0 {
                    Self::quotient(self.literal_lowered(k)?, vec![power])
                } else if k == 1.0 {
                    power
                } else {
                    Self::chain(vec![self.literal_lowered(k)?, power])
                }
            }
        }))
    }

    fn literal_lowered(&mut self, value: f64) -> Result<Lowered, EmitError> {
        Ok(Lowered::new(self.literal(value)?, ATOM))
    }

    fn call(&mut self, name: &str, args: &[Id]) -> Result<Lowered, EmitError> {
        self.uses_real = true;
        let f = ident(name);
        let mut list = Vec::with_capacity(args.len());
        for &a in args {
            list.push(self.expr(a)?.tokens);
        }
        Ok(Lowered::new(quote!(Real::#f(#(#list),*)), ATOM))
    }

    fn negate(m: Lowered) -> Lowered {
        if m.negated || m.prec < PRODUCT {
            let t = m.at(ATOM);
            return Lowered {
                tokens: quote!(-#t),
                prec: UNARY,
                negated: true,
            };
        }
        // `-a * b` parses as (−a)·b, which is exactly −(a·b).
        let t = m.tokens;
        Lowered {
            tokens: quote!(-#t),
            prec: m.prec.min(UNARY),
            negated: true,
        }
    }

    /// A sum term as (negative?, magnitude).
    fn signed_term(&mut self, t: Id) -> Result<(bool, Lowered), EmitError> {
        let g = self.graph;
        if self.bound.contains_key(&t) {
            return Ok((false, self.expr(t)?));
        }
        if let Some(c) = g.as_const(t) {
            if c < 0.0 {
                return Ok((true, self.constant(-c)?));
            }
        }
        if let Node::Mul(xs) = g.node(t) {
            if let Some((&c, rest)) = xs.split_first() {
                if let Some(c) = g.as_const(c).filter(|&c| c < 0.0) {
                    return Ok((true, self.product(-c, rest)?));
                }
            }
        }
        Ok((false, self.expr(t)?))
    }

    fn sum(&mut self, xs: &[Id]) -> Result<Lowered, EmitError> {
        let g = self.graph;
        // Terms in node order, the constant last (as the printer does).
        let mut ordered: Vec<Id> = xs
            .iter()
            .copied()
            .filter(|&x| g.as_const(x).is_none())
            .collect();
        ordered.extend(xs.iter().copied().filter(|&x| g.as_const(x).is_some()));
        let mut terms = Vec::with_capacity(ordered.len());
        for t in ordered {
            terms.push(self.signed_term(t)?);
        }
        // Start from a positive term when there is one.
        let first = terms.iter().position(|(neg, _)| !neg).unwrap_or(0);
        if first >= terms.len() {
            return self.constant(0.0);
        }
        let (neg0, m0) = terms.remove(first);
        let mut acc = if neg0 { Self::negate(m0) } else { m0 }.at(SUM);
        for (neg, m) in terms {
            let m = m.at(PRODUCT);
            acc = if neg {
                quote!(#acc - #m)
            } else {
                quote!(#acc + #m)
            };
        }
        Ok(Lowered::new(acc, SUM))
    }

    /// c · Π factors, negative powers in a denominator. Parameter-only
    /// factors come first, `c * A / (B * C) * x * y / (d * e)`: evaluated
    /// left to right, the prefix is a constant the compiler folds, so the
    /// call pays only for the factors that depend on the inputs.
    fn product(&mut self, c: f64, factors: &[Id]) -> Result<Lowered, EmitError> {
        let g = self.graph;
        let mut parts: [Vec<Lowered>; 4] = Default::default(); // [static num, static den, num, den]
        for &f in factors {
            let group = if self.is_static(f) { 0 } else { 2 };
            if !self.bound.contains_key(&f) {
                if let Node::Pow(b, e) = g.node(f) {
                    if let Some(ev) = g.as_const(*e).filter(|&e| e < 0.0) {
                        if let Some(p) = self.inverse_power(*b, -ev)? {
                            parts[group].push(p);
                            continue;
                        }
                        if let Some(p) = self.positive_power(*b, -ev)? {
                            parts[group + 1].push(p);
                            continue;
                        }
                    }
                }
            }
            parts[group].push(self.expr(f)?);
        }
        let [static_num, static_den, num, den] = parts;
        let mut head = Vec::new();
        if c.abs() != 1.0 || (static_num.is_empty() && (!static_den.is_empty() || num.is_empty())) {
            head.push(self.constant(c.abs())?);
        }
        head.extend(static_num);
        let mut all = Vec::new();
        if !head.is_empty() {
            all.push(Self::quotient(Self::chain(head), static_den));
        }
        all.extend(num);
        let body = Self::quotient(Self::chain(all), den);
        Ok(if c < 0.0 { Self::negate(body) } else { body })
    }

    /// `n / (d₁ * d₂)` (n alone when there is no denominator).
    fn quotient(n: Lowered, den: Vec<Lowered>) -> Lowered {
        if den.is_empty() {
            return n;
        }
        let n = n.at(PRODUCT);
        let d = Self::chain(den).at(UNARY);
        Lowered::new(quote!(#n / #d), PRODUCT)
    }

    /// Whether `id` depends on parameters and constants only (memoised).
    fn is_static(&mut self, id: Id) -> bool {
        if let Some(&s) = self.statics.get(&id) {
            return s;
        }
        let g = self.graph;
        let s = match g.node(id) {
            Node::Const(_) => true,
            Node::Sym(_) => self.params.contains(&id),
            _ => g.children(id).into_iter().all(|c| self.is_static(c)),
        };
        self.statics.insert(id, s);
        s
    }

    /// a * b * c (left-associated; right operands parenthesised if needed).
    fn chain(factors: Vec<Lowered>) -> Lowered {
        let mut it = factors.into_iter();
        let Some(first) = it.next() else {
            return Lowered::new(quote!(), ATOM);
        };
        let mut rest = it.peekable();
        if rest.peek().is_none() {
            return first;
        }
        let mut acc = first.at(PRODUCT);
        for f in rest {
            let f = f.at(UNARY);
            acc = quote!(#acc * #f);
        }
        Lowered::new(acc, PRODUCT)
    }

    /// b⁻ⁿ (n = 2, 3, 4) written with the `let`s of b⁻¹ and b⁻² already
    /// emitted (`inv_t * inv_t_sq`): multiplications instead of a division.
    fn inverse_power(&mut self, b: Id, n: f64) -> Result<Option<Lowered>, EmitError> {
        if !(2.0..=4.0).contains(&n) || n.fract() != 0.0 {
            return Ok(None);
        }
        let g = self.graph;
        let bound_inverse = |k: f64| {
            let e = g.find(&Node::Const((-k).to_bits()))?;
            let id = g.find(&Node::Pow(b, e))?;
            self.defined.contains(&id).then_some(id)
        };
        let (inv1, inv2) = (bound_inverse(1.0), bound_inverse(2.0));
        let ids: Vec<Id> = match (n as u8, inv1, inv2) {
            (2, Some(i1), _) => vec![i1, i1],
            (3, Some(i1), Some(i2)) => vec![i2, i1],
            (3, Some(i1), None) => vec![i1, i1, i1],
            (4, _, Some(i2)) => vec![i2, i2],
            _ => return Ok(None),
        };
        let mut factors = Vec::with_capacity(ids.len());
        for id in ids {
            factors.push(self.expr(id)?);
        }
        Ok(Some(Self::chain(factors)))
    }

    /// b^p for p > 0 when it has a non-`powf` form (integer ≤ 64, or ½).
    fn positive_power(&mut self, b: Id, p: f64) -> Result<Option<Lowered>, EmitError> {
        if p.fract() == 0.0 && p <= MAX_POWI {
            let n = p as i32; // exact: integral and ≤ 64
            let base = self.expr(b)?;
            return Ok(Some(match n {
                1 => base,
                2 => {
                    let t = base.at(UNARY);
                    Lowered::new(quote!(#t * #t), PRODUCT)
                }
                3 => {
                    let t = base.at(UNARY);
                    Lowered::new(quote!(#t * #t * #t), PRODUCT)
                }
                _ => {
                    self.uses_real = true;
                    let t = base.tokens;
                    let n = proc_macro2::Literal::i32_unsuffixed(n);
                    Lowered::new(quote!(Real::powi(#t, #n)), ATOM)
                }
            }));
        }
        if p == 0.5 {
            return Ok(Some(self.call("sqrt", &[b])?));
        }
        Ok(None)
    }

    fn pow(&mut self, b: Id, e: Id) -> Result<Lowered, EmitError> {
        if let Some(ev) = self.graph.as_const(e) {
            if ev < 0.0 {
                if let Some(p) = self.inverse_power(b, -ev)? {
                    return Ok(p);
                }
            }
            if let Some(p) = self.positive_power(b, ev.abs())? {
                if ev > 0.0 {
                    return Ok(p);
                }
                let one = self.literal(1.0)?;
                let d = p.at(UNARY);
                return Ok(Lowered::new(quote!(#one / #d), PRODUCT));
            }
        }
        self.call("powf", &[b, e])
    }
}
