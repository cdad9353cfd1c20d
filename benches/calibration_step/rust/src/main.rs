//! Bench driver of `benches/calibration_step.sh` (see `benches/calibration_step/run.py`).
//!
//!     calibration-step-bench sizes        RAM of the emitted types, bytes
//!     calibration-step-bench KIND N REPS  N calls of KIND, REPS times; prints
//!                                         `best_ns_per_call=<f> checksum=<f>`
//!
//! KIND:
//! - step{64,32}{fixed,adaptive}: one control sample, the UKF's `step(u, i)`
//!   then the controller's `step(t, ẑ, v̂, φ̂)`, over the run's record, cycled
//!   (closing from its start, opening from its half): the file emitted with
//!   every parameter a const (`fixed`) and with θ at run time (`adaptive`);
//! - base{64,32}: the loop without the calls;
//! - push{64,32}: `Record::push` of one sample (what the firmware adds to
//!   each control sample);
//! - update{64,32}: one whole update, `ukf::…::calibrate` on the run's record
//!   (from θ_d every call: the same work each time);
//! - law{64,32}{fixed,adaptive}: the replay example's (a law on measured
//!   states) controller step over its closing's states, folded and with θ;
//! - replaypush{64,32}: its `Record::push` of one sample (decimated);
//! - replay{64,32}: one whole replay update, `f…::calibrate` on the closing's
//!   record (from θ_d every call).

use std::hint::black_box;
use std::time::Instant;

mod record {
    include!(concat!(env!("OUT_DIR"), "/record.rs"));
}
#[allow(dead_code, clippy::all)]
mod adaptive {
    include!(concat!(env!("OUT_DIR"), "/adaptive.rs"));
}
#[allow(dead_code, clippy::all)]
mod fixed {
    include!(concat!(env!("OUT_DIR"), "/fixed.rs"));
}

use record::RECORD;

mod sensor_record {
    include!(concat!(env!("OUT_DIR"), "/sensor_record.rs"));
}
#[allow(dead_code, clippy::all)]
mod sensor_adaptive {
    include!(concat!(env!("OUT_DIR"), "/sensor_adaptive.rs"));
}
#[allow(dead_code, clippy::all)]
mod sensor_fixed {
    include!(concat!(env!("OUT_DIR"), "/sensor_fixed.rs"));
}
use sensor_record::SENSOR_RECORD;

macro_rules! law_loop {
    ($name:ident, $law:path, $f:ty) => {
        fn $name(rec: &[[$f; 6]], n: usize) -> f64 {
            use $law as law;
            let mut controller = law::Controller::new(law::Operation::Closing);
            let mut acc: $f = 0.0;
            let mut k = 0;
            for _ in 0..n {
                if k == 0 {
                    controller = law::Controller::new(law::Operation::Closing);
                    controller.start(0.0);
                }
                let [_, _, _, z, v, phi] = *black_box(&rec[k]);
                let t = k as $f * law::SAMPLE_PERIOD;
                acc += black_box(controller.step(t, z, v, phi));
                k += 1;
                if k == rec.len() {
                    k = 0;
                }
            }
            acc as f64
        }
    };
}
law_loop!(law64fixed, sensor_fixed::f64, f64);
law_loop!(law32fixed, sensor_fixed::f32, f32);
law_loop!(law64adaptive, sensor_adaptive::f64, f64);
law_loop!(law32adaptive, sensor_adaptive::f32, f32);

macro_rules! replay_loop {
    ($name:ident, $push:ident, $module:path, $f:ty) => {
        fn $name(rec: &[[$f; 6]], n: usize) -> f64 {
            use $module as m;
            let mut record = m::Record::new();
            record.start(m::Z_MAX);
            for [c, u, i, ..] in rec {
                record.push(&m::CALIBRATION, *c, *u, *i);
            }
            let mut acc = 0.0;
            for _ in 0..n {
                let mut calibration = m::Calibration::new(&m::CALIBRATION);
                let outcome = m::calibrate(&mut calibration, black_box(&record));
                if let reldesign_runtime::calibrate::Outcome::Updated { after, .. } = outcome {
                    acc += f64::from(after);
                }
                acc += f64::from(black_box(calibration.theta)[0]);
            }
            acc
        }

        fn $push(rec: &[[$f; 6]], n: usize) -> f64 {
            use $module as m;
            let mut record = m::Record::new();
            let mut k = 0;
            for _ in 0..n {
                if k == 0 {
                    record.start(m::Z_MAX);
                }
                let [c, u, i, ..] = *black_box(&rec[k]);
                record.push(&m::CALIBRATION, c, u, i);
                k += 1;
                if k == rec.len() {
                    k = 0;
                }
            }
            black_box(&record).len() as f64
        }
    };
}
replay_loop!(replay64, replaypush64, sensor_adaptive::f64, f64);
replay_loop!(replay32, replaypush32, sensor_adaptive::f32, f32);

