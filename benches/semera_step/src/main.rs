//! Bench driver of `benches/semera_step.sh` (see `benches/semera_step/run.py`).
//!
//!     semera-step-bench KIND N REPS    N calls of KIND, REPS times; prints
//!                                      `best_ns_per_call=<f> checksum=<f>`
//!
//! KIND: semera64 semera32 integral64 integral32 (`step` of the runtime's
//! estimator, with the generated settings, on the samples of `record.csv`, cycling), base64 base32 (the
//! same loop without the call: loop overhead). The record (801 samples of a
//! noisy two-cycle square-wave experiment, see build.rs) is parsed at start
//! up, identically in every run, so callgrind's N vs 2N difference removes it.

use std::hint::black_box;
use std::time::Instant;

#[allow(clippy::all, dead_code)]
mod semera {
    include!(concat!(env!("OUT_DIR"), "/semera.rs"));
}

use semera::estimators::{f32 as s32, f64 as s64};

fn record() -> Vec<[f64; 2]> {
    include_str!(concat!(env!("OUT_DIR"), "/record.csv"))
        .lines()
        .map(|l| {
            let mut it = l.split(' ').map(|x| x.parse::<f64>().expect("number"));
            [it.next().expect("v"), it.next().expect("i")]
        })
        .collect()
}

macro_rules! step_loop {
    ($name:ident, $f:ty, $make:expr) => {
        fn $name(x: &[[$f; 2]], n: usize) -> f64 {
            let mut est = $make;
            let mut acc: $f = 0.0;
            let mut k = 0;
            for _ in 0..n {
                let [v, i] = *black_box(&x[k]);
                let e = est.step(v, i);
                acc += e.lambda;
                k += 1;
                if k == x.len() {
                    k = 0;
                }
            }
            black_box(acc) as f64
        }
    };
}

step_loop!(semera64, f64, s64::Semera::new(&s64::SEMERA));
step_loop!(semera32, f32, s32::Semera::new(&s32::SEMERA));
step_loop!(integral64, f64, s64::Integral::new(&s64::INTEGRAL));
step_loop!(integral32, f32, s32::Integral::new(&s32::INTEGRAL));

/// The loop without the estimator: the sample's current is "the estimate".
struct Base;
struct BaseEstimate<F> {
    lambda: F,
}
impl Base {
    #[inline(always)]
    fn step<F>(&mut self, _v: F, i: F) -> BaseEstimate<F> {
        BaseEstimate { lambda: i }
    }
}
step_loop!(base64, f64, Base);
step_loop!(base32, f32, Base);

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: {} KIND N REPS", args[0]);
        std::process::exit(2);
    }
    let x64 = record();
    let x32: Vec<[f32; 2]> = x64.iter().map(|s| s.map(|a| a as f32)).collect();
    let kind = args[1].as_str();
    let n: usize = args[2].parse().expect("N");
    let reps: usize = args[3].parse().expect("REPS");
    let run = |n: usize| -> f64 {
        match kind {
            "semera64" => semera64(&x64, n),
            "semera32" => semera32(&x32, n),
            "integral64" => integral64(&x64, n),
            "integral32" => integral32(&x32, n),
            "base64" => base64(&x64, n),
            "base32" => base32(&x32, n),
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
