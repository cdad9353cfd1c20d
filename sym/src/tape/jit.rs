//! A tape compiled to machine code at run time (Cranelift), with the
//! interpreter's results bit for bit: the same IEEE operations in the same
//! order (no fused multiply-add, no reassociation), and the library
//! functions (`exp`, `ln`, `tanh`, `powi`, `powf`, `min`, `max`, `sign`)
//! called through the same Rust functions the interpreter calls. (A NaN is
//! a NaN in both, but which operand's payload or sign it carries may
//! differ where either compiler swaps a commutative operation's operands;
//! Rust does not fix those bits either.)
//!
//! Why: the interpreter's cost is its dispatch, one indirect branch per
//! instruction (issue 36 §2: 41–48 % of a diagnosis in `Tape::eval`).
//! Compiled, an instruction is its arithmetic, a store and the loads its
//! block has not computed yet.
//!
//! **Layout.** One function per tape, `fn(slots, changed)`: each group of
//! the layout runs where `changed` meets its inputs' mask, exactly as
//! [`super::Tape::eval`] runs the interpreter on them; every result is
//! stored to its slot (the scratch keeps them for the next evaluation), and
//! within a straight-line block an operand computed there is taken from its
//! register. A `Branch` becomes two blocks; what they compute is read back
//! from the slots, as the interpreter's `Select` does.
//!
//! **Cache.** Machine code depends on the instructions alone (constants
//! live in the slots), and a fit compiles the same tape for every trial
//! description: the compiled functions are shared by instructions
//! ([`compiled`]). Where the host has no Cranelift backend, or compiling
//! fails, the interpreter runs; `RELDESIGN_INTERPRET=1` forces it (for
//! measurements).

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{types, AbiParam, InstBuilder, MemFlags, Signature, Value};
use cranelift_codegen::isa::OwnedTargetIsa;
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{Linkage, Module};

use super::{Group, Instr, Op};
use crate::graph::Func;

/// A compiled tape: `run(slots, changed)`.
pub(super) struct Compiled {
    run: extern "C" fn(*mut f64, u64),
    /// The slots the code reads and writes: `0..n_slots`.
    n_slots: usize,
    /// Owns the executable memory of `run`; freed on drop.
    module: Option<JITModule>,
}

// SAFETY: after `finalize_definitions` the module's memory is only executed
// (never written) until `Compiled` is dropped, and `run` reads and writes
// nothing but the slots it is given: calling it from several threads at once,
// each on its own slots, shares nothing mutable.
unsafe impl Send for Compiled {}
unsafe impl Sync for Compiled {}

impl Drop for Compiled {
    fn drop(&mut self) {
        if let Some(module) = self.module.take() {
            // SAFETY: `run` points into this module and dies with `self`;
            // no other pointer into it was handed out.
            unsafe { module.free_memory() };
        }
    }
}

impl super::Compiled for Compiled {
    /// Runs the groups of the tape whose inputs meet `changed` on `slots`.
    #[inline]
    fn run(&self, slots: &mut [f64], changed: u64) {
        assert!(slots.len() >= self.n_slots, "tape: scratch too short");
        // (the code touches slots 0..n_slots only, checked above)
        (self.run)(slots.as_mut_ptr(), changed);
    }
}

impl std::fmt::Debug for Compiled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Compiled({} slots)", self.n_slots)
    }
}

/// What a compiled function depends on.
type Key = (Vec<Instr>, Vec<Group>, usize);

/// Distinct tapes kept compiled; past it the cache starts again (a
/// long-running process, e.g. the Python binding, sees many descriptions).
const CACHE_ENTRIES: usize = 1024;