macro_rules! sensor_base_loop {
    ($name:ident, $f:ty) => {
        fn $name(rec: &[[$f; 6]], n: usize) -> f64 {
            let mut acc: $f = 0.0;
            let mut k = 0;
            for _ in 0..n {
                let [_, u, ..] = *black_box(&rec[k]);
                acc += black_box(u);
                k += 1;
                if k == rec.len() {
                    k = 0;
                }
            }
            acc as f64
        }
    };
}
sensor_base_loop!(sensorbase64, f64);
sensor_base_loop!(sensorbase32, f32);

macro_rules! step_loop {
    ($name:ident, $law:path, $filter:path, $f:ty) => {
        fn $name(rec: &[[$f; 3]], n: usize) -> f64 {
            use $filter as filter;
            use $law as law;
            let half = rec.len() / 2;
            let mut observer = filter::Filter::new();
            let mut controller = law::Controller::new(law::Operation::Closing);
            let mut acc: $f = 0.0;
            let mut k = 0;
            for _ in 0..n {
                if k == 0 {
                    observer = filter::Filter::new();
                    controller = law::Controller::new(law::Operation::Closing);
                    controller.start(0.0);
                } else if k == half {
                    controller = law::Controller::new(law::Operation::Opening);
                    controller.start(0.0);
                }
                let [_, u, i] = *black_box(&rec[k]);
                let e = observer.step(u, i);
                let t = (if k < half { k } else { k - half }) as $f * law::SAMPLE_PERIOD;
                acc += black_box(controller.step(t, e.z, e.v, e.phi));
                k += 1;
                if k == rec.len() {
                    k = 0;
                }
            }
            acc as f64
        }
    };
}
step_loop!(step64fixed, fixed::f64, fixed::ukf::f64, f64);
step_loop!(step32fixed, fixed::f32, fixed::ukf::f32, f32);
step_loop!(step64adaptive, adaptive::f64, adaptive::ukf::f64, f64);
step_loop!(step32adaptive, adaptive::f32, adaptive::ukf::f32, f32);

macro_rules! base_loop {
    ($name:ident, $f:ty) => {
        fn $name(rec: &[[$f; 3]], n: usize) -> f64 {
            let mut acc: $f = 0.0;
            let mut k = 0;
            for _ in 0..n {
                let [_, u, _] = *black_box(&rec[k]);
                acc += black_box(u);
                k += 1;
                if k == rec.len() {
                    k = 0;
                }
            }
            acc as f64
        }
    };
}
base_loop!(base64, f64);
base_loop!(base32, f32);

macro_rules! update_loop {
    ($name:ident, $filter:path, $f:ty) => {
        fn $name(rec: &[[$f; 3]], n: usize) -> f64 {
            use $filter as filter;
            let mut record = filter::Record::new();
            record.start(filter::Z_MAX);
            for [c, u, i] in rec {
                record.push(&filter::CALIBRATION, *c, *u, *i);
            }
            let mut acc = 0.0;
            for _ in 0..n {
                let mut calibration = filter::Calibration::new(&filter::CALIBRATION);
                let outcome = filter::calibrate(&mut calibration, black_box(&record));
                if let reldesign_runtime::calibrate::Outcome::Updated { after, .. } = outcome {
                    acc += f64::from(after);
                }
                acc += f64::from(black_box(calibration.theta)[0]);
            }
            acc
        }
    };
}
macro_rules! push_loop {
    ($name:ident, $filter:path, $f:ty) => {
        fn $name(rec: &[[$f; 3]], n: usize) -> f64 {
            use $filter as filter;
            let mut record = filter::Record::new();
            let mut k = 0;
            for _ in 0..n {
                if k == 0 {
                    record.start(filter::Z_MAX);
                }
                let [c, u, i] = *black_box(&rec[k]);
                record.push(&filter::CALIBRATION, c, u, i);
                k += 1;
                if k == rec.len() {
                    k = 0;
                }
            }
            black_box(&record).len() as f64
        }
    };
}
push_loop!(push64, adaptive::ukf::f64, f64);
push_loop!(push32, adaptive::ukf::f32, f32);

