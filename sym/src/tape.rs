//! Compilation of expressions to a flat tape, and its f64 evaluators.
//!
//! A tape is a straight-line program over numbered slots: inputs first, then
//! constants, then one slot per instruction. Shared subexpressions are
//! computed once (the DAG is already hash-consed, and identical instructions
//! the compiler derives are merged too). Evaluation is a single pass over a
//! `Vec<Instr>`: no tree walking, no allocation. Sums with negated terms
//! become subtractions and products with negative powers divisions, so the
//! tape does the arithmetic a person would write (`compile.rs`).
//!
//! **Branches.** A `Select(c, a, b)` needs only one of `a`, `b`. What only one
//! side needs (e.g. the series or the closed form of a function near a
//! removable singularity, the other pieces of a spline) is compiled into a
//! conditional block of that side, and a [`Instr::Branch`] runs one block
//! only. Which nodes those are follows from a usage analysis of the DAG
//! (`Guards`): a node belongs to the innermost branch that all its uses lie
//! in. Values a block computes are only reused inside that block.
//!
//! **Layout** (`layout.rs`). The instructions are grouped by the set of
//! inputs they depend on, and a scratch buffer remembers the previous
//! evaluation: [`Tape::eval`] runs only the groups whose inputs changed (bit
//! for bit), e.g. none of the air-gap terms while the armature rests on a
//! stop. Consecutive pairs whose intermediate result is used once are fused
//! into one instruction (`MulAdd` for a·b + c, …), with the same rounding.
//!
//! **Evaluators.** The interpreter dispatches on each instruction; its cost
//! is mostly that dispatch, not the arithmetic. Tapes of at most [`NARROW`]
//! slots also carry their instructions with one-byte slot numbers, run on a
//! scratch array of that size, so that indexing needs no bounds checks (in
//! safe code). [`Tape::eval_many`] evaluates many points at once, each
//! instruction on `LANES` points, which vectorises and spreads the dispatch.

// `!(a >= b)` comparisons are deliberate: they also catch NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod compile;
#[cfg(feature = "jit")]
mod jit;
mod layout;

use std::ops::IndexMut;

use super::graph::{sign, Func, Graph, Id};

/// One tape instruction: `dst = op(args)`; operands are slot numbers of type
/// `S` (see [`Instr`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Op<S> {
    Add(S, S, S),
    Sub(S, S, S),
    Mul(S, S, S),
    Div(S, S, S),
    Neg(S, S),
    Recip(S, S),
    Powi(S, S, i32),
    Powf(S, S, S),
    Func(Func, S, S),
    Min(S, S, S),
    Max(S, S, S),
    /// dst = if c ≥ 0 { a } else { b }
    Select(S, S, S, S),
    /// Fused pairs (see `fuse`): `MulAdd(d, a, b, c)`: d = a·b + c.
    MulAdd(S, S, S, S),
    /// d = a·b − c
    MulSub(S, S, S, S),
    /// `SubMul(d, c, a, b)`: d = c − a·b
    SubMul(S, S, S, S),
    /// d = (a + b)·c
    AddMul(S, S, S, S),
    /// d = (a − b)·c
    SubThenMul(S, S, S, S),
    /// d = a·b·c
    MulMul(S, S, S, S),
    /// d = a/b + c
    DivAdd(S, S, S, S),
    /// d = a/b − c
    DivSub(S, S, S, S),
    /// `SubDiv(d, c, a, b)`: d = c − a/b
    SubDiv(S, S, S, S),
    /// `Branch(c, n)` is followed by the `c ≥ 0` block (`n` instructions, the
    /// last a `Skip` over the other block) and then the other block: if
    /// c ≥ 0 (not NaN, like `Select`) execution falls through into the first,
    /// else it skips it. The `Select` after both picks the result.
    Branch(S, u32),
    /// Skips the next `n` instructions (ends the first block of a `Branch`).
    Skip(u32),
}

/// The instructions a tape is compiled to (slots as `u32`).
pub type Instr = Op<u32>;

/// Tapes with at most this many slots also get their instructions with
/// one-byte slot numbers, run on a scratch array of exactly this size: the
/// indexing then needs no bounds checks (all in safe code).
const NARROW: usize = 256;

