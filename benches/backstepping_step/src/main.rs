//! Bench driver of `benches/backstepping_step.sh` (see
//! `benches/backstepping_step/run.py`).
//!
//!     backstepping-step-bench dump          per sample of the record: the steps'
//!                                           and the laws' outputs, the modes,
//!                                           the loop's own input and mode, CSV
//!     backstepping-step-bench KIND N REPS   N calls of KIND, REPS times; prints
//!                                           `best_ns_per_call=<f> checksum=<f>`
//!
//! KIND, over the samples of the record (build.rs: the designed closed loop
//! of `examples/backstepping-valve.toml`), cycling:
//! - step64, step32: `Controller::step(t, z, v, phi, 0.0)` of the generated
//!   controller on the record's states, the controller carried on across
//!   cycles and its time advancing as in the loop (each cycle of the record
//!   adds two periods of the square reference to t, so the reference's phase
//!   is the loop's): the reference, V ≤ C, F_d, the switching [SB 31–33], the
//!   φ guard, else the law [SB 19], saturated;
//! - law64, law32: the law [SB 19] alone (`law(z, v, phi, y_ref)`, y_ref the
//!   sample's reference) at every sample: what a step costs in the region;
//! - base64, base32: the same loop without the call.
//!
//! The record is the same in every run, so a run of 2N calls minus one of N
//! leaves exactly N calls (N a multiple of the record's length).

use std::hint::black_box;
use std::time::Instant;

use reldesign_runtime::backstepping::Mode;

mod record {
    include!(concat!(env!("OUT_DIR"), "/record.rs"));
}
// the generated file holds more than the driver calls
#[allow(clippy::all, dead_code)]
mod valve {
    include!(concat!(env!("OUT_DIR"), "/backstepping_valve.rs"));
}

use record::{LOOP, RECORD};

/// `n` calls of `$call(&mut state, row, offset)` over the record, cycling;
/// `offset` [s] advances by `$cycle` with each cycle.
macro_rules! record_loop {
    ($name:ident, $f:ty, $make:expr, $call:ident, $cycle:expr) => {
        fn $name(rec: &[[$f; 5]], n: usize) -> f64 {
            let mut state = $make;
            let mut acc: $f = 0.0;
            let mut offset: $f = 0.0;
            let mut k = 0;
            for _ in 0..n {
                acc += $call(&mut state, *black_box(&rec[k]), offset);
                k += 1;
                if k == rec.len() {
                    k = 0;
                    offset += $cycle;
                }
            }
            black_box(acc) as f64
        }
    };
}

/// One call of each kind on a row [t, z, v, φ, y_r] of the record.
macro_rules! calls {
    ($f:ident, $step:ident, $law:ident, $base:ident) => {
        #[inline(always)]
        fn $step(c: &mut valve::$f::Controller, r: [$f; 5], offset: $f) -> $f {
            c.step(r[0] + offset, r[1], r[2], r[3], 0.0)
        }
        #[inline(always)]
        fn $law(_: &mut (), r: [$f; 5], _: $f) -> $f {
            valve::$f::law(r[1], r[2], r[3], r[4])
        }
        #[inline(always)]
        fn $base(_: &mut (), r: [$f; 5], offset: $f) -> $f {
            (r[0] + offset) + r[1]
        }
    };
}
calls!(f64, step_call64, law_call64, nothing64);
calls!(f32, step_call32, law_call32, nothing32);

/// One cycle of the record: two periods of the square reference.
const CYCLE64: f64 = 2.0 * valve::f64::PERIOD;
const CYCLE32: f32 = 2.0 * valve::f32::PERIOD;

record_loop!(
    step64,
    f64,
    valve::f64::Controller::new(),
    step_call64,
    CYCLE64
);
record_loop!(
    step32,
    f32,
    valve::f32::Controller::new(),
    step_call32,
    CYCLE32
);
record_loop!(law64, f64, (), law_call64, CYCLE64);
record_loop!(law32, f32, (), law_call32, CYCLE32);
record_loop!(base64, f64, (), nothing64, CYCLE64);
record_loop!(base32, f32, (), nothing32, CYCLE32);

fn dump(rec64: &[[f64; 5]], rec32: &[[f32; 5]]) {
    println!(
        "k,t,phi,step64_u,step32_u,step64_mode,step32_mode,loop_u,loop_mode,\
         law64_u,law32_u,law_runs"
    );
    let (mut c64, mut c32) = (valve::f64::Controller::new(), valve::f32::Controller::new());
    for (k, ((r, s), (loop_u, loop_mode))) in rec64.iter().zip(rec32).zip(LOOP).enumerate() {
        let (u, w) = (
            c64.step(r[0], r[1], r[2], r[3], 0.0),
            c32.step(s[0], s[1], s[2], s[3], 0.0),
        );
        let (l, m) = (
            valve::f64::law(r[1], r[2], r[3], r[4]),
            valve::f32::law(s[1], s[2], s[3], s[4]),
        );
        // the f64 step evaluated its law at this sample
        let law_runs = c64.mode() != Mode::Waiting && r[3] > valve::f64::PHI_GUARD;
        println!(
            "{k},{:e},{:e},{u:e},{w:e},{},{},{loop_u:e},{loop_mode},{l:e},{m:e},{}",
            r[0],
            r[3],
            c64.mode() as u8,
            c32.mode() as u8,
            u8::from(law_runs)
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rec64: Vec<[f64; 5]> = RECORD.to_vec();
    let rec32: Vec<[f32; 5]> = RECORD.iter().map(|s| s.map(|x| x as f32)).collect();
    if args.len() == 2 && args[1] == "dump" {
        dump(&rec64, &rec32);
        return;
    }
    if args.len() != 4 {
        eprintln!("usage: {} dump | KIND N REPS", args[0]);
        std::process::exit(2);
    }
    let kind = args[1].as_str();
    let n: usize = args[2].parse().expect("N");
    let reps: usize = args[3].parse().expect("REPS");
    let run = |n: usize| -> f64 {
        match kind {
            "step64" => step64(&rec64, n),
            "step32" => step32(&rec32, n),
            "law64" => law64(&rec64, n),
            "law32" => law32(&rec32, n),
            "base64" => base64(&rec64, n),
            "base32" => base32(&rec32, n),
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
