//! The backstepping law [SFB 19] and its region [SFB Theorem 3] on the
//! bundled valves.

use designer::backstepping_loop::run_backstepping;
use designer::closed_loop::Noise;
use designer::description::parse_file;
use designer::design::Design;
use designer::sim::Options;
use support::example_path;

#[test]
fn probe() {
    let d = parse_file(&example_path("backstepping-valve.toml")).unwrap();
    let design = Design::new(&d).unwrap();
    let b = design.backstepping.as_ref().unwrap();
    println!("P {:?} levels {:?}", b.region.p, b.region.levels);
    let run = run_backstepping(&design, None, 1e-5, None, Noise::seeded(1), None, &Options::default()).unwrap();
    println!("steps {:?}", run.steps());
    println!("switches {}", run.switches());
    let tr = &run.run.trajectory;
    for k in (0..tr.t.len()).step_by(500).take(80) {
        println!("{:.4} z {:.3e} v {:.3e} phi {:.3e} u {:.2} mode {:?} in {} Fd {:.3} V {:.3e}", tr.t[k], tr.x[k][0], tr.x[k][1], tr.x[k][2], tr.u[k], run.modes[k.min(run.modes.len()-1)], run.inside[k.min(run.modes.len()-1)], run.desired_force[k.min(run.modes.len()-1)], run.lyapunov[k.min(run.modes.len()-1)]);
    }
}