/// A compiled set of expressions of a fixed list of input symbols.
#[derive(Clone, Debug)]
pub struct Tape {
    instrs: Vec<Instr>,
    /// `instrs` with one-byte slots, when the tape has at most [`NARROW`]
    /// slots (its scratch then has exactly that many, plus the flag).
    narrow: Option<Vec<Op<u8>>>,
    /// Consecutive runs of `instrs` that depend on the same inputs.
    groups: Vec<Group>,
    /// Initial slot contents: zeros for inputs and instructions, constants in
    /// place (then zeros up to [`NARROW`] for narrow tapes), and last the
    /// "evaluated" flag of a scratch buffer.
    template: Vec<f64>,
    /// Number of slots the instructions use.
    n_slots: usize,
    n_inputs: usize,
    outputs: Vec<u32>,
    /// The tape as machine code, compiled at its first evaluation (None:
    /// the interpreter runs; feature `jit`, `tape/jit.rs`).
    #[cfg(feature = "jit")]
    compiled: std::sync::OnceLock<Option<std::sync::Arc<jit::Compiled>>>,
}

/// Instructions `start..end` of a tape, which depend on the inputs in `mask`
/// (bit i: input i; all bits when the tape has more than 64 inputs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct Group {
    mask: u64,
    start: u32,
    end: u32,
}

/// A symbol reached by an expression but not listed as a tape input.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("symbol `{0}` is neither a tape input nor bound to a value")]
pub struct UnboundSymbol(pub String);

impl Tape {
    /// Compiles `outputs` as functions of `inputs` (symbol nodes, in order).
    pub fn compile(graph: &Graph, inputs: &[Id], outputs: &[Id]) -> Result<Tape, UnboundSymbol> {
        let (instrs, mut template, outputs) = compile::instructions(graph, inputs, outputs)?;
        let n_slots = template.len();
        let (instrs, groups) = layout::group_by_inputs(instrs, inputs.len(), n_slots, &outputs);
        let narrow = (template.len() <= NARROW)
            .then(|| {
                instrs
                    .iter()
                    .map(|i| i.narrow())
                    .collect::<Option<Vec<_>>>()
            })
            .flatten();
        if narrow.is_some() {
            template.resize(NARROW, 0.0);
        }
        template.push(0.0);
        Ok(Tape {
            instrs,
            narrow,
            n_slots,
            groups,
            template,
            n_inputs: inputs.len(),
            outputs,
            #[cfg(feature = "jit")]
            compiled: std::sync::OnceLock::new(),
        })
    }

    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Number of instructions on the tape (an evaluation runs at most these:
    /// one block of each branch is skipped).
    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }

    /// The instructions, in order (for inspection and tests).
    pub fn instrs(&self) -> &[Instr] {
        &self.instrs
    }

    /// A scratch buffer for [`Tape::eval`] (constants pre-loaded; reuse it).
    pub fn scratch(&self) -> Vec<f64> {
        self.template.clone()
    }

    /// Evaluates all outputs. `scratch` must come from [`Tape::scratch`]
    /// and is only ever used with this tape: it keeps the values of the
    /// previous evaluation, and the instructions whose inputs are the same
    /// (bit for bit) as then are not run again (e.g. everything that depends
    /// on the position alone while the armature rests on a stop).
    pub fn eval(&self, inputs: &[f64], scratch: &mut [f64], outputs: &mut [f64]) {
        #[cfg(feature = "jit")]
        let compiled = (self.compiled)
            .get_or_init(|| jit::compiled(&self.instrs, &self.groups, self.n_slots))
            .as_ref()
            .map(|c| &**c);
        #[cfg(not(feature = "jit"))]
        let compiled: Option<&Interpreted> = None;
        self.eval_by(compiled, inputs, scratch, outputs)
    }

