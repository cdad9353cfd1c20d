//! The compiler from the expression DAG to tape instructions: the slot of
//! every node, sums and products as the arithmetic a person would write,
//! repeated instructions merged, and the sides of each `Select` in
//! conditional blocks (see the `tape` module docs).

use std::collections::HashMap;

use super::super::graph::{Func, Graph, Id, Node};
use super::{Instr, UnboundSymbol};

/// Instructions, slot template (inputs, constants, one slot per
/// instruction) and output slots.
type Compiled = (Vec<Instr>, Vec<f64>, Vec<u32>);

/// Compiles `outputs` as functions of `inputs`.
pub(super) fn instructions(
    graph: &Graph,
    inputs: &[Id],
    outputs: &[Id],
) -> Result<Compiled, UnboundSymbol> {
    let mut c = Compiler {
        graph,
        guards: Guards::analyse(graph, outputs),
        scopes: vec![Scope {
            parent: 0,
            depth: 0,
        }],
        scope: 0,
        slots: HashMap::new(),
        values: HashMap::new(),
        template: vec![0.0; inputs.len()],
        instrs: Vec::new(),
        constants: HashMap::new(),
    };
    for (k, &x) in inputs.iter().enumerate() {
        c.slots.insert(x, (k as u32, 0));
    }
    let outputs = outputs
        .iter()
        .map(|&o| c.slot(o))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((c.instrs, c.template, outputs))
}

/// Where each node is needed: a tree of contexts, the root (0) meaning
/// "always" and each other context one side of one `Select`, nested in the
/// context of that `Select`. A node's guard is the innermost context that all
/// its uses lie in.
struct Guards {
    /// (parent context, depth) of each context.
    tree: Vec<(u32, u32)>,
    /// The contexts of the `a` (≥ 0) and `b` sides of each `Select`.
    sides: HashMap<Id, (u32, u32)>,
    guard: HashMap<Id, u32>,
}

impl Guards {
    fn analyse(graph: &Graph, outputs: &[Id]) -> Guards {
        let mut g = Guards {
            tree: vec![(0, 0)],
            sides: HashMap::new(),
            guard: HashMap::new(),
        };
        for &o in outputs {
            g.meet(o, 0);
        }
        // Reverse post-order visits every node after all its users.
        for n in graph.postorder(outputs).into_iter().rev() {
            let ctx = g.guard[&n];
            if let Node::Select(c, a, b) = *graph.node(n) {
                let depth = g.tree[ctx as usize].1 + 1;
                let side_a = g.tree.len() as u32;
                g.tree.push((ctx, depth));
                g.tree.push((ctx, depth));
                g.sides.insert(n, (side_a, side_a + 1));
                g.meet(c, ctx);
                g.meet(a, side_a);
                g.meet(b, side_a + 1);
            } else {
                for child in graph.children(n) {
                    g.meet(child, ctx);
                }
            }
        }
        g
    }

    /// Records a use of `n` in context `ctx`.
    fn meet(&mut self, n: Id, ctx: u32) {
        let merged = match self.guard.get(&n) {
            Some(&old) => self.common(old, ctx),
            None => ctx,
        };
        self.guard.insert(n, merged);
    }

    /// The innermost context containing both `a` and `b`.
    fn common(&self, mut a: u32, mut b: u32) -> u32 {
        let depth = |c: u32| self.tree[c as usize].1;
        while depth(a) > depth(b) {
            a = self.tree[a as usize].0;
        }
        while depth(b) > depth(a) {
            b = self.tree[b as usize].0;
        }
        while a != b {
            (a, b) = (self.tree[a as usize].0, self.tree[b as usize].0);
        }
        a
    }

    /// Whether `n` is needed only inside one side of the `Select` `sel`.
    fn inside(&self, n: Id, sel: Id) -> bool {
        let (side_a, side_b) = self.sides[&sel];
        let g = self.guard[&n];
        let c = self.common(g, side_a);
        c == side_a || self.common(g, side_b) == side_b
    }
}