update_loop!(update64, adaptive::ukf::f64, f64);
update_loop!(update32, adaptive::ukf::f32, f32);

fn sizes() {
    use adaptive::ukf::{f32 as a32, f64 as a64};
    use std::mem::size_of;
    println!("record32={}", size_of::<a32::Record>());
    println!("record64={}", size_of::<a64::Record>());
    println!("calibration32={}", size_of::<a32::Calibration>());
    println!("calibration64={}", size_of::<a64::Calibration>());
    println!("filter32_adaptive={}", size_of::<a32::Filter>());
    println!("filter32_fixed={}", size_of::<fixed::ukf::f32::Filter>());
    println!(
        "controller32_adaptive={}",
        size_of::<adaptive::f32::Controller>()
    );
    println!("controller32_fixed={}", size_of::<fixed::f32::Controller>());
    println!("filter64_adaptive={}", size_of::<a64::Filter>());
    println!("parameters={}", a32::ADAPTED.len());
    println!("record_samples={}", a32::RECORD_CAPACITY);
    println!("run_samples={}", RECORD.len());
    use sensor_adaptive::{f32 as s32, f64 as s64};
    println!("replay_record32={}", size_of::<s32::Record>());
    println!("replay_record64={}", size_of::<s64::Record>());
    println!("replay_calibration32={}", size_of::<s32::Calibration>());
    println!("replay_controller32_adaptive={}", size_of::<s32::Controller>());
    println!("replay_controller32_fixed={}", size_of::<sensor_fixed::f32::Controller>());
    println!("replay_parameters={}", s32::ADAPTED.len());
    println!("replay_record_samples={}", s32::RECORD_CAPACITY);
    println!("replay_decimation={}", s32::CALIBRATION.decimation);
    println!("replay_operation_samples={}", SENSOR_RECORD.len());
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 2 && args[1] == "sizes" {
        sizes();
        return;
    }
    if args.len() != 4 {
        eprintln!("usage: {} sizes | KIND N REPS", args[0]);
        std::process::exit(2);
    }
    let rec64: Vec<[f64; 3]> = RECORD.to_vec();
    let rec32: Vec<[f32; 3]> = RECORD.iter().map(|s| s.map(|x| x as f32)).collect();
    let srec64: Vec<[f64; 6]> = SENSOR_RECORD.to_vec();
    let srec32: Vec<[f32; 6]> = SENSOR_RECORD.iter().map(|s| s.map(|x| x as f32)).collect();
    let kind = args[1].as_str();
    let n: usize = args[2].parse().expect("N");
    let reps: usize = args[3].parse().expect("REPS");
    let run = |n: usize| -> f64 {
        match kind {
            "step64fixed" => step64fixed(&rec64, n),
            "step32fixed" => step32fixed(&rec32, n),
            "step64adaptive" => step64adaptive(&rec64, n),
            "step32adaptive" => step32adaptive(&rec32, n),
            "base64" => base64(&rec64, n),
            "base32" => base32(&rec32, n),
            "update64" => update64(&rec64, n),
            "push64" => push64(&rec64, n),
            "push32" => push32(&rec32, n),
            "update32" => update32(&rec32, n),
            "law64fixed" => law64fixed(&srec64, n),
            "law32fixed" => law32fixed(&srec32, n),
            "law64adaptive" => law64adaptive(&srec64, n),
            "law32adaptive" => law32adaptive(&srec32, n),
            "sensorbase64" => sensorbase64(&srec64, n),
            "sensorbase32" => sensorbase32(&srec32, n),
            "replaypush64" => replaypush64(&srec64, n),
            "replaypush32" => replaypush32(&srec32, n),
            "replay64" => replay64(&srec64, n),
            "replay32" => replay32(&srec32, n),
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
        let ns = start.elapsed().as_nanos() as f64 / n as f64;
        best = best.min(ns);
    }
    println!("best_ns_per_call={best} checksum={checksum:e}");
}