/// The tape's compiled function, from the cache or compiled now (None:
/// interpret).
pub(super) fn compiled(
    instrs: &[Instr],
    groups: &[Group],
    n_slots: usize,
) -> Option<Arc<Compiled>> {
    static DISABLED: OnceLock<bool> = OnceLock::new();
    if *DISABLED.get_or_init(|| std::env::var_os("RELDESIGN_INTERPRET").is_some_and(|v| v == "1")) {
        return None;
    }
    static CACHE: OnceLock<Mutex<HashMap<Key, Option<Arc<Compiled>>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    // (a lock poisoned by a panic elsewhere holds a valid map all the same)
    let lock = || {
        cache
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    };
    let key: Key = (instrs.to_vec(), groups.to_vec(), n_slots);
    if let Some(hit) = lock().get(&key) {
        return hit.clone();
    }
    // (a tape the code generator cannot take, or a panic inside it, leaves
    // the tape to the interpreter)
    let made = std::panic::catch_unwind(|| compile(instrs, groups, n_slots))
        .ok()
        .flatten()
        .map(Arc::new);
    let mut cache = lock();
    if cache.len() >= CACHE_ENTRIES {
        cache.clear();
    }
    cache.entry(key).or_insert(made).clone()
}

/// Compiles the tape, or None where this host has no backend or an operand
/// lies outside the slots (the code's memory safety rests on that).
fn compile(instrs: &[Instr], groups: &[Group], n_slots: usize) -> Option<Compiled> {
    let inside = |s: u32| (s as usize) < n_slots && byte_offset(s).is_some();
    if !instrs.iter().all(|i| super::layout::slots(i).all(&inside)) {
        return None;
    }
    let mut module = JITModule::new(JITBuilder::with_isa(
        host()?,
        cranelift_module::default_libcall_names(),
    ));
    let mut ctx = module.make_context();
    let pointer = module.target_config().pointer_type();
    ctx.func.signature.params.push(AbiParam::new(pointer));
    ctx.func.signature.params.push(AbiParam::new(types::I64));
    let id = module
        .declare_function("tape", Linkage::Local, &ctx.func.signature)
        .ok()?;
    let mut builder_ctx = FunctionBuilderContext::new();
    let mut b = FunctionBuilder::new(&mut ctx.func, &mut builder_ctx);
    let entry = b.create_block();
    b.append_block_params_for_function_params(entry);
    b.switch_to_block(entry);
    b.seal_block(entry);
    let (slots, changed) = (b.block_params(entry)[0], b.block_params(entry)[1]);
    let mut emitter = Emitter {
        b,
        slots,
        pointer,
        known: HashMap::new(),
    };
    for g in groups {
        emitter.group(g, &instrs[g.start as usize..g.end as usize], changed);
    }
    emitter.b.ins().return_(&[]);
    emitter.b.finalize();
    module.define_function(id, &mut ctx).ok()?;
    module.clear_context(&mut ctx);
    module.finalize_definitions().ok()?;
    let code = module.get_finalized_function(id);
    // SAFETY: `code` is the function just defined with the signature
    // (pointer, i64) → (), the C calling convention of this host's ISA.
    let run = unsafe { std::mem::transmute::<*const u8, extern "C" fn(*mut f64, u64)>(code) };
    Some(Compiled {
        run,
        n_slots,
        module: Some(module),
    })
}

/// The function being built, and the slots' values known in the current
/// block.
struct Emitter<'a> {
    b: FunctionBuilder<'a>,
    slots: Value,
    pointer: types::Type,
    /// Slot → its value, computed or loaded in the current block (or one
    /// that dominates it).
    known: HashMap<u32, Value>,
}

