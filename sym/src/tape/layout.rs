//! The layout of a compiled tape: instructions grouped by the inputs they
//! depend on (so that an evaluation can skip what did not change) and
//! consecutive pairs fused into one instruction (see the `tape` module docs).

use super::{Group, Instr};

/// A unit of the layout: what it depends on (bit i: input i) and its
/// instructions (one, or a whole `Branch` with its blocks and `Select`).
type Unit = (u64, Vec<Instr>);

/// Reorders `instrs` into groups of equal input dependence: a unit depends
/// on the inputs its operands depend on. Groups are ordered by the number of
/// inputs they depend on, so operands still come before their users. Pairs
/// of consecutive instructions outside branches are fused on the way (see
/// [`fuse`]).
pub(super) fn group_by_inputs(
    instrs: Vec<Instr>,
    n_inputs: usize,
    n_slots: usize,
    outputs: &[u32],
) -> (Vec<Instr>, Vec<Group>) {
    let mut units = fused_units(&instrs, n_inputs, &use_counts(&instrs, outputs, n_slots));
    if n_inputs > 64 {
        for u in &mut units {
            u.0 = u64::MAX;
        }
    }
    units.sort_by_key(|(mask, _)| (mask.count_ones(), *mask));
    let mut ordered = Vec::with_capacity(instrs.len());
    let mut groups: Vec<Group> = Vec::new();
    for (mask, unit) in units {
        let start = ordered.len() as u32;
        ordered.extend_from_slice(&unit);
        let end = ordered.len() as u32;
        match groups.last_mut() {
            Some(g) if g.mask == mask => g.end = end,
            _ => groups.push(Group { mask, start, end }),
        }
    }
    (ordered, groups)
}

/// How often each slot is read (outputs included).
fn use_counts(instrs: &[Instr], outputs: &[u32], n_slots: usize) -> Vec<u32> {
    let mut uses = vec![0u32; n_slots];
    for &o in outputs {
        uses[o as usize] += 1;
    }
    for ins in instrs {
        for &o in operands(ins).1.iter().flatten() {
            uses[o as usize] += 1;
        }
    }
    uses
}

/// The units of `instrs` in order, with the inputs each depends on, and
/// consecutive single instructions fused where [`fuse`] allows (a fused
/// pair depends on what the second instruction depends on).
fn fused_units(instrs: &[Instr], n_inputs: usize, uses: &[u32]) -> Vec<Unit> {
    let mut deps = vec![0u64; uses.len()];
    for (i, d) in deps.iter_mut().enumerate().take(n_inputs) {
        *d = 1u64.checked_shl(i as u32).unwrap_or(u64::MAX);
    }
    let mut units: Vec<Unit> = Vec::new();
    let mut i = 0;
    while i < instrs.len() {
        let end = match instrs[i] {
            Instr::Branch(_, n) => match instrs[i + n as usize] {
                Instr::Skip(nb) => i + n as usize + nb as usize + 2,
                _ => unreachable!("the first block of a branch ends with a skip"),
            },
            _ => i + 1,
        };
        let mask = unit_dependence(&instrs[i..end], &mut deps);
        let fused = match units.last() {
            Some((_, prev)) if prev.len() == 1 && end == i + 1 => fuse(prev[0], instrs[i], uses),
            _ => None,
        };
        match fused {
            Some(f) => *units.last_mut().expect("fused with the last unit") = (mask, vec![f]),
            None => units.push((mask, instrs[i..end].to_vec())),
        }
        i = end;
    }
    units
}

/// The inputs a unit depends on; records that of the slots it writes in
/// `deps` (the unit's result, its last instruction's, depends on all of it).
fn unit_dependence(unit: &[Instr], deps: &mut [u64]) -> u64 {
    let mut mask = 0;
    for ins in unit {
        let (dst, ops) = operands(ins);
        let m = ops.iter().flatten().fold(0, |m, &o| m | deps[o as usize]);
        if let Some(d) = dst {
            deps[d as usize] = m;
        }
        mask |= m;
    }
    if let Some(d) = unit.last().and_then(|ins| operands(ins).0) {
        deps[d as usize] = mask;
    }
    mask
}

