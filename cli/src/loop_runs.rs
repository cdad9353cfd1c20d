//! `reldesign loop MODEL.toml --runs N [--json] [--plant PLANT.toml]
//! [--sample-period S] [--seed K] [--out OUT.csv] [--plot FILE.svg]`: N
//! successive runs of the designed controller on the plant, the design's
//! self-calibration (`[controller] self_calibration`) updated between them by
//! the runtime's own code; per run the parameters used, per operation the
//! first impact, the bounces and the highest bounce, against the
//! uncontrolled switching (`../shared/spec/cli.md`, `loop --runs N --json`).
//! `--out` writes the last run's samples, `--plot` the runs' picture
//! (`runs_plot.rs`).

use std::fmt::Write as _;

use designer::calibrate::{choose, run_runs, CalibrationDesign, Outcome, Run, Update};
use designer::closed_loop::{check_sample_period, switching_baseline};
use designer::description::Operation;
use designer::sim::Options;
use miette::Report;

use serde_json::{json, Value};

use crate::closed_loop::Args;
use crate::fail;

pub fn run(args: &Args) -> Result<(), Report> {
    let runs = match args.runs {
        Some(n) if n > 0 => n,
        _ => return Err(fail("--runs: expected a positive number of runs")),
    };
    let description = crate::load(&args.model)?;
    let file = args.model.display().to_string();
    let plant = args.plant.as_deref().map(crate::load).transpose()?;
    let Some(controller) = &description.controller else {
        return Err(fail(format!(
            "{file}: `loop --runs` runs the designed controller: the description needs [trajectory] and [controller]"
        )));
    };
    let ts = crate::closed_loop::positive("--sample-period", args.sample_period)?
        .unwrap_or(controller.sample_period);
    check_sample_period(&description, ts).map_err(|e| fail(format!("{file}: {e}")))?;
    let design = crate::closed_loop::design_at(&description, args, ts, &file)?;
    let calibration = if controller.self_calibration {
        Some(choose(&design, ts).map_err(|e| fail(format!("{file}: self-calibration: {e}")))?)
    } else {
        None
    };
    let options = Options::default();
    let done = run_runs(
        &design,
        calibration.as_ref(),
        plant.as_ref(),
        runs,
        ts,
        crate::closed_loop::noise_of(args)?,
        &options,
    )
    .map_err(|e| fail(format!("{file}: {e}")))?;
    let baseline = switching_baseline(&description, plant.as_ref(), &options)
        .map_err(|e| fail(format!("{file}: {e}")))?;
    // the last run's CSV (--out) and the runs' picture (--plot), together
    let csv = match (&args.out, done.last()) {
        (Some(_), Some(last)) => Some(crate::closed_loop::to_csv(
            &last.run_loop,
            design.model.dim() > 3,
            None,
        )),
        _ => None,
    };
    let title = format!("{}: {runs} runs at T_s = {ts:e} s", description.name);
    let svg = match &args.plot {
        Some(_) => Some(crate::runs_plot::svg(&done, &baseline, &title).map_err(fail)?),
        None => None,
    };
    let mut files: Vec<(&std::path::Path, &[u8])> = Vec::new();
    if let (Some(out), Some(csv)) = (&args.out, &csv) {
        files.push((out.as_path(), csv.as_bytes()));
    }
    if let (Some(path), Some(svg)) = (&args.plot, &svg) {
        files.push((path.as_path(), svg.as_bytes()));
    }
    crate::atomic::write_all(&files).map_err(fail)?;
    // the runtime pushes an armature not at its stop by t_f + the design's margin
    let late_after = designer::closed_loop::late_after(&design);
    if args.json {
        println!(
            "{}",
            to_json(&done, &baseline, calibration.as_ref(), late_after)
        );
    } else {
        print!(
            "{}",
            text(&done, &baseline, calibration.as_ref(), late_after)
        );
    }
    Ok(())
}

/// A number for JSON: not finite → null.
fn number(x: Option<f64>) -> Value {
    x.filter(|v| v.is_finite())
        .map_or(Value::Null, |v| json!(v))
}

fn update_json(update: &Option<Update>, calibration: Option<&CalibrationDesign>) -> Value {
    let (error, outcome) = match update {
        None => return Value::Null,
        Some(Update::Replay(o)) => ("rms_current_error", o),
        Some(Update::Innovations(o)) => ("rms_innovation", o),
    };
    // whether the fitted model still leaves the current unexplained (where
    // the design states a threshold: an observer's σ_i)
    let unexplained = calibration.and_then(|c| c.leaves_unexplained(outcome));
    match outcome {
        Outcome::Updated { before, after } => json!({
            "updated": true,
            format!("{error}_before"): before.sqrt(),
            format!("{error}_after"): after.sqrt(),
            "unexplained": unexplained,
        }),
        Outcome::Refused(why) => json!({ "updated": false, "refused": format!("{why:?}") }),
    }
}