impl Emitter<'_> {
    /// `if changed & mask != 0 { code }`.
    fn group(&mut self, g: &Group, code: &[Instr], changed: Value) {
        let (run, next) = (self.b.create_block(), self.b.create_block());
        let hit = self.b.ins().band_imm(changed, g.mask as i64);
        self.b.ins().brif(hit, run, &[], next, &[]);
        self.b.seal_block(run);
        self.b.switch_to_block(run);
        self.known.clear();
        self.straight(code);
        self.b.ins().jump(next, &[]);
        self.b.seal_block(next);
        self.b.switch_to_block(next);
        self.known.clear();
    }

    /// The instructions `code`, branches included.
    fn straight(&mut self, code: &[Instr]) {
        let mut k = 0;
        while k < code.len() {
            match code[k] {
                Op::Branch(c, n) => {
                    let n = n as usize;
                    let Op::Skip(m) = code[k + n] else {
                        unreachable!("the first block of a branch ends with a skip")
                    };
                    let m = m as usize;
                    let (taken, other) = (&code[k + 1..k + n], &code[k + n + 1..k + n + 1 + m]);
                    self.branch(c, taken, other);
                    k += n + 1 + m;
                }
                Op::Skip(_) => unreachable!("a skip ends the first block of a branch"),
                ins => {
                    self.instruction(ins);
                    k += 1;
                }
            }
        }
    }

    /// `if c ≥ 0 { taken } else { other }` (NaN: `other`, as the interpreter).
    fn branch(&mut self, c: u32, taken: &[Instr], other: &[Instr]) {
        let c = self.slot(c);
        let zero = self.b.ins().f64const(0.0);
        let ge = self.b.ins().fcmp(FloatCC::GreaterThanOrEqual, c, zero);
        let (yes, no, join) = (
            self.b.create_block(),
            self.b.create_block(),
            self.b.create_block(),
        );
        self.b.ins().brif(ge, yes, &[], no, &[]);
        let before = self.known.clone();
        for (block, code) in [(yes, taken), (no, other)] {
            self.b.seal_block(block);
            self.b.switch_to_block(block);
            self.known = before.clone();
            self.straight(code);
            self.b.ins().jump(join, &[]);
        }
        self.b.seal_block(join);
        self.b.switch_to_block(join);
        self.known = before;
    }

    /// One instruction other than a branch: its value, stored to its slot.
    fn instruction(&mut self, ins: Instr) {
        let (d, v) = match ins {
            Op::Add(d, a, b) => (d, self.binary(a, b, |i, x, y| i.ins().fadd(x, y))),
            Op::Sub(d, a, b) => (d, self.binary(a, b, |i, x, y| i.ins().fsub(x, y))),
            Op::Mul(d, a, b) => (d, self.binary(a, b, |i, x, y| i.ins().fmul(x, y))),
            Op::Div(d, a, b) => (d, self.binary(a, b, |i, x, y| i.ins().fdiv(x, y))),
            Op::Neg(d, a) => {
                let x = self.slot(a);
                (d, self.b.ins().fneg(x))
            }
            Op::Recip(d, a) => {
                let (one, x) = (self.b.ins().f64const(1.0), self.slot(a));
                (d, self.b.ins().fdiv(one, x))
            }
            Op::Powi(d, a, n) => {
                let (x, n) = (self.slot(a), self.b.ins().iconst(types::I32, i64::from(n)));
                (
                    d,
                    self.call(address_powi(powi), &[types::F64, types::I32], &[x, n]),
                )
            }
            Op::Powf(d, a, b) => (d, self.call2(address2(powf), a, b)),
            Op::Func(f, d, a) => {
                let x = self.slot(a);
                let v = match f {
                    Func::Sqrt => self.b.ins().sqrt(x),
                    Func::Abs => self.b.ins().fabs(x),
                    _ => self.call(func_address(f), &[types::F64], &[x]),
                };
                (d, v)
            }
            Op::Min(d, a, b) => (d, self.call2(address2(min), a, b)),
            Op::Max(d, a, b) => (d, self.call2(address2(max), a, b)),
            Op::Select(d, c, a, b) => {
                let (c, x, y) = (self.slot(c), self.slot(a), self.slot(b));
                let zero = self.b.ins().f64const(0.0);
                let ge = self.b.ins().fcmp(FloatCC::GreaterThanOrEqual, c, zero);
                (d, self.b.ins().select(ge, x, y))
            }
            Op::MulAdd(d, a, b, c) => (d, self.fused(a, b, c, Fused::MulAdd)),
            Op::MulSub(d, a, b, c) => (d, self.fused(a, b, c, Fused::MulSub)),
            Op::SubMul(d, c, a, b) => (d, self.fused(a, b, c, Fused::SubMul)),
            Op::AddMul(d, a, b, c) => (d, self.fused(a, b, c, Fused::AddMul)),
            Op::SubThenMul(d, a, b, c) => (d, self.fused(a, b, c, Fused::SubThenMul)),
            Op::MulMul(d, a, b, c) => (d, self.fused(a, b, c, Fused::MulMul)),
            Op::DivAdd(d, a, b, c) => (d, self.fused(a, b, c, Fused::DivAdd)),
            Op::DivSub(d, a, b, c) => (d, self.fused(a, b, c, Fused::DivSub)),
            Op::SubDiv(d, c, a, b) => (d, self.fused(a, b, c, Fused::SubDiv)),
            Op::Branch(..) | Op::Skip(_) => unreachable!("handled by `straight`"),
        };
        let offset = slot_offset(d);
        self.b
            .ins()
            .store(MemFlags::trusted(), v, self.slots, offset);
        self.known.insert(d, v);
    }

    /// The value of slot `s`: known in this block, or loaded.
    fn slot(&mut self, s: u32) -> Value {
        if let Some(&v) = self.known.get(&s) {
            return v;
        }
        let v = (self.b.ins()).load(types::F64, MemFlags::trusted(), self.slots, slot_offset(s));
        self.known.insert(s, v);
        v
    }

    fn binary(
        &mut self,
        a: u32,
        b: u32,
        op: impl FnOnce(&mut FunctionBuilder, Value, Value) -> Value,
    ) -> Value {
        let (x, y) = (self.slot(a), self.slot(b));
        op(&mut self.b, x, y)
    }

    /// A fused pair, as its two operations in the interpreter's order (`a`,
    /// `b` the first operation's operands, `c` the second's other one).
    fn fused(&mut self, a: u32, b: u32, c: u32, kind: Fused) -> Value {
        let (x, y, z) = (self.slot(a), self.slot(b), self.slot(c));
        let i = &mut self.b;
        match kind {
            Fused::MulAdd => {
                let p = i.ins().fmul(x, y);
                i.ins().fadd(p, z)
            }
            Fused::MulSub => {
                let p = i.ins().fmul(x, y);
                i.ins().fsub(p, z)
            }
            Fused::SubMul => {
                let p = i.ins().fmul(x, y);
                i.ins().fsub(z, p)
            }
            Fused::AddMul => {
                let s = i.ins().fadd(x, y);
                i.ins().fmul(s, z)
            }
            Fused::SubThenMul => {
                let s = i.ins().fsub(x, y);
                i.ins().fmul(s, z)
            }
            Fused::MulMul => {
                let p = i.ins().fmul(x, y);
                i.ins().fmul(p, z)
            }
            Fused::DivAdd => {
                let q = i.ins().fdiv(x, y);
                i.ins().fadd(q, z)
            }
            Fused::DivSub => {
                let q = i.ins().fdiv(x, y);
                i.ins().fsub(q, z)
            }
            Fused::SubDiv => {
                let q = i.ins().fdiv(x, y);
                i.ins().fsub(z, q)
            }
        }
    }

    fn call2(&mut self, f: usize, a: u32, b: u32) -> Value {
        let (x, y) = (self.slot(a), self.slot(b));
        self.call(f, &[types::F64, types::F64], &[x, y])
    }

    /// A call of the Rust function at `address` with `args` of `params`
    /// types, returning an f64.
    fn call(&mut self, address: usize, params: &[types::Type], args: &[Value]) -> Value {
        let call_conv = self.b.func.signature.call_conv;
        let mut sig = Signature::new(call_conv);
        // (an i32 argument sign-extended, as the C ABIs of riscv64 and
        // s390x expect of the caller)
        let param = |t: &types::Type| match *t {
            types::I32 => AbiParam::new(types::I32).sext(),
            t => AbiParam::new(t),
        };
        sig.params.extend(params.iter().map(param));
        sig.returns.push(AbiParam::new(types::F64));
        let sig = self.b.import_signature(sig);
        let callee = self.b.ins().iconst(self.pointer, address as i64);
        let call = self.b.ins().call_indirect(sig, callee, args);
        self.b.inst_results(call)[0]
    }
}

