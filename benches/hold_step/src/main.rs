//! Bench driver of `benches/hold_step.sh` (see `benches/hold_step/run.py`).
//!
//!     hold-step-bench dump            per sample of the record: the estimates of
//!                                     both UKFs, the holds' outputs, CSV on stdout
//!     hold-step-bench KIND N REPS     N calls of KIND, REPS times; prints
//!                                     `best_ns_per_call=<f> checksum=<f>`
//!
//! KIND, over the samples of the record (build.rs: the designed closed loop
//! of `examples/jiles-atherton-valve.toml`), cycling:
//! - ukf64, ukf32: `ukf::f…::Filter::step(u, i)` of the generated UKF
//!   [JA 84–87] on the record's voltage and current, the filter carried on
//!   across cycles;
//! - hold64, hold32: `f…::Controller::step(z, v, phi, hc)` of the generated
//!   position hold on the record's estimates: the stop rules [JA 94], the
//!   φ guard, else the law [JA 89], saturated;
//! - law64, law32: the law [JA 89] alone (`hold::Hold::law` of the emitted
//!   `Design`) at every sample: what a step costs in motion;
//! - ukfx64, ukfx32: the UKF of the sensorless design at 20 kHz
//!   (`tests/data/sensorless-ja-valve.toml`: [z, z_prev, φ, H_c, R], the
//!   exponential flux step with 4 substeps) on its own loop's voltage and
//!   current (`record_ja`, as long as the record);
//! - ukfo64, ukfo32: the same with one exponential substep per sample;
//! - base64, base32: the same loop without the call.
//!
//! The record is the same in every run, so a run of 2N calls minus one of N
//! leaves exactly N calls (N a multiple of the record's length).

use std::hint::black_box;
use std::time::Instant;

use reldesign_runtime::hold::Hold;

mod record {
    include!(concat!(env!("OUT_DIR"), "/record.rs"));
}
mod record_ja {
    include!(concat!(env!("OUT_DIR"), "/record_ja.rs"));
}
// the sensorless design at 20 kHz: its UKF with the exponential flux step
#[allow(clippy::all, dead_code)]
mod sensorless {
    include!(concat!(env!("OUT_DIR"), "/sensorless_ja_valve.rs"));
}
// the same with one substep per sample
#[allow(clippy::all, dead_code)]
mod sensorless_one {
    include!(concat!(env!("OUT_DIR"), "/sensorless_ja_valve_1.rs"));
}
// the generated file holds more than the driver calls
#[allow(clippy::all, dead_code)]
mod valve {
    include!(concat!(env!("OUT_DIR"), "/jiles_atherton_valve.rs"));
}
use valve::ukf;

use record::RECORD;

/// `n` calls of `$call(&mut state, row)` over the record, cycling.
macro_rules! record_loop {
    ($name:ident, $f:ty, $make:expr, $call:ident) => {
        fn $name(rec: &[[$f; 6]], n: usize) -> f64 {
            let mut state = $make;
            let mut acc: $f = 0.0;
            let mut k = 0;
            for _ in 0..n {
                acc += $call(&mut state, *black_box(&rec[k]));
                k += 1;
                if k == rec.len() {
                    k = 0;
                }
            }
            black_box(acc) as f64
        }
    };
}

/// `$name`: one step of the filter `$filter` on a row [u, i, …], its ẑ.
macro_rules! filter_call {
    ($name:ident, $filter:ty, $f:ty) => {
        #[inline(always)]
        fn $name(f: &mut $filter, r: [$f; 6]) -> $f {
            black_box(f.step(r[0], r[1])).z
        }
    };
}
/// One call of each kind on a row [u, i, ẑ, v̂, φ̂, Ĥ_c] of the record.
macro_rules! calls {
    ($f:ident, $filter:ident, $hold:ident, $law:ident, $base:ident) => {
        filter_call!($filter, ukf::$f::Filter, $f);
        #[inline(always)]
        fn $hold(c: &mut valve::$f::Controller, r: [$f; 6]) -> $f {
            c.step(r[2], r[3], r[4], r[5])
        }
        #[inline(always)]
        fn $law(d: &mut valve::$f::Design, r: [$f; 6]) -> $f {
            d.law(
                [r[2], r[3], r[4], r[5]],
                [valve::$f::POSITION, 0.0, 0.0, 0.0],
            )
        }
        #[inline(always)]
        fn $base(_: &mut (), r: [$f; 6]) -> $f {
            r[0] + r[2]
        }
    };
}
calls!(f64, filter64, hold_step64, law_alone64, nothing64);
calls!(f32, filter32, hold_step32, law_alone32, nothing32);

