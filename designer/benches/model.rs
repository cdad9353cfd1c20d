//! `cargo bench -p reldesign-designer --bench model`: nanoseconds per
//! evaluation of f(x, u) on the compiled tape, for every bundled example, and
//! the wall time of the JA three-pulse experiment (40 ms of simulated time).
//!
//! Tapes skip what depends only on inputs unchanged since their previous
//! evaluation, so "full" alternates between two states that differ in every
//! input, and "resting" between two that share z and v (the armature on a
//! stop: the air-gap terms are reused). Timing is wall clock, best of several
//! rounds (least disturbed by other load).

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use designer::description::parse_file;
use designer::model::{Model, ModelPlant};
use designer::record::Record;
use designer::replay::replay_plant;
use designer::sim::{Options, PiecewiseLinear, Plant, State, MAX_SWITCHES};

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

/// Nanoseconds per evaluation of f on a held branch (what the simulator
/// integrates; `deriv` also evaluates the switching functions), alternating
/// between `a` and `b`.
fn ns_per_f(plant: &ModelPlant, a: State, b: State) -> f64 {
    let mut dx = [0.0; 4];
    let mut k = 0u32;
    let branch = [1.0; MAX_SWITCHES];
    let secs = best_of(7, 200_000, || {
        k = k.wrapping_add(1);
        let x = if k & 1 == 0 { &a } else { &b };
        plant.deriv_branch(0.0, black_box(x), black_box(12.0), &branch, &mut dx);
        black_box(dx[1]);
    });
    secs * 1e9
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
    println!(
        "{:<28} {:>8} {:>18} {:>18}",
        "example", "instrs", "ns per f, full", "ns per f, resting"
    );
    for path in &paths {
        let d = parse_file(path).unwrap();
        let mut model = Model::build(&d);
        let plant = ModelPlant::new(&mut model);
        let z = d.mechanics.z_max * 0.5;
        let x = [z, 0.1, 5e-6, 100.0];
        let full = ns_per_f(&plant, x, [z * 1.01, 0.11, 5.1e-6, 101.0]);
        let resting = ns_per_f(&plant, x, [z, 0.1, 5.1e-6, 101.0]);
        println!(
            "{:<28} {:>8} {:>18.1} {:>18.1}",
            path.file_name().unwrap().to_string_lossy(),
            plant.f_tape_len(),
            full,
            resting
        );
    }

    let d = parse_file(&root.join("examples/jiles-atherton-valve.toml")).unwrap();
    let mut model = Model::build(&d);
    let plant = ModelPlant::new(&mut model);
    let record = Record::read(&root.join("tests/data/ja-three-pulses.csv")).unwrap();
    let t = record.time(2).unwrap();
    let input = PiecewiseLinear::new(t.clone(), record.column("v").unwrap()).unwrap();
    for rtol in [1e-7, 1e-8, 1e-9] {
        let options = Options {
            rtol,
            ..Options::default()
        };
        let mut stats = Default::default();
        let secs = best_of(5, 20, || {
            let r = replay_plant(&plant, &model, &input, &t, &options).unwrap();
            stats = r.trajectory.stats;
        });
        println!(
            "JA three-pulse experiment, rtol {rtol:e}: {:.3} ms per run, {stats:?}",
            secs * 1e3
        );
    }
}