/// The fused pairs of the layout (see [`Op`]).
#[derive(Clone, Copy)]
enum Fused {
    MulAdd,
    MulSub,
    SubMul,
    AddMul,
    SubThenMul,
    MulMul,
    DivAdd,
    DivSub,
    SubDiv,
}

/// The code generator for this host, made once (None: no backend here).
fn host() -> Option<OwnedTargetIsa> {
    static HOST: OnceLock<Option<OwnedTargetIsa>> = OnceLock::new();
    let made = || {
        let mut flags = settings::builder();
        flags.set("opt_level", "speed").ok()?;
        let builder = cranelift_native::builder().ok()?;
        builder.finish(settings::Flags::new(flags)).ok()
    };
    HOST.get_or_init(made).clone()
}

/// The byte offset of slot `s`, where it fits the loads' and stores' i32.
fn byte_offset(s: u32) -> Option<i32> {
    i32::try_from(8 * u64::from(s)).ok()
}

/// The byte offset of slot `s` ([`compile`] checked that it fits).
fn slot_offset(s: u32) -> i32 {
    byte_offset(s).expect("checked by `compile`")
}

extern "C" fn powi(x: f64, n: i32) -> f64 {
    x.powi(n)
}

extern "C" fn powf(x: f64, y: f64) -> f64 {
    x.powf(y)
}