/// A compile-time scope: the straight-line code outside all blocks (0) or a
/// conditional block. A slot computed in a scope is valid there and in the
/// scopes nested in it.
struct Scope {
    parent: u32,
    depth: u32,
}

struct Compiler<'g> {
    graph: &'g Graph,
    guards: Guards,
    scopes: Vec<Scope>,
    /// The scope instructions are currently emitted into.
    scope: u32,
    /// Node → (slot, scope it was computed in).
    slots: HashMap<Id, (u32, u32)>,
    /// Instruction (destination 0) → (slot, scope): merges repeated ones.
    values: HashMap<Instr, (u32, u32)>,
    template: Vec<f64>,
    instrs: Vec<Instr>,
    constants: HashMap<u64, u32>,
}

impl Compiler<'_> {
    fn new_slot(&mut self, value: f64) -> u32 {
        self.template.push(value);
        (self.template.len() - 1) as u32
    }

    /// Emits `make(dst)` into the current scope, unless the same instruction
    /// was already emitted where its value is visible.
    fn emit(&mut self, make: impl FnOnce(u32) -> Instr) -> u32 {
        let key = make(0);
        if let Some(&(d, scope)) = self.values.get(&key) {
            if self.visible(scope) {
                return d;
            }
        }
        let d = self.new_slot(0.0);
        self.instrs.push(with_dst(key, d));
        self.values.insert(key, (d, self.scope));
        d
    }

    /// Whether values computed in `scope` are visible in the current scope.
    fn visible(&self, scope: u32) -> bool {
        let mut s = self.scope;
        while self.scopes[s as usize].depth > self.scopes[scope as usize].depth {
            s = self.scopes[s as usize].parent;
        }
        s == scope
    }

    /// The visible slot of `id`, if it has been computed.
    fn known(&self, id: Id) -> Option<u32> {
        let &(slot, scope) = self.slots.get(&id)?;
        self.visible(scope).then_some(slot)
    }

    /// Slot of a numeric constant introduced by the compiler (deduplicated).
    fn constant(&mut self, value: f64) -> u32 {
        if let Some(&s) = self.constants.get(&value.to_bits()) {
            return s;
        }
        let s = self.new_slot(value);
        self.constants.insert(value.to_bits(), s);
        s
    }

    /// Slot holding the value of `id`, compiling it on first use.
    fn slot(&mut self, id: Id) -> Result<u32, UnboundSymbol> {
        if let Some(s) = self.known(id) {
            return Ok(s);
        }
        let s = match self.graph.node(id).clone() {
            Node::Const(bits) => {
                let s = self.new_slot(f64::from_bits(bits));
                self.slots.insert(id, (s, 0));
                return Ok(s);
            }
            Node::Sym(i) => return Err(UnboundSymbol(self.graph.symbol_name(i).to_owned())),
            Node::Add(xs) => self.compile_sum(&xs)?,
            Node::Mul(xs) => self.compile_product(&xs)?,
            Node::Pow(b, e) => self.compile_pow(b, e)?,
            Node::Func(f, a) => {
                let a = self.slot(a)?;
                self.emit(|d| Instr::Func(f, d, a))
            }
            Node::Min(a, b) => {
                let (a, b) = (self.slot(a)?, self.slot(b)?);
                self.emit(|d| Instr::Min(d, a, b))
            }
            Node::Max(a, b) => {
                let (a, b) = (self.slot(a)?, self.slot(b)?);
                self.emit(|d| Instr::Max(d, a, b))
            }
            Node::Select(c, a, b) => self.compile_select(id, c, a, b)?,
        };
        self.slots.insert(id, (s, self.scope));
        Ok(s)
    }

    /// `Select(c, a, b)`: what only one side needs goes into that side's
    /// block of a `Branch`; what is needed elsewhere too is computed first.
    fn compile_select(&mut self, id: Id, c: Id, a: Id, b: Id) -> Result<u32, UnboundSymbol> {
        let c = self.slot(c)?;
        for n in self.shared_operands(id, [a, b]) {
            self.slot(n)?;
        }
        // Branch(c, na + 1) [a-block… Skip(nb)] [b-block…]
        let at = self.instrs.len();
        self.instrs.push(Instr::Branch(c, 0));
        let a = self.in_block(|this| this.slot(a))?;
        let skip = self.instrs.len();
        self.instrs.push(Instr::Skip(0));
        let b = self.in_block(|this| this.slot(b))?;
        let (na, nb) = (skip - at - 1, self.instrs.len() - skip - 1);
        if na + nb == 0 {
            self.instrs.truncate(at);
        } else {
            self.instrs[at] = Instr::Branch(c, na as u32 + 1);
            self.instrs[skip] = Instr::Skip(nb as u32);
        }
        let d = self.new_slot(0.0);
        self.instrs.push(Instr::Select(d, c, a, b));
        Ok(d)
    }

    /// The not yet computed nodes below the sides of `sel` that are needed
    /// outside them too (the boundary of what its blocks compute), children
    /// before parents.
    fn shared_operands(&self, sel: Id, sides: [Id; 2]) -> Vec<Id> {
        let mut seen = std::collections::HashSet::new();
        let mut stack = sides.to_vec();
        let mut shared = Vec::new();
        while let Some(n) = stack.pop() {
            if !seen.insert(n) || self.known(n).is_some() {
                continue;
            }
            if self.guards.inside(n, sel) {
                stack.extend(self.graph.children(n));
            } else {
                shared.push(n);
            }
        }
        // Ids grow with construction, so operands come before their users.
        shared.sort();
        shared
    }

    /// Runs `f` in a new block scope nested in the current one.
    fn in_block<T>(&mut self, f: impl FnOnce(&mut Self) -> T) -> T {
        let outer = self.scope;
        let depth = self.scopes[outer as usize].depth + 1;
        self.scopes.push(Scope {
            parent: outer,
            depth,
        });
        self.scope = (self.scopes.len() - 1) as u32;
        let r = f(self);
        self.scope = outer;
        r
    }

    /// A term of a sum as (negated?, slot of its magnitude).
    fn signed_term(&mut self, t: Id) -> Result<(bool, u32), UnboundSymbol> {
        if let Node::Mul(xs) = self.graph.node(t) {
            if let Some(c) = self.graph.as_const(xs[0]) {
                if c < 0.0 {
                    let xs = xs.clone();
                    let magnitude = self.scaled_product(-c, &xs[1..])?;
                    return Ok((true, magnitude));
                }
            }
        }
        Ok((false, self.slot(t)?))
    }

    fn compile_sum(&mut self, xs: &[Id]) -> Result<u32, UnboundSymbol> {
        let mut terms = Vec::with_capacity(xs.len());
        for &t in xs {
            terms.push(self.signed_term(t)?);
        }
        // Start from a positive term when there is one.
        let first = terms.iter().position(|(neg, _)| !neg).unwrap_or(0);
        let (neg0, s0) = terms.remove(first);
        let mut acc = if neg0 {
            self.emit(|d| Instr::Neg(d, s0))
        } else {
            s0
        };
        for (neg, s) in terms {
            let a = acc;
            acc = self.emit(|d| {
                if neg {
                    Instr::Sub(d, a, s)
                } else {
                    Instr::Add(d, a, s)
                }
            });
        }
        Ok(acc)
    }

    fn compile_product(&mut self, xs: &[Id]) -> Result<u32, UnboundSymbol> {
        match self.graph.as_const(xs[0]) {
            Some(c) => self.scaled_product(c, &xs[1..]),
            None => self.scaled_product(1.0, xs),
        }
    }

    /// c · Π factors, with negative integer powers moved to a denominator.
    fn scaled_product(&mut self, c: f64, factors: &[Id]) -> Result<u32, UnboundSymbol> {
        let mut num = Vec::new();
        let mut den = Vec::new();
        for &f in factors {
            match self.graph.node(f) {
                Node::Pow(b, e)
                    if self
                        .graph
                        .as_const(*e)
                        .is_some_and(|e| e < 0.0 && e.fract() == 0.0) =>
                {
                    let (b, n) = (*b, -self.graph.as_const(*e).unwrap_or(-1.0) as i32);
                    den.push(self.power_slot(b, n)?);
                }
                _ => num.push(self.slot(f)?),
            }
        }
        if c != 1.0 {
            let s = self.constant(c);
            num.insert(0, s);
        }
        let numerator = self.chain(&num, Instr::Mul);
        let denominator = self.chain(&den, Instr::Mul);
        Ok(match (numerator, denominator) {
            (Some(n), None) => n,
            (Some(n), Some(d)) => self.emit(|dst| Instr::Div(dst, n, d)),
            (None, Some(d)) => self.emit(|dst| Instr::Recip(dst, d)),
            (None, None) => self.constant(1.0),
        })
    }

    fn chain(&mut self, slots: &[u32], op: fn(u32, u32, u32) -> Instr) -> Option<u32> {
        let (&first, rest) = slots.split_first()?;
        let mut acc = first;
        for &s in rest {
            let a = acc;
            acc = self.emit(|d| op(d, a, s));
        }
        Some(acc)
    }

    /// Slot of b^n for a positive integer n.
    fn power_slot(&mut self, b: Id, n: i32) -> Result<u32, UnboundSymbol> {
        let b = self.slot(b)?;
        Ok(match n {
            1 => b,
            2 => self.emit(|d| Instr::Mul(d, b, b)),
            _ => self.emit(|d| Instr::Powi(d, b, n)),
        })
    }

    fn compile_pow(&mut self, b: Id, e: Id) -> Result<u32, UnboundSymbol> {
        if let Some(ev) = self.graph.as_const(e) {
            if ev.fract() == 0.0 && ev.abs() <= 64.0 {
                let n = ev as i32;
                if n > 0 {
                    return self.power_slot(b, n);
                }
                let p = self.power_slot(b, -n)?;
                return Ok(self.emit(|d| Instr::Recip(d, p)));
            }
            if ev == 0.5 {
                let b = self.slot(b)?;
                return Ok(self.emit(|d| Instr::Func(Func::Sqrt, d, b)));
            }
        }
        let (b, e) = (self.slot(b)?, self.slot(e)?);
        Ok(self.emit(|d| Instr::Powf(d, b, e)))
    }
}