    /// [`Tape::eval`] by `compiled` code, or the interpreter where None.
    fn eval_by<C: Compiled>(
        &self,
        compiled: Option<&C>,
        inputs: &[f64],
        scratch: &mut [f64],
        outputs: &mut [f64],
    ) {
        assert_eq!(inputs.len(), self.n_inputs, "tape: wrong number of inputs");
        assert_eq!(
            scratch.len(),
            self.template.len(),
            "tape: scratch from another tape"
        );
        let (slots, flag) = scratch.split_at_mut(self.template.len() - 1);
        let mut changed = if flag[0] == 0.0 { u64::MAX } else { 0 };
        for (i, (s, &x)) in slots.iter_mut().zip(inputs).enumerate() {
            if s.to_bits() != x.to_bits() {
                changed |= 1u64.checked_shl(i as u32).unwrap_or(u64::MAX);
                *s = x;
            }
        }
        match (compiled, &self.narrow) {
            (Some(code), _) => code.run(slots, changed),
            (None, Some(code)) => {
                let s: &mut [f64; NARROW] = slots.try_into().expect("narrow scratch size");
                self.for_changed(changed, |r| run(&code[r], s));
            }
            (None, None) => self.for_changed(changed, |r| run(&self.instrs[r], slots)),
        }
        flag[0] = 1.0;
        for (o, &slot) in outputs.iter_mut().zip(&self.outputs) {
            *o = slots[slot as usize];
        }
    }
}

impl Tape {
    /// Calls `run` on the instructions that depend on an input in `changed`,
    /// merging adjacent groups into one call.
    #[inline]
    fn for_changed(&self, changed: u64, mut run: impl FnMut(std::ops::Range<usize>)) {
        let mut pending: Option<(u32, u32)> = None;
        for g in self.groups.iter().filter(|g| g.mask & changed != 0) {
            pending = match pending {
                Some((start, end)) if end == g.start => Some((start, g.end)),
                Some((start, end)) => {
                    run(start as usize..end as usize);
                    Some((g.start, g.end))
                }
                None => Some((g.start, g.end)),
            };
        }
        if let Some((start, end)) = pending {
            run(start as usize..end as usize);
        }
    }
}

/// A tape's machine code: runs the groups whose inputs meet `changed`.
trait Compiled {
    fn run(&self, slots: &mut [f64], changed: u64);
}

/// No machine code: the interpreter runs (without the `jit` feature, and in
/// the compiled code's tests).
#[allow(dead_code)]
enum Interpreted {}

impl Compiled for Interpreted {
    fn run(&self, _: &mut [f64], _: u64) {
        match *self {}
    }
}

/// Points evaluated together by [`Tape::eval_many`].
const LANES: usize = 16;
/// One slot's values at `LANES` points.
type Lanes = [f64; LANES];

/// Points `start..start + m` (m ≤ LANES) of the column `(data, stride,
/// offset)` (point k: `data[k·stride + offset]`); unused lanes repeat the
/// last point.
#[inline]
fn column_lanes((data, stride, offset): (&[f64], usize, usize), start: usize, m: usize) -> Lanes {
    if stride == 1 {
        if let Some(&full) = data[start + offset..].first_chunk() {
            return full;
        }
    }
    std::array::from_fn(|l| data[(start + l.min(m - 1)) * stride + offset])
}

/// Number of points of the column `(data, stride, offset)`.
fn column_len((data, stride, offset): (&[f64], usize, usize)) -> usize {
    (data.len() + stride).saturating_sub(offset + 1) / stride.max(1)
}