extern "C" fn min(x: f64, y: f64) -> f64 {
    x.min(y)
}

extern "C" fn max(x: f64, y: f64) -> f64 {
    x.max(y)
}

extern "C" fn exp(x: f64) -> f64 {
    Func::Exp.apply(x)
}

extern "C" fn ln(x: f64) -> f64 {
    Func::Ln.apply(x)
}

extern "C" fn sign(x: f64) -> f64 {
    Func::Sign.apply(x)
}

extern "C" fn tanh(x: f64) -> f64 {
    Func::Tanh.apply(x)
}

extern "C" fn coth(x: f64) -> f64 {
    Func::Coth.apply(x)
}

/// The Rust function a call computes `f` with.
fn func_address(f: Func) -> usize {
    match f {
        Func::Exp => address1(exp),
        Func::Ln => address1(ln),
        Func::Sign => address1(sign),
        Func::Tanh => address1(tanh),
        Func::Coth => address1(coth),
        Func::Sqrt | Func::Abs => unreachable!("inline instructions"),
    }
}

fn address1(f: extern "C" fn(f64) -> f64) -> usize {
    f as usize
}

fn address2(f: extern "C" fn(f64, f64) -> f64) -> usize {
    f as usize
}

fn address_powi(f: extern "C" fn(f64, i32) -> f64) -> usize {
    f as usize
}

#[cfg(test)]
/// The compiled code against the interpreter, bit for bit: every
/// instruction, nested branches, groups skipped on a reused scratch, and
/// inputs at the edges of f64 (±0, subnormals, ±∞, NaN).
mod tests {
    use super::super::{Interpreted, Tape};
    use super::compile;
    use crate::graph::{Func, Graph, Id};

    /// A tape of x, y, z using every kind of instruction, with a branch
    /// inside a branch (a piecewise function of y inside a `select` on x).
    fn every_instruction() -> Tape {
        let mut g = Graph::new();
        let (x, y, z) = (g.symbol("x"), g.symbol("y"), g.symbol("z"));
        let mut outs: Vec<Id> = Vec::new();
        for f in Func::ALL {
            outs.push(g.func(f, x));
            let yz = g.add(y, z);
            outs.push(g.func(f, yz));
        }
        let xy = g.mul(x, y);
        let xy_z = g.add(xy, z);
        let z_xy = g.sub(z, xy);
        let x_y = g.div(x, y);
        let x_y_z = g.sub(x_y, z);
        let xpy = g.add(x, y);
        let xpy_z = g.mul(xpy, z);
        let xmy = g.sub(x, y);
        let xmy_z = g.mul(xmy, z);
        let xyz = g.mul(xy, z);
        outs.extend([xy_z, z_xy, x_y_z, xpy_z, xmy_z, xyz]);
        let (neg, recip, cube, inv2) = (g.neg(x), g.recip(y), g.powi(z, 3), g.powi(x, -2));
        let (pow, min, max) = (g.pow(y, z), g.min(x, z), g.max(y, z));
        outs.extend([neg, recip, cube, inv2, pow, min, max]);
        // y piecewise (a branch of its own), inside a select on x
        let sq = g.mul(y, y);
        let ey = g.exp(y);
        let ly = g.ln(sq);
        let pieces = [sq, ey, ly];
        let inner = g.piecewise(y, &[-1.0, 1.0], &pieces);
        let sx = g.sqrt(x);
        let a = g.mul(sx, inner);
        let tz = g.tanh(z);
        let b = g.div(tz, x);
        outs.push(g.select(x, a, b));
        Tape::compile(&g, &[x, y, z], &outs).unwrap()
    }