/// `q` computing with the result of `p` directly, when that result is used
/// by `q` only: one instruction instead of two (the arithmetic, and so the
/// rounding, is the same).
fn fuse(p: Instr, q: Instr, uses: &[u32]) -> Option<Instr> {
    let (Some(r), _) = operands(&p) else {
        return None;
    };
    if uses[r as usize] != 1 {
        return None;
    }
    Some(match (p, q) {
        // a·b + c, c + a·b
        (Instr::Mul(_, a, b), Instr::Add(d, x, y)) if x == r => Instr::MulAdd(d, a, b, y),
        (Instr::Mul(_, a, b), Instr::Add(d, x, y)) if y == r => Instr::MulAdd(d, a, b, x),
        // a·b − c, c − a·b
        (Instr::Mul(_, a, b), Instr::Sub(d, x, y)) if x == r => Instr::MulSub(d, a, b, y),
        (Instr::Mul(_, a, b), Instr::Sub(d, x, y)) if y == r => Instr::SubMul(d, x, a, b),
        // (a + b)·c, (a − b)·c, a·b·c
        (Instr::Add(_, a, b), Instr::Mul(d, x, y)) if x == r || y == r => {
            Instr::AddMul(d, a, b, if x == r { y } else { x })
        }
        (Instr::Sub(_, a, b), Instr::Mul(d, x, y)) if x == r || y == r => {
            Instr::SubThenMul(d, a, b, if x == r { y } else { x })
        }
        (Instr::Mul(_, a, b), Instr::Mul(d, x, y)) if x == r || y == r => {
            Instr::MulMul(d, a, b, if x == r { y } else { x })
        }
        // a/b + c, c + a/b, a/b − c, c − a/b
        (Instr::Div(_, a, b), Instr::Add(d, x, y)) if x == r => Instr::DivAdd(d, a, b, y),
        (Instr::Div(_, a, b), Instr::Add(d, x, y)) if y == r => Instr::DivAdd(d, a, b, x),
        (Instr::Div(_, a, b), Instr::Sub(d, x, y)) if x == r => Instr::DivSub(d, a, b, y),
        (Instr::Div(_, a, b), Instr::Sub(d, x, y)) if y == r => Instr::SubDiv(d, x, a, b),
        _ => return None,
    })
}

/// Every slot an instruction writes or reads (the compiled code checks them).
#[cfg_attr(not(feature = "jit"), allow(dead_code))]
pub(super) fn slots(ins: &Instr) -> impl Iterator<Item = u32> {
    let (d, read) = operands(ins);
    d.into_iter().chain(read.into_iter().flatten())
}

/// The destination slot of an instruction and the slots it reads.
fn operands(ins: &Instr) -> (Option<u32>, [Option<u32>; 3]) {
    match *ins {
        Instr::Add(d, a, b)
        | Instr::Sub(d, a, b)
        | Instr::Mul(d, a, b)
        | Instr::Div(d, a, b)
        | Instr::Powf(d, a, b)
        | Instr::Min(d, a, b)
        | Instr::Max(d, a, b) => (Some(d), [Some(a), Some(b), None]),
        Instr::Neg(d, a) | Instr::Recip(d, a) | Instr::Powi(d, a, _) | Instr::Func(_, d, a) => {
            (Some(d), [Some(a), None, None])
        }
        Instr::Select(d, a, b, c)
        | Instr::MulAdd(d, a, b, c)
        | Instr::MulSub(d, a, b, c)
        | Instr::SubMul(d, a, b, c)
        | Instr::AddMul(d, a, b, c)
        | Instr::SubThenMul(d, a, b, c)
        | Instr::MulMul(d, a, b, c)
        | Instr::DivAdd(d, a, b, c)
        | Instr::DivSub(d, a, b, c)
        | Instr::SubDiv(d, a, b, c) => (Some(d), [Some(a), Some(b), Some(c)]),
        Instr::Branch(c, _) => (None, [Some(c), None, None]),
        Instr::Skip(_) => (None, [None; 3]),
    }
}
