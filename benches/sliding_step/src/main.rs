//! Bench driver of `benches/sliding_step.sh` (see `benches/sliding_step/run.py`).
//!
//!     sliding-step-bench KIND N REPS    N calls of KIND, REPS times; prints
//!                                       `best_ns_per_call=<f> checksum=<f>`
//!
//! KIND: step64 step32 (`Controller::step(t, z, v, a, phi)` of the generated
//! `sliding_mode_valve` controller, the runtime's model-free sliding-mode law
//! [SM 34] with its reference lookup), ref64 ref32 (`Controller::reference(t)`
//! alone: the lookup), base64 base32 (the same loop without the call: loop
//! overhead). Every kind runs over the samples of `record.csv` (the designed
//! closed loop, see build.rs), cycling: the first half with a
//! `Controller::new(Operation::Closing)`, the second with an `Opening` one,
//! each `start`ed at its operation's start when the record reaches it. The
//! record is parsed at start up, identically in every run, so callgrind's N vs
//! 2N difference removes it.

use std::hint::black_box;
use std::time::Instant;

#[allow(clippy::all, dead_code)]
mod sliding_mode_valve {
    include!(concat!(env!("OUT_DIR"), "/sliding_mode_valve.rs"));
}

use sliding_mode_valve::{f32 as c32, f64 as c64};

/// `t z v a phi` per sample; the index of the first sample of the opening.
fn record() -> (Vec<[f64; 5]>, usize) {
    let x: Vec<[f64; 5]> = include_str!(concat!(env!("OUT_DIR"), "/record.csv"))
        .lines()
        .map(|l| {
            let mut it = l.split(' ').map(|x| x.parse::<f64>().expect("number"));
            [(); 5].map(|()| it.next().expect("t z v a phi"))
        })
        .collect();
    // the closed loop's rule: an operation runs from the first sample at or after its start
    let opening = starts()[1];
    let split = x
        .iter()
        .position(|s| s[0] >= opening)
        .expect("opening samples");
    (x, split)
}

/// The closing's and the opening's start times [s] (build.rs).
fn starts() -> [f64; 2] {
    [env!("CLOSING_START"), env!("OPENING_START")].map(|s| s.parse().expect("start time"))
}

/// One call of a loop on the sample `s` = [t, z, v, a, φ]: the controller's
/// `step`, or its `reference` lookup alone.
macro_rules! call {
    (step, $c:expr, $s:expr) => {{
        let [t, z, v, a, phi] = $s;
        $c.step(t, z, v, a, phi)
    }};
    (reference, $c:expr, $s:expr) => {
        black_box($c.reference($s[0]))[0]
    };
}

/// `n` calls over the record `x` (closing before `split`, opening from it),
/// cycling; each operation's controller is started when the record reaches it.
macro_rules! record_loop {
    ($name:ident, $f:ty, $make:expr, $call:ident) => {
        fn $name(x: &[[$f; 5]], split: usize, starts: [$f; 2], n: usize) -> f64 {
            let mut ops = $make;
            let mut acc: $f = 0.0;
            let (mut k, mut op) = (0, 0);
            for _ in 0..n {
                if k == 0 {
                    op = 0;
                    ops[0].start(starts[0]);
                } else if k == split {
                    op = 1;
                    ops[1].start(starts[1]);
                }
                acc += call!($call, ops[op], *black_box(&x[k]));
                k += 1;
                if k == x.len() {
                    k = 0;
                }
            }
            black_box(acc) as f64
        }
    };
}

macro_rules! controllers {
    ($m:ident) => {
        [
            $m::Controller::new($m::Operation::Closing),
            $m::Controller::new($m::Operation::Opening),
        ]
    };
}

record_loop!(step64, f64, controllers!(c64), step);
record_loop!(step32, f32, controllers!(c32), step);
record_loop!(ref64, f64, controllers!(c64), reference);
record_loop!(ref32, f32, controllers!(c32), reference);

/// The loop without the controller: the sample's position is "the input".
struct Base;
impl Base {
    #[inline(always)]
    fn start<F>(&mut self, _t_start: F) {}
    #[inline(always)]
    fn step<F>(&mut self, _t: F, z: F, _v: F, _a: F, _phi: F) -> F {
        z
    }
}
record_loop!(base64, f64, [Base, Base], step);
record_loop!(base32, f32, [Base, Base], step);

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: {} KIND N REPS", args[0]);
        std::process::exit(2);
    }
    let (x64, split) = record();
    let x32: Vec<[f32; 5]> = x64.iter().map(|s| s.map(|a| a as f32)).collect();
    let (s64, s32) = (starts(), starts().map(|t| t as f32));
    let kind = args[1].as_str();
    let n: usize = args[2].parse().expect("N");
    let reps: usize = args[3].parse().expect("REPS");
    let run = |n: usize| -> f64 {
        match kind {
            "step64" => step64(&x64, split, s64, n),
            "step32" => step32(&x32, split, s32, n),
            "ref64" => ref64(&x64, split, s64, n),
            "ref32" => ref32(&x32, split, s32, n),
            "base64" => base64(&x64, split, s64, n),
            "base32" => base32(&x32, split, s32, n),
            _ => {
                eprintln!("unknown kind {kind}");
                std::process::exit(2);
            }
        }
    };
    let mut best = f64::INFINITY;
    let mut checksum = 0.0;
    for _ in 0..reps {
        let start = Instant::now();
        checksum = run(n);
        best = best.min(start.elapsed().as_nanos() as f64 / n as f64);
    }
    println!("best_ns_per_call={best} checksum={checksum:e}");
}