    const EDGES: [f64; 12] = [
        0.0,
        -0.0,
        0.5,
        -0.5,
        1.0,
        -3.0,
        2.5e-310,
        1e300,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        7.25,
    ];

    /// Both evaluators on one reused scratch each, point after point.
    fn compare(tape: &Tape, points: impl Iterator<Item = [f64; 3]>) -> usize {
        let code = compile(&tape.instrs, &tape.groups, tape.n_slots).expect("this host compiles");
        let (mut s_code, mut s_interp) = (tape.scratch(), tape.scratch());
        let n = tape.n_outputs();
        let (mut o_code, mut o_interp) = (vec![0.0; n], vec![0.0; n]);
        let mut compared = 0;
        for p in points {
            tape.eval_by(Some(&code), &p, &mut s_code, &mut o_code);
            tape.eval_by(None::<&Interpreted>, &p, &mut s_interp, &mut o_interp);
            for (j, (c, i)) in o_code.iter().zip(&o_interp).enumerate() {
                assert_eq!(c.to_bits(), i.to_bits(), "output {j} at {p:?}: {c} ≠ {i}");
            }
            compared += n;
        }
        compared
    }

    #[test]
    fn every_instruction_matches_the_interpreter_bit_for_bit() {
        let tape = every_instruction();
        let ops = |f: fn(&super::Instr) -> bool| tape.instrs().iter().any(f);
        assert!(ops(|i| matches!(i, super::Op::Branch(..))));
        let fused = |i: &super::Instr| {
            use super::Op::*;
            matches!(
                i,
                MulAdd(..)
                    | MulSub(..)
                    | SubMul(..)
                    | AddMul(..)
                    | SubThenMul(..)
                    | MulMul(..)
                    | DivAdd(..)
                    | DivSub(..)
                    | SubDiv(..)
            )
        };
        assert!(ops(fused), "{:?}", tape.instrs());
        // every triple of edge values, in an order that changes one input
        // at a time as often as all three (groups skipped and run)
        let points = (0..EDGES.len().pow(3)).map(|k| {
            let e = |d: usize| EDGES[(k / EDGES.len().pow(d as u32)) % EDGES.len()];
            [e(0), e(1), e(2)]
        });
        assert!(compare(&tape, points) > 10_000);
    }

    #[test]
    fn a_wide_tape_matches_the_interpreter() {
        // more than 256 slots: the interpreter's wide path
        let mut g = Graph::new();
        let (x, y, z) = (g.symbol("x"), g.symbol("y"), g.symbol("z"));
        let mut acc = x;
        let mut outs = Vec::new();
        for k in 0..300 {
            let c = g.constant(1.0 + k as f64 / 7.0);
            let t = g.mul(acc, c);
            let s = if k % 3 == 0 { g.tanh(t) } else { g.add(t, y) };
            acc = g.div(s, z);
            outs.push(acc);
        }
        let tape = Tape::compile(&g, &[x, y, z], &outs).unwrap();
        assert!(tape.n_slots > 256);
        let points = (0..400).map(|k| {
            let k = k as f64;
            [0.1 * k - 3.0, (0.37 * k).sin(), 1.0 + 0.01 * k]
        });
        compare(&tape, points);
    }
}