impl Tape {
    /// Evaluates all outputs at many points at once. Input i at point k is
    /// `data[k·stride + offset]` of `inputs[i] = (data, stride, offset)`
    /// (stride 1, offset 0 for a plain column; stride 4, offset 2 for
    /// component 2 of an array of `[f64; 4]`), all inputs having the same
    /// number n of points, and output j at point k goes to `outputs[j·n + k]`.
    /// The same as calling [`eval`](Self::eval) per point, but each
    /// instruction is decoded once for a group of points (and vectorises),
    /// and what depends only on inputs that are the same as in the previous
    /// group is not recomputed: several times faster for many points.
    ///
    /// # Panics
    /// If the numbers or lengths do not fit.
    pub fn eval_many(&self, inputs: &[(&[f64], usize, usize)], outputs: &mut [f64]) {
        let n = inputs.first().map_or(0, |&c| column_len(c));
        assert!(
            inputs.len() == self.n_inputs
                && inputs.iter().all(|&c| c.1 > 0 && column_len(c) == n)
                && outputs.len() == n * self.outputs.len(),
            "tape: eval_many needs {} input columns of equal length and room for {} outputs each",
            self.n_inputs,
            self.outputs.len()
        );
        let mut s: Vec<Lanes> = self.template[..self.n_slots]
            .iter()
            .map(|&v| [v; LANES])
            .collect();
        let used = self.groups.iter().fold(0, |m, g| m | g.mask);
        for start in (0..n).step_by(LANES) {
            let m = LANES.min(n - start);
            let mut changed = if start == 0 { u64::MAX } else { 0 };
            for (i, (slot, &col)) in s.iter_mut().zip(inputs).enumerate() {
                let bit = 1u64.checked_shl(i as u32).unwrap_or(u64::MAX);
                if used & bit != 0 {
                    let lanes = column_lanes(col, start, m);
                    // (Lane by lane: an array's `!=` is a `memcmp` call.)
                    if lanes
                        .iter()
                        .zip(&*slot)
                        .any(|(a, b)| a.to_bits() != b.to_bits())
                    {
                        changed |= bit;
                        *slot = lanes;
                    }
                }
            }
            // (Bounds checks are shared by the lanes here: no narrow code.)
            self.for_changed(changed, |r| run_lanes(&self.instrs[r], &mut s[..]));
            for (j, &slot) in self.outputs.iter().enumerate() {
                let column = &mut outputs[j * n + start..(j + 1) * n];
                match column.first_chunk_mut() {
                    Some(full) => *full = s[slot as usize],
                    None => column.copy_from_slice(&s[slot as usize][..m]),
                }
            }
        }
    }
}

/// [`run`] on `LANES` points at once. A branch runs each block that at least
/// one point takes (recursively; a block only computes values, so running it
/// for points that do not need it is harmless: the `Select` discards them).
fn run_lanes<S: Slot, M: IndexMut<usize, Output = Lanes> + ?Sized>(code: &[Op<S>], s: &mut M) {
    let mut it = code.iter();
    while let Some(ins) = it.next() {
        match *ins {
            Op::Add(d, a, b) => lanes2(s, d, a, b, |x, y| x + y),
            Op::Sub(d, a, b) => lanes2(s, d, a, b, |x, y| x - y),
            Op::Mul(d, a, b) => lanes2(s, d, a, b, |x, y| x * y),
            Op::Div(d, a, b) => lanes2(s, d, a, b, |x, y| x / y),
            Op::Neg(d, a) => lanes1(s, d, a, |x| -x),
            Op::Recip(d, a) => lanes1(s, d, a, |x| 1.0 / x),
            Op::Powi(d, a, n) => lanes1(s, d, a, |x| x.powi(n)),
            Op::Powf(d, a, b) => lanes2(s, d, a, b, f64::powf),
            Op::Func(f, d, a) => match f {
                // One loop per function (no per-lane dispatch).
                Func::Sqrt => lanes1(s, d, a, f64::sqrt),
                Func::Exp => lanes1(s, d, a, f64::exp),
                Func::Ln => lanes1(s, d, a, f64::ln),
                Func::Abs => lanes1(s, d, a, f64::abs),
                Func::Sign => lanes1(s, d, a, sign),
                Func::Tanh => lanes1(s, d, a, f64::tanh),
                Func::Coth => lanes1(s, d, a, crate::graph::coth),
            },
            Op::Min(d, a, b) => lanes2(s, d, a, b, f64::min),
            Op::Max(d, a, b) => lanes2(s, d, a, b, f64::max),
            Op::Select(d, c, a, b) => {
                let (c, a, b) = (s[c.ix()], s[a.ix()], s[b.ix()]);
                s[d.ix()] = std::array::from_fn(|l| if c[l] >= 0.0 { a[l] } else { b[l] });
            }
            Op::MulAdd(d, a, b, c) => lanes3(s, d, [a, b, c], |a, b, c| a * b + c),
            Op::MulSub(d, a, b, c) => lanes3(s, d, [a, b, c], |a, b, c| a * b - c),
            Op::SubMul(d, c, a, b) => lanes3(s, d, [c, a, b], |c, a, b| c - a * b),
            Op::AddMul(d, a, b, c) => lanes3(s, d, [a, b, c], |a, b, c| (a + b) * c),
            Op::SubThenMul(d, a, b, c) => lanes3(s, d, [a, b, c], |a, b, c| (a - b) * c),
            Op::MulMul(d, a, b, c) => lanes3(s, d, [a, b, c], |a, b, c| a * b * c),
            Op::DivAdd(d, a, b, c) => lanes3(s, d, [a, b, c], |a, b, c| a / b + c),
            Op::DivSub(d, a, b, c) => lanes3(s, d, [a, b, c], |a, b, c| a / b - c),
            Op::SubDiv(d, c, a, b) => lanes3(s, d, [c, a, b], |c, a, b| c - a / b),
            Op::Branch(c, n) => {
                // [a… Skip(nb)] [b…]
                let rest = it.as_slice();
                let (a, rest) = rest.split_at(n as usize - 1);
                let Op::Skip(nb) = rest[0] else {
                    unreachable!("the first block of a branch ends with a skip")
                };
                let (b, rest) = rest[1..].split_at(nb as usize);
                let c = s[c.ix()];
                if c.iter().any(|&v| v >= 0.0) {
                    run_lanes(a, s);
                }
                if c.iter().any(|&v| !(v >= 0.0)) {
                    run_lanes(b, s);
                }
                it = rest.iter();
            }
            Op::Skip(_) => unreachable!("skips are consumed with their branch"),
        }
    }
}

