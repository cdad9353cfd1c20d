//! `reldesign loop` for `[controller] law = "backstepping"`: the backstepping
//! position controller (switched-force-backstepping [SB]) in a sampled loop
//! from rest on the spring's stop, or from `--initial-state z,v,phi` (the
//! paper's three kinds of initial condition are states). Writes the loop's
//! CSV with three more columns, `switching` (0 waiting with u = 0, 1 the law
//! outside D, 2 the law inside D), `lyapunov` (V = ZᵀPZ + ½·(F − F_d)²) and
//! `desired_force` (F_d [N]), and prints the switches, the final error and,
//! per step of a square reference, the settling time and the overshoot.

use std::fmt::Write as _;

use designer::backstepping_loop::{run_backstepping, BacksteppingRun, Mode, STEP_BAND};
use designer::closed_loop::Noise;
use designer::design::Design;
use designer::sim::Options;

/// The loop of `design`'s backstepping controller, its CSV and its summary.
pub fn run(
    design: &Design,
    plant: Option<&designer::description::Description>,
    ts: f64,
    duration: Option<f64>,
    noise: Noise,
    initial: Option<[f64; 3]>,
) -> Result<(BacksteppingRun, String), String> {
    let run = run_backstepping(
        design,
        plant,
        ts,
        duration,
        noise,
        initial,
        &Options::default(),
    )
    .map_err(|e| e.to_string())?;
    let summary = summary(&run, ts);
    Ok((run, summary))
}

/// The extra CSV columns at sample `k`.
pub fn columns(run: &BacksteppingRun, k: usize) -> String {
    let mode = match run.modes.get(k) {
        Some(Mode::Waiting) => 0,
        Some(Mode::Inside) => 2,
        _ => 1,
    };
    let at = |v: &[f64]| v.get(k).copied().unwrap_or(f64::NAN);
    format!(
        ",{mode},{:?},{:?}",
        at(&run.lyapunov),
        at(&run.desired_force)
    )
}

fn summary(run: &BacksteppingRun, ts: f64) -> String {
    let tr = &run.run.trajectory;
    let mut s = format!("backstepping at T_s = {ts:e} s\n");
    let n = tr.t.len();
    if n == 0 {
        return s;
    }
    let first_in = run.inside.iter().position(|&b| b).map(|k| tr.t[k]);
    let _ = writeln!(
        s,
        "  start {} D (F_d = {:+.4} N); in D from {}; the input law switched {} time(s)",
        if run.inside.first() == Some(&true) {
            "inside"
        } else {
            "outside"
        },
        run.desired_force.first().copied().unwrap_or(f64::NAN),
        first_in.map_or("never".into(), |t| format!("{:.3} ms", t * 1e3)),
        run.switches()
    );
    let _ = writeln!(
        s,
        "  at the end: z = {:e} m, z − y_r = {:+.3e} m",
        tr.x[n - 1][0],
        tr.x[n - 1][0] - run.run.z_ref[n - 1]
    );
    for step in run.steps() {
        let _ = writeln!(
            s,
            "  step to {:e} m at {:.1} ms: settled ({} % of the step) {}, overshoot {:.2} %",
            step.target,
            step.start * 1e3,
            STEP_BAND * 100.0,
            step.settling_time
                .map_or("not within the step".into(), |t| format!(
                    "in {:.3} ms",
                    t * 1e3
                )),
            step.overshoot * 100.0
        );
    }
    s
}