/// `ins` with its destination slot replaced by `d`.
fn with_dst(ins: Instr, d: u32) -> Instr {
    match ins {
        Instr::Add(_, a, b) => Instr::Add(d, a, b),
        Instr::Sub(_, a, b) => Instr::Sub(d, a, b),
        Instr::Mul(_, a, b) => Instr::Mul(d, a, b),
        Instr::Div(_, a, b) => Instr::Div(d, a, b),
        Instr::Neg(_, a) => Instr::Neg(d, a),
        Instr::Recip(_, a) => Instr::Recip(d, a),
        Instr::Powi(_, a, n) => Instr::Powi(d, a, n),
        Instr::Powf(_, a, b) => Instr::Powf(d, a, b),
        Instr::Func(f, _, a) => Instr::Func(f, d, a),
        Instr::Min(_, a, b) => Instr::Min(d, a, b),
        Instr::Max(_, a, b) => Instr::Max(d, a, b),
        Instr::Select(_, c, a, b) => Instr::Select(d, c, a, b),
        Instr::MulAdd(..)
        | Instr::MulSub(..)
        | Instr::SubMul(..)
        | Instr::AddMul(..)
        | Instr::SubThenMul(..)
        | Instr::MulMul(..)
        | Instr::DivAdd(..)
        | Instr::DivSub(..)
        | Instr::SubDiv(..) => unreachable!("fused instructions are not emitted through `emit`"),
        Instr::Branch(..) | Instr::Skip(..) => {
            unreachable!("branches are not emitted through `emit`")
        }
    }
}
