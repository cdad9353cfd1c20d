//! Compilation of expressions to a flat tape, and its f64 evaluator.
//!
//! A tape is a straight-line program over numbered slots: inputs first, then
//! constants, then one slot per instruction. Shared subexpressions are
//! computed once (the DAG is already hash-consed). Evaluation is a single pass
//! over a `Vec<Instr>`: no tree walking, no allocation. Sums with negated
//! terms become subtractions and products with negative powers divisions, so
//! the tape does the arithmetic a person would write.

use std::collections::HashMap;

use super::graph::{sign, Func, Graph, Id, Node};

/// One tape instruction: `dst = op(args)`; operands are slot numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Instr {
    Add(u32, u32, u32),
    Sub(u32, u32, u32),
    Mul(u32, u32, u32),
    Div(u32, u32, u32),
    Neg(u32, u32),
    Recip(u32, u32),
    Powi(u32, u32, i32),
    Powf(u32, u32, u32),
    Func(Func, u32, u32),
    Min(u32, u32, u32),
    Max(u32, u32, u32),
    /// dst = if c ≥ 0 { a } else { b }
    Select(u32, u32, u32, u32),
}

/// A compiled set of expressions of a fixed list of input symbols.
#[derive(Clone, Debug)]
pub struct Tape {
    instrs: Vec<Instr>,
    /// Initial slot contents: zeros for inputs and instructions, constants in place.
    template: Vec<f64>,
    n_inputs: usize,
    outputs: Vec<u32>,
}

/// A symbol reached by an expression but not listed as a tape input.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("symbol `{0}` is neither a tape input nor bound to a value")]
pub struct UnboundSymbol(pub String);

impl Tape {
    /// Compiles `outputs` as functions of `inputs` (symbol nodes, in order).
    pub fn compile(graph: &Graph, inputs: &[Id], outputs: &[Id]) -> Result<Tape, UnboundSymbol> {
        let mut c = Compiler {
            graph,
            slots: HashMap::new(),
            template: vec![0.0; inputs.len()],
            instrs: Vec::new(),
            constants: HashMap::new(),
        };
        for (k, &x) in inputs.iter().enumerate() {
            c.slots.insert(x, k as u32);
        }
        let outputs = outputs
            .iter()
            .map(|&o| c.slot(o))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Tape {
            instrs: c.instrs,
            template: c.template,
            n_inputs: inputs.len(),
            outputs,
        })
    }

    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Number of instructions executed per evaluation.
    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }

    /// A scratch buffer for [`Tape::eval`] (constants pre-loaded; reuse it).
    pub fn scratch(&self) -> Vec<f64> {
        self.template.clone()
    }

    /// Evaluates all outputs. `scratch` must come from [`Tape::scratch`].
    pub fn eval(&self, inputs: &[f64], scratch: &mut [f64], outputs: &mut [f64]) {
        assert_eq!(inputs.len(), self.n_inputs, "tape: wrong number of inputs");
        assert_eq!(
            scratch.len(),
            self.template.len(),
            "tape: scratch from another tape"
        );
        scratch[..self.n_inputs].copy_from_slice(inputs);
        let s = scratch;
        for ins in &self.instrs {
            let (dst, v) = match *ins {
                Instr::Add(d, a, b) => (d, s[a as usize] + s[b as usize]),
                Instr::Sub(d, a, b) => (d, s[a as usize] - s[b as usize]),
                Instr::Mul(d, a, b) => (d, s[a as usize] * s[b as usize]),
                Instr::Div(d, a, b) => (d, s[a as usize] / s[b as usize]),
                Instr::Neg(d, a) => (d, -s[a as usize]),
                Instr::Recip(d, a) => (d, 1.0 / s[a as usize]),
                Instr::Powi(d, a, n) => (d, s[a as usize].powi(n)),
                Instr::Powf(d, a, b) => (d, s[a as usize].powf(s[b as usize])),
                Instr::Func(f, d, a) => (d, apply(f, s[a as usize])),
                Instr::Min(d, a, b) => (d, s[a as usize].min(s[b as usize])),
                Instr::Max(d, a, b) => (d, s[a as usize].max(s[b as usize])),
                Instr::Select(d, c, a, b) => (
                    d,
                    if s[c as usize] >= 0.0 {
                        s[a as usize]
                    } else {
                        s[b as usize]
                    },
                ),
            };
            s[dst as usize] = v;
        }
        for (o, &slot) in outputs.iter_mut().zip(&self.outputs) {
            *o = s[slot as usize];
        }
    }
}

#[inline]
fn apply(f: Func, x: f64) -> f64 {
    match f {
        Func::Sqrt => x.sqrt(),
        Func::Exp => x.exp(),
        Func::Ln => x.ln(),
        Func::Abs => x.abs(),
        Func::Sign => sign(x),
        Func::Tanh => x.tanh(),
        Func::Coth => 1.0 / x.tanh(),
    }
}

struct Compiler<'g> {
    graph: &'g Graph,
    slots: HashMap<Id, u32>,
    template: Vec<f64>,
    instrs: Vec<Instr>,
    constants: HashMap<u64, u32>,
}

impl Compiler<'_> {
    fn new_slot(&mut self, value: f64) -> u32 {
        self.template.push(value);
        (self.template.len() - 1) as u32
    }

    fn emit(&mut self, make: impl FnOnce(u32) -> Instr) -> u32 {
        let d = self.new_slot(0.0);
        self.instrs.push(make(d));
        d
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
        if let Some(&s) = self.slots.get(&id) {
            return Ok(s);
        }
        let s = match self.graph.node(id).clone() {
            Node::Const(bits) => self.new_slot(f64::from_bits(bits)),
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
            Node::Select(c, a, b) => {
                let (c, a, b) = (self.slot(c)?, self.slot(a)?, self.slot(b)?);
                self.emit(|d| Instr::Select(d, c, a, b))
            }
        };
        self.slots.insert(id, s);
        Ok(s)
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
