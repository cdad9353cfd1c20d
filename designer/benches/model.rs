//! `cargo bench -p reldesign-designer --bench model`: nanoseconds per
//! evaluation of f(x, u) on the flat tape, for every bundled example, and the
//! wall time of the JA three-pulse experiment (40 ms of simulated time).
//!
//! Timing is wall clock, best of several rounds (least disturbed by other load).

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use designer::description::parse_file;
use designer::model::{Model, ModelPlant};
use designer::record::Record;
use designer::replay::replay_plant;
use designer::sim::{Options, PiecewiseLinear, Plant};

fn best_of<F: FnMut()>(rounds: usize, iterations: usize, mut f: F) -> f64 {
    (0..rounds)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..iterations {
                f();
            }
            start.elapsed().as_secs_f64() / iterations as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut paths: Vec<_> = std::fs::read_dir(root.join("examples"))
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    println!("{:<28} {:>8} {:>14}", "example", "instrs", "ns per f(x,u)");
    for path in &paths {
        let d = parse_file(path).unwrap();
        let mut model = Model::build(&d);
        let plant = ModelPlant::new(&mut model);
        let mut x = [d.mechanics.z_max * 0.5, 0.1, 5e-6, 100.0];
        let mut dx = [0.0; 4];
        let secs = best_of(7, 200_000, || {
            plant.deriv(0.0, black_box(&x), black_box(12.0), &mut dx);
            x[1] = black_box(dx[1]) * 0.0 + 0.1;
        });
        println!(
            "{:<28} {:>8} {:>14.1}",
            path.file_name().unwrap().to_string_lossy(),
            plant.f_tape_len(),
            secs * 1e9
        );
    }

    let d = parse_file(&root.join("examples/jiles-atherton-valve.toml")).unwrap();
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    let record = Record::read(&root.join("tests/data/ja-three-pulses.csv")).unwrap();
    let t = record.time(2).unwrap();
    let input = PiecewiseLinear::new(t.clone(), record.column("v").unwrap()).unwrap();
    for rtol in [1e-8, 1e-9, 1e-10] {
        let options = Options {
            rtol,
            ..Options::default()
        };
        let mut steps = 0;
        let secs = best_of(5, 20, || {
            let r = replay_plant(&plant, &model, &input, &t, &options).unwrap();
            steps = r.trajectory.stats.accepted;
        });
        println!(
            "JA three-pulse experiment, rtol {rtol:e}: {:.3} ms per run, {steps} accepted steps",
            secs * 1e3
        );
    }
}