filter_call!(exp_filter64, sensorless::ukf::f64::Filter, f64);
filter_call!(exp_filter32, sensorless::ukf::f32::Filter, f32);
filter_call!(one_filter64, sensorless_one::ukf::f64::Filter, f64);
filter_call!(one_filter32, sensorless_one::ukf::f32::Filter, f32);
record_loop!(ukfx64, f64, sensorless::ukf::f64::Filter::new(), exp_filter64);
record_loop!(ukfx32, f32, sensorless::ukf::f32::Filter::new(), exp_filter32);
record_loop!(ukfo64, f64, sensorless_one::ukf::f64::Filter::new(), one_filter64);
record_loop!(ukfo32, f32, sensorless_one::ukf::f32::Filter::new(), one_filter32);

record_loop!(ukf64, f64, ukf::f64::Filter::new(), filter64);
record_loop!(ukf32, f32, ukf::f32::Filter::new(), filter32);
record_loop!(hold64, f64, valve::f64::Controller::new(), hold_step64);
record_loop!(hold32, f32, valve::f32::Controller::new(), hold_step32);
record_loop!(law64, f64, valve::f64::Design, law_alone64);
record_loop!(law32, f32, valve::f32::Design, law_alone32);
record_loop!(base64, f64, (), nothing64);
record_loop!(base32, f32, (), nothing32);

/// Whether the hold evaluates its law [JA 89] at the estimate `r`: not at a
/// stop [JA 94], φ above the guard.
fn law_runs(r: &[f64; 6]) -> bool {
    let s = valve::f64::Design.settings();
    reldesign_runtime::hold::stop_rule(&s, r[2]).is_none() && r[4] > s.phi_guard
}

fn dump(rec64: &[[f64; 6]], rec32: &[[f32; 6]]) {
    println!("k,ukf64_z,ukf32_z,ukf64_phi,ukf32_phi,ukf32_repairs,hold64_u,hold32_u,law_runs");
    let (mut f64f, mut f32f) = (ukf::f64::Filter::new(), ukf::f32::Filter::new());
    let (c64, c32) = (valve::f64::Controller::new(), valve::f32::Controller::new());
    for (k, (r, s)) in rec64.iter().zip(rec32).enumerate() {
        let (a, b) = (f64f.step(r[0], r[1]), f32f.step(s[0], s[1]));
        let (u, v) = (
            c64.step(r[2], r[3], r[4], r[5]),
            c32.step(s[2], s[3], s[4], s[5]),
        );
        println!(
            "{k},{:e},{:e},{:e},{:e},{},{u:e},{v:e},{}",
            a.z,
            b.z,
            a.phi,
            b.phi,
            f32f.repairs(),
            u8::from(law_runs(r))
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rec64: Vec<[f64; 6]> = RECORD.to_vec();
    let rec32: Vec<[f32; 6]> = RECORD.iter().map(|s| s.map(|x| x as f32)).collect();
    let ja64: Vec<[f64; 6]> = record_ja::RECORD.to_vec();
    let ja32: Vec<[f32; 6]> = ja64.iter().map(|s| s.map(|x| x as f32)).collect();
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
            "ukf64" => ukf64(&rec64, n),
            "ukf32" => ukf32(&rec32, n),
            "ukfx64" => ukfx64(&ja64, n),
            "ukfx32" => ukfx32(&ja32, n),
            "ukfo64" => ukfo64(&ja64, n),
            "ukfo32" => ukfo32(&ja32, n),
            "hold64" => hold64(&rec64, n),
            "hold32" => hold32(&rec32, n),
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