/// What an update did, in a line.
fn update_text(update: &Update, calibration: Option<&CalibrationDesign>) -> String {
    let (Update::Replay(outcome) | Update::Innovations(outcome)) = update;
    match outcome {
        Outcome::Updated { before, after } => {
            let unexplained = calibration.and_then(|c| c.leaves_unexplained(outcome)) == Some(true);
            format!(
                "RMS current error {:.3e} → {:.3e} A{}",
                before.sqrt(),
                after.sqrt(),
                if unexplained {
                    " (unexplained: the adapted model does not explain this valve's current)"
                } else {
                    ""
                }
            )
        }
        Outcome::Refused(why) => format!("refused ({why:?})"),
    }
}

/// Whether an arrival [s from the operation's start] came after the push.
fn to_json(
    runs: &[Run],
    baseline: &[(Operation, Option<f64>)],
    calibration: Option<&CalibrationDesign>,
    late_after: f64,
) -> String {
    let runs: Vec<Value> = runs
        .iter()
        .map(|r| {
            let parameters: serde_json::Map<String, Value> = r
                .parameters
                .iter()
                .map(|(k, v)| ((*k).to_owned(), json!(v)))
                .collect();
            let operations: Vec<Value> = r
                .operations
                .iter()
                .map(|o| {
                    json!({
                        "operation": o.outcome.operation.name(),
                        "impact_velocity": number(o.outcome.impact_velocity),
                        "bounces": o.outcome.bounces,
                        "max_bounce_height": o.outcome.highest_bounce,
                        "arrival_time": number(o.outcome.arrival),
                        "late": o.outcome.arrived_late(late_after),
                        "flagged_late": o.outcome.flagged_late,
                        "calibration": update_json(&o.update, calibration),
                    })
                })
                .collect();
            json!({ "run": r.run, "parameters": parameters, "operations": operations })
        })
        .collect();
    let switching: Vec<Value> = baseline
        .iter()
        .map(|(op, v)| json!({ "operation": op.name(), "impact_velocity": number(*v) }))
        .collect();
    let adapted: Vec<Value> = calibration.map_or(Vec::new(), |c| {
        c.parameters
            .iter()
            .map(|a| {
                json!({ "key": a.key, "design": a.nominal, "lower": a.lower, "upper": a.upper,
                        "new_information": a.new_information })
            })
            .collect()
    });
    serde_json::to_string_pretty(&json!({
        "runs": runs,
        "switching": switching,
        "calibration": calibration.map(|c| c.method.name()),
        "adapted": adapted,
    }))
    .unwrap_or_default()
}

fn text(
    runs: &[Run],
    baseline: &[(Operation, Option<f64>)],
    calibration: Option<&CalibrationDesign>,
    late_after: f64,
) -> String {
    let mut s = String::new();
    match calibration {
        Some(c) => {
            let keys: Vec<&str> = c.parameters.iter().map(|a| a.key).collect();
            let _ = writeln!(
                s,
                "self-calibration ({}) adapts {}",
                c.method.name(),
                keys.join(", ")
            );
        }
        None => {
            let _ = writeln!(s, "no self-calibration ([controller] self_calibration)");
        }
    }
    for r in runs {
        let values: Vec<String> = r
            .parameters
            .iter()
            .map(|(k, v)| format!("{k} = {v:.5e}"))
            .collect();
        let _ = writeln!(s, "run {}: {}", r.run, values.join(", "));
        for o in &r.operations {
            let v = o
                .outcome
                .impact_velocity
                .map_or("never reached the stop".into(), |v| format!("{v:+.4e} m/s"));
            let pushed = o.outcome.verdict(late_after);
            let _ = writeln!(
                s,
                "  {:<8} first impact {v}, {} bounce(s), highest {:.2e} m{pushed}",
                o.outcome.operation.name(),
                o.outcome.bounces,
                o.outcome.highest_bounce
            );
            if let Some(u) = &o.update {
                let _ = writeln!(s, "  update: {}", update_text(u, calibration));
            }
        }
    }
    let _ = writeln!(s, "uncontrolled switching (u_max, then 0 V):");
    for (op, v) in baseline {
        let v = v.map_or("never".into(), |v| format!("{v:+.4e} m/s"));
        let _ = writeln!(s, "  {:<8} first impact {v}", op.name());
    }
    s
}
