//! `cargo bench -p reldesign-designer --bench trajectory`: wall time of the
//! energy-optimal trajectory (closing 1 → 0 mm and opening 0 → 1 mm of the
//! perfect-tracking valve in [1 ms, 6 ms], ±20 V, tol 1e-6, the settings of
//! designer/tests/optimal.rs).
//!
//! Two figures per case, best of several rounds (least disturbed by other
//! load):
//! - `solve`: `energy_optimal` alone (Hamiltonian derivation and compilation,
//!   initial guess, collocation, switches and cost), model and linearization
//!   built beforehand;
//! - `total`: model build from the parsed description + linearization +
//!   `energy_optimal`.
//!
//! Machine-readable lines `TRAJECTORY_JSON {...}` are parsed by
//! benches/trajectory_vs_scipy.py. Environment: `TRAJECTORY_ROUNDS` (default 7).

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use designer::description::parse_file;
use designer::design::{energy_optimal, Linearization, OptimalSpec};
use designer::model::Model;

const T0: f64 = 1e-3;
const TF: f64 = 6e-3;
const BOUND: f64 = 20.0;

fn best_of<F: FnMut()>(rounds: usize, mut f: F) -> f64 {
    (0..rounds)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let rounds: usize = std::env::var("TRAJECTORY_ROUNDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(7)
        .max(1);
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/perfect-tracking-valve.toml");
    let desc = parse_file(&path).unwrap_or_else(|e| panic!("{e}"));
    println!(
        "{:<8} {:>6} {:>16} {:>6} {:>8} {:>6} {:>11} {:>11}",
        "case", "bound", "J", "nodes", "newton", "jacs", "solve [ms]", "total [ms]"
    );
    let (mut sum_solve, mut sum_total) = (0.0, 0.0);
    for (case, z0, zf) in [("closing", 1e-3, 0.0), ("opening", 0.0, 1e-3)] {
        let spec = OptimalSpec::new(z0, zf, T0, TF, -BOUND, BOUND);
        // the figures (one untimed run, also the warm-up)
        let mut model = Model::build(&desc);
        let lin = Linearization::derive(&mut model).unwrap();
        let traj = energy_optimal(&mut model, &lin, &spec).unwrap_or_else(|e| panic!("{e}"));
        // energy_optimal alone; the model is rebuilt each round (untimed) so
        // that its expression graph does not grow across rounds
        let solve = (0..rounds)
            .map(|_| {
                let mut model = Model::build(&desc);
                let lin = Linearization::derive(&mut model).unwrap();
                let start = Instant::now();
                let t = energy_optimal(&mut model, &lin, black_box(&spec)).unwrap();
                let el = start.elapsed().as_secs_f64();
                black_box(t.cost);
                el
            })
            .fold(f64::INFINITY, f64::min);
        let total = best_of(rounds, || {
            let mut model = Model::build(black_box(&desc));
            let lin = Linearization::derive(&mut model).unwrap();
            let t = energy_optimal(&mut model, &lin, black_box(&spec)).unwrap();
            black_box(t.cost);
        });
        sum_solve += solve;
        sum_total += total;
        println!(
            "{:<8} {:>6} {:>16.12} {:>6} {:>8} {:>6} {:>11.3} {:>11.3}",
            case,
            BOUND,
            traj.cost,
            traj.nodes(),
            traj.newton_iterations,
            traj.solution.jacobian_evaluations,
            solve * 1e3,
            total * 1e3
        );
        let j = serde_json::json!({
            "case": case,
            "bound": BOUND,
            "tol": spec.tol,
            "cost": traj.cost,
            "nodes": traj.nodes(),
            "newton_iterations": traj.newton_iterations,
            "jacobian_evaluations": traj.solution.jacobian_evaluations,
            "mesh_refinements": traj.mesh_refinements,
            "rhs_evaluations": traj.solution.rhs_evaluations,
            "max_residual": traj.max_residual,
            "solve_s": solve,
            "total_s": total,
            "rounds": rounds,
        });
        println!("TRAJECTORY_JSON {j}");
    }
    println!(
        "closing + opening: solve {:.3} ms, total {:.3} ms (best of {rounds})",
        sum_solve * 1e3,
        sum_total * 1e3
    );
}
