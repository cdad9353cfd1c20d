//! Design-time cost of the backstepping law's certified region
//! (`benches/backstepping_step.sh`, see `benches/backstepping_step/run.py`).
//!
//!     region TOML CALLS DESIGNS
//!
//! Designs TOML once (`Design::new`), then calls
//! `designer::design::design_region` CALLS times on that design's inputs
//! (the closed loop A [SB 14], the decay α, the force gradient k and the
//! targets, need_rest = true, as `design_backstepping` calls it), each call
//! timed alone, and checks that every call gives the design's region
//! bit for bit. Then times `Design::new` itself DESIGNS times. Prints
//! `key=value` lines: the median, smallest and largest µs per call, the
//! number of conic solves per call, and the medians of the whole design.

use std::path::Path;
use std::time::Instant;

use designer::description::parse_file;
use designer::design::{design_region, Design};

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    let n = xs.len();
    if n % 2 == 1 {
        xs[n / 2]
    } else {
        0.5 * (xs[n / 2 - 1] + xs[n / 2])
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: {} TOML CALLS DESIGNS", args[0]);
        std::process::exit(2);
    }
    let calls: usize = args[2].parse().expect("CALLS");
    let designs: usize = args[3].parse().expect("DESIGNS");
    let d = parse_file(Path::new(&args[1])).unwrap_or_else(|e| panic!("{e}"));
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let designed = design.backstepping.expect("a backstepping design").region;

    let mut us = Vec::with_capacity(calls);
    for _ in 0..calls {
        let targets = designed.targets.clone();
        let start = Instant::now();
        let region = design_region(
            designed.a,
            designed.decay,
            designed.force_gradient,
            targets,
            true,
        );
        let elapsed = start.elapsed().as_secs_f64() * 1e6;
        let region = std::hint::black_box(region).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(region, designed, "design_region differs from the design's");
        us.push(elapsed);
    }
    let (lo, hi) = us.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| {
        (lo.min(x), hi.max(x))
    });
    println!("region_median_us={}", median(us));
    println!("region_min_us={lo}");
    println!("region_max_us={hi}");
    // the paper's program, and the extended one where it leaves a rest outside
    println!("solves_per_call={}", 1 + usize::from(designed.extended));
    println!("targets={}", designed.targets.len());

    let mut ms = Vec::with_capacity(designs);
    for _ in 0..designs {
        let start = Instant::now();
        let design = std::hint::black_box(Design::new(std::hint::black_box(&d)));
        ms.push(start.elapsed().as_secs_f64() * 1e3);
        assert!(design.is_ok());
    }
    println!("design_median_ms={}", median(ms));
}