#[inline(always)]
fn lanes3<S: Slot, M: IndexMut<usize, Output = Lanes> + ?Sized>(
    s: &mut M,
    d: S,
    [a, b, c]: [S; 3],
    f: impl Fn(f64, f64, f64) -> f64,
) {
    let (x, y, z) = (s[a.ix()], s[b.ix()], s[c.ix()]);
    s[d.ix()] = std::array::from_fn(|l| f(x[l], y[l], z[l]));
}

#[inline(always)]
fn lanes1<S: Slot, M: IndexMut<usize, Output = Lanes> + ?Sized>(
    s: &mut M,
    d: S,
    a: S,
    f: impl Fn(f64) -> f64,
) {
    let x = s[a.ix()];
    s[d.ix()] = x.map(f);
}

#[inline(always)]
fn lanes2<S: Slot, M: IndexMut<usize, Output = Lanes> + ?Sized>(
    s: &mut M,
    d: S,
    a: S,
    b: S,
    f: impl Fn(f64, f64) -> f64,
) {
    let (x, y) = (s[a.ix()], s[b.ix()]);
    s[d.ix()] = std::array::from_fn(|l| f(x[l], y[l]));
}

/// Runs `code` on the slots `s`.
fn run<S: Slot, M: IndexMut<usize, Output = f64> + ?Sized>(code: &[Op<S>], s: &mut M) {
    let mut it = code.iter();
    while let Some(ins) = it.next() {
        let (dst, v): (S, f64) = match *ins {
            Op::Add(d, a, b) => (d, s[a.ix()] + s[b.ix()]),
            Op::Sub(d, a, b) => (d, s[a.ix()] - s[b.ix()]),
            Op::Mul(d, a, b) => (d, s[a.ix()] * s[b.ix()]),
            Op::Div(d, a, b) => (d, s[a.ix()] / s[b.ix()]),
            Op::Neg(d, a) => (d, -s[a.ix()]),
            Op::Recip(d, a) => (d, 1.0 / s[a.ix()]),
            Op::Powi(d, a, n) => (d, s[a.ix()].powi(n)),
            Op::Powf(d, a, b) => (d, s[a.ix()].powf(s[b.ix()])),
            Op::Func(f, d, a) => (d, Func::apply(f, s[a.ix()])),
            Op::Min(d, a, b) => (d, s[a.ix()].min(s[b.ix()])),
            Op::Max(d, a, b) => (d, s[a.ix()].max(s[b.ix()])),
            Op::Select(d, c, a, b) => (
                d,
                if s[c.ix()] >= 0.0 {
                    s[a.ix()]
                } else {
                    s[b.ix()]
                },
            ),
            Op::MulAdd(d, a, b, c) => (d, s[a.ix()] * s[b.ix()] + s[c.ix()]),
            Op::MulSub(d, a, b, c) => (d, s[a.ix()] * s[b.ix()] - s[c.ix()]),
            Op::SubMul(d, c, a, b) => (d, s[c.ix()] - s[a.ix()] * s[b.ix()]),
            Op::AddMul(d, a, b, c) => (d, (s[a.ix()] + s[b.ix()]) * s[c.ix()]),
            Op::SubThenMul(d, a, b, c) => (d, (s[a.ix()] - s[b.ix()]) * s[c.ix()]),
            Op::MulMul(d, a, b, c) => (d, s[a.ix()] * s[b.ix()] * s[c.ix()]),
            Op::DivAdd(d, a, b, c) => (d, s[a.ix()] / s[b.ix()] + s[c.ix()]),
            Op::DivSub(d, a, b, c) => (d, s[a.ix()] / s[b.ix()] - s[c.ix()]),
            Op::SubDiv(d, c, a, b) => (d, s[c.ix()] - s[a.ix()] / s[b.ix()]),
            Op::Branch(c, n) => {
                if !(s[c.ix()] >= 0.0) {
                    it = it.as_slice()[n as usize..].iter();
                }
                continue;
            }
            Op::Skip(n) => {
                it = it.as_slice()[n as usize..].iter();
                continue;
            }
        };
        s[dst.ix()] = v;
    }
}

/// A slot number of an instruction operand.
trait Slot: Copy {
    fn ix(self) -> usize;
}

impl Slot for u32 {
    #[inline(always)]
    fn ix(self) -> usize {
        self as usize
    }
}

impl Slot for u8 {
    #[inline(always)]
    fn ix(self) -> usize {
        usize::from(self)
    }
}

impl Op<u32> {
    /// The instruction with one-byte slots, if they all fit.
    fn narrow(self) -> Option<Op<u8>> {
        let n = |x: u32| u8::try_from(x).ok();
        Some(match self {
            Op::Add(d, a, b) => Op::Add(n(d)?, n(a)?, n(b)?),
            Op::Sub(d, a, b) => Op::Sub(n(d)?, n(a)?, n(b)?),
            Op::Mul(d, a, b) => Op::Mul(n(d)?, n(a)?, n(b)?),
            Op::Div(d, a, b) => Op::Div(n(d)?, n(a)?, n(b)?),
            Op::Neg(d, a) => Op::Neg(n(d)?, n(a)?),
            Op::Recip(d, a) => Op::Recip(n(d)?, n(a)?),
            Op::Powi(d, a, k) => Op::Powi(n(d)?, n(a)?, k),
            Op::Powf(d, a, b) => Op::Powf(n(d)?, n(a)?, n(b)?),
            Op::Func(f, d, a) => Op::Func(f, n(d)?, n(a)?),
            Op::Min(d, a, b) => Op::Min(n(d)?, n(a)?, n(b)?),
            Op::Max(d, a, b) => Op::Max(n(d)?, n(a)?, n(b)?),
            Op::Select(d, c, a, b) => Op::Select(n(d)?, n(c)?, n(a)?, n(b)?),
            Op::MulAdd(d, a, b, c) => Op::MulAdd(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::MulSub(d, a, b, c) => Op::MulSub(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::SubMul(d, a, b, c) => Op::SubMul(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::AddMul(d, a, b, c) => Op::AddMul(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::SubThenMul(d, a, b, c) => Op::SubThenMul(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::MulMul(d, a, b, c) => Op::MulMul(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::DivAdd(d, a, b, c) => Op::DivAdd(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::DivSub(d, a, b, c) => Op::DivSub(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::SubDiv(d, a, b, c) => Op::SubDiv(n(d)?, n(a)?, n(b)?, n(c)?),
            Op::Branch(c, k) => Op::Branch(n(c)?, k),
            Op::Skip(k) => Op::Skip(k),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tape of x, y with parts that depend on x only, on y only, on both,
    /// and a branch whose sides need expressions of their own.
    fn sample() -> (Graph, Tape) {
        let mut g = Graph::new();
        let (x, y) = (g.symbol("x"), g.symbol("y"));
        let ex = g.exp(x);
        let three = g.constant(3.0);
        let x3 = g.add(ex, three);
        let ly = g.mul(y, y);
        let one = g.one();
        let ly1 = g.add(ly, one);
        let lny = g.ln(ly1);
        let xy = g.mul(x3, lny);
        // x ≥ 0: sqrt(x)·y + 1, else y/(1 + x²)
        let sx = g.sqrt(x);
        let sxy = g.mul(sx, y);
        let a = g.add(sxy, one);
        let x2 = g.mul(x, x);
        let d = g.add(x2, one);
        let b = g.div(y, d);
        let sel = g.select(x, a, b);
        let tape = Tape::compile(&g, &[x, y], &[xy, sel, lny]).unwrap();
        (g, tape)
    }

    fn fresh(tape: &Tape, inputs: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; tape.n_outputs()];
        tape.eval(inputs, &mut tape.scratch(), &mut out);
        out
    }

    const POINTS: [[f64; 2]; 7] = [
        [0.5, 2.0],
        [0.5, 3.0],
        [-0.5, 3.0],
        [-0.5, 3.0],
        [0.25, -1.0],
        [-0.0, -1.0],
        [0.0, 7.0],
    ];

    #[test]
    fn reused_scratch_skips_nothing_it_needs() {
        let (_, tape) = sample();
        let mut scratch = tape.scratch();
        let mut out = vec![0.0; 3];
        for p in POINTS {
            tape.eval(&p, &mut scratch, &mut out);
            let want = fresh(&tape, &p);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&out), bits(&want), "at {p:?}");
        }
    }

    #[test]
    fn branches_compute_only_one_side_and_match_the_graph() {
        let (_, tape) = sample();
        assert!(tape.instrs().iter().any(|i| matches!(i, Instr::Branch(..))));
        for [xv, yv] in POINTS {
            let out = fresh(&tape, &[xv, yv]);
            let want = if xv >= 0.0 {
                xv.sqrt() * yv + 1.0
            } else {
                yv / (xv * xv + 1.0)
            };
            assert!(
                (out[1] - want).abs() <= 1e-15 * want.abs().max(1.0),
                "{xv} {yv}"
            );
        }
    }

    #[test]
    fn eval_many_matches_eval_bit_for_bit() {
        let (_, tape) = sample();
        // Enough points for several groups of lanes, with repeats and a
        // partial last group; mixed branch sides inside a group.
        let pts: Vec<[f64; 2]> = (0..3 * LANES + 5)
            .map(|k| POINTS[(k * 5 / 3) % 7])
            .collect();
        // Input 0 as a plain column, input 1 strided in the points themselves.
        let xs: Vec<f64> = pts.iter().map(|p| p[0]).collect();
        let flat = pts.as_flattened();
        let mut out = vec![0.0; 3 * pts.len()];
        tape.eval_many(&[(&xs, 1, 0), (flat, 2, 1)], &mut out);
        for (k, p) in pts.iter().enumerate() {
            let want = fresh(&tape, p);
            for j in 0..3 {
                assert_eq!(
                    out[j * pts.len() + k].to_bits(),
                    want[j].to_bits(),
                    "{p:?} #{j}"
                );
            }
        }
    }

    #[test]
    fn fused_pairs_round_like_the_pairs() {
        let mut g = Graph::new();
        let (a, b, c) = (g.symbol("a"), g.symbol("b"), g.symbol("c"));
        let ab = g.mul(a, b);
        let ab_c = g.add(ab, c);
        let ac = g.mul(a, c);
        let c_ac = g.sub(c, ac);
        let apb = g.add(a, b);
        let apb_c = g.mul(apb, c);
        let tape = Tape::compile(&g, &[a, b, c], &[ab_c, c_ac, apb_c]).unwrap();
        let fused =
            |i: &Instr| matches!(i, Instr::MulAdd(..) | Instr::SubMul(..) | Instr::AddMul(..));
        assert_eq!(
            tape.instrs().iter().filter(|i| fused(i)).count(),
            3,
            "{:?}",
            tape.instrs()
        );
        for (av, bv, cv) in [
            (0.1, 0.7, -0.3),
            (1e300, 1e10, -1.0),
            (3.0, 1.0 / 3.0, 1e-17),
        ] {
            let out = fresh(&tape, &[av, bv, cv]);
            assert_eq!(out[0].to_bits(), (av * bv + cv).to_bits());
            assert_eq!(out[1].to_bits(), (cv - av * cv).to_bits());
            assert_eq!(out[2].to_bits(), ((av + bv) * cv).to_bits());
        }
    }
}
