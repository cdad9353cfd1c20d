//! `reldesign build MODEL.toml [--out FILE.rs]`: designs the controller of the
//! description's `[trajectory]` and `[controller]` sections and emits its code.
//! The design report goes to stderr; the code to FILE (atomically) or stdout.

use std::path::PathBuf;

use designer::description::SetPoint;
use designer::design::{BacksteppingDesign, LawDesign};
use miette::Report;

use crate::fail;

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description with [trajectory] and [controller] sections
    model: PathBuf,
    /// Output Rust file (written atomically, only when the design succeeds); stdout when absent
    #[arg(long)]
    out: Option<PathBuf>,
    /// Do not print the design report
    #[arg(long)]
    quiet: bool,
    /// Also write the design figures as JSON (per operation: J, max |u|,
    /// saturation switches, mesh size, residuals, table size; the backstepping
    /// law's certified region)
    #[arg(long)]
    report_json: Option<PathBuf>,
    /// Also draw the backstepping law's certified region (the (z₁, z₂) plane: F_d = 0,
    /// the paper's V₁ region and the LMI's) to this SVG file
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub fn run(args: &Args) -> Result<(), Report> {
    let description = crate::load(&args.model)?;
    let design = designer::design::Design::new(&description)
        .map_err(|e| fail(format!("{}: {e}", description.source.file_name)))?;
    let code = reldesign_build::emit(&design).map_err(fail)?;
    if !args.quiet {
        eprintln!(
            "{}: design of `{}`\n{}",
            args.model.display(),
            description.name,
            design.report()
        );
        if let Some(c) = &description.controller {
            if c.self_calibration {
                eprintln!("{}", calibration_report(&design, c.sample_period));
            }
        }
    }
    let report = args
        .report_json
        .as_ref()
        .map(|path| (path, report_json(&design)));
    let plot = match (&args.plot, &design.backstepping) {
        (None, _) => None,
        (Some(path), Some(b)) => {
            let title = format!("{}: the backstepping law's certified region", description.name);
            Some((path, crate::region_plot::svg(b, &title).map_err(fail)?))
        }
        (Some(_), None) => {
            return Err(fail(format!(
                "--plot draws the region of [controller] law = \"backstepping\"; {} designs no such law",
                args.model.display()
            )))
        }
    };
    let mut files: Vec<(&std::path::Path, &[u8])> = Vec::new();
    if let Some(path) = &args.out {
        files.push((path.as_path(), code.as_bytes()));
    }
    if let Some((path, json)) = &report {
        files.push((path.as_path(), json.as_bytes()));
    }
    if let Some((path, svg)) = &plot {
        files.push((path.as_path(), svg.as_bytes()));
    }
    crate::atomic::write_all(&files).map_err(fail)?;
    if args.out.is_none() {
        print!("{code}");
    }
    Ok(())
}

/// The backstepping law's keys and design values.
fn backstepping_json(b: &BacksteppingDesign) -> serde_json::Value {
    let switching = b.switching.name();
    let reference = match b.reference {
        SetPoint::Position(z) => serde_json::json!({ "position": z }),
        SetPoint::Square { low, high, period } => {
            serde_json::json!({ "square": [low, high, period] })
        }
    };
    serde_json::json!({
        "law": "backstepping",
        "gains": b.gains,
        "switching": switching,
        "reference": reference,
        "rest_position": b.rest,
        "phi_guard": b.phi_guard,
        "holding": b.holding.iter().map(|&(flux, input)| serde_json::json!({"flux": flux, "input": input})).collect::<Vec<_>>(),
    })
}

/// The certified region [SB lemma 1], [SB Theorem 3]: A, P, C and whether
/// the spring's rest is in D, for the design's P and the paper's P = ½I; per
/// target where there are two (a square reference): `c` is the first
/// target's, `contains_rest` holds for every target.
fn region_json(b: &BacksteppingDesign) -> serde_json::Value {
    let r = &b.region;
    let [p11, p12, p22] = r.p;
    let level = |l: Option<&designer::design::Level>| {
        l.map_or(
            serde_json::json!({ "c": null, "contains_rest": false }),
            |l| serde_json::json!({ "c": l.c, "contains_rest": l.contains_rest }),
        )
    };
    let targets: Vec<serde_json::Value> = (r.targets.iter().zip(&r.levels).zip(&r.identity))
        .map(|((t, l), i)| {
            serde_json::json!({
                "position": t.position,
                "holding_force": t.holding_force,
                "rest": t.rest,
                "c": l.c,
                "contains_rest": l.contains_rest,
                "identity": { "c": i.c, "contains_rest": i.contains_rest },
            })
        })
        .collect();
    let first = level(r.levels.first());
    let all = |levels: &[designer::design::Level]| levels.iter().all(|l| l.contains_rest);
    let mut identity = level(r.identity.first());
    identity["contains_rest"] = all(&r.identity).into();
    serde_json::json!({
        "a": r.a,
        "p": [[p11, p12], [p12, p22]],
        "c": first["c"],
        "decay": r.decay,
        "contains_rest": all(&r.levels),
        "identity": identity,
        "extended": r.extended,
        "force_gradient": r.force_gradient,
        "trace": p11 + p22,
        "targets": targets,
    })
}

/// The design figures, for scripts and oracles.
fn report_json(design: &designer::design::Design) -> String {
    let no_operations = Vec::new();
    let operations: serde_json::Map<String, serde_json::Value> = design
        .controller
        .as_ref()
        .map_or(&no_operations, |c| &c.operations)
        .iter()
        .map(|o| {
            let mut entry = serde_json::json!({
                "z0": o.z0,
                "zf": o.zf,
                "segments": o.table.segments.len(),
                "feasible": o.feasibility.is_feasible(),
                "max_input": o.feasibility.max_input,
                "min_input": o.feasibility.min_input,
            });
            if let (Some(opt), Some(map)) = (&o.optimal, entry.as_object_mut()) {
                map.insert("optimal".into(), opt.summary_json());
            }
            (o.operation.name().to_string(), entry)
        })
        .collect();
    let law = design.controller.as_ref().map(|c| match c.law {
        LawDesign::FeedbackLinearization { gains } => {
            serde_json::json!({ "law": "feedback-linearization", "gains": gains })
        }
        LawDesign::SlidingMode {
            lambda1,
            lambda2,
            nonnegative_current,
        } => serde_json::json!({
            "law": "sliding-mode",
            "lambda1": lambda1,
            "lambda2": lambda2,
            "nonnegative_current": nonnegative_current,
        }),
        LawDesign::ModelSlidingMode { p, k } => serde_json::json!({
            "law": "model-sliding-mode",
            "p": p,
            "k": k,
            "gains": c.law.tracking_gains(),
        }),
    });
    let law = law.or_else(|| {
        design.hold.as_ref().map(|h| {
            serde_json::json!({
                "law": "model-sliding-mode",
                "p": h.p,
                "k": h.k,
                "gains": h.gains(),
                "position": h.position,
                "holding_flux": h.holding_flux,
                "holding_input": h.holding_input,
                "phi_guard": h.phi_guard,
            })
        })
    });
    let law = law.or_else(|| design.backstepping.as_ref().map(backstepping_json));
    let gains = (design.controller.as_ref())
        .and_then(|c| c.law.tracking_gains())
        .or_else(|| design.hold.as_ref().map(|h| h.gains()));
    let mut value = serde_json::json!({ "name": design.description.name, "controller": law, "gains": gains, "operations": operations });
    if let (Some(b), Some(map)) = (&design.backstepping, value.as_object_mut()) {
        map.insert("region".into(), region_json(b));
    }
    serde_json::to_string_pretty(&value).unwrap_or_default() + "\n"
}

/// What the self-calibration adapts and why (the identifiability of the
/// planned operations), and what the emitted file does not carry yet.
fn calibration_report(design: &designer::design::Design, sample_period: f64) -> String {
    use std::fmt::Write as _;
    let mut s = String::from("self-calibration (controller.self_calibration):\n");
    match designer::calibrate::choose(design, sample_period) {
        Ok(c) => {
            let _ = writeln!(
                s,
                "  method: {} ({})",
                c.method.name(),
                match c.method {
                    designer::calibrate::Method::Innovations => {
                        "the observer's innovations over each run, every physics parameter"
                    }
                    designer::calibrate::Method::Replay => {
                        "each operation's record replayed, the parameters its current identifies"
                    }
                }
            );
            for a in &c.parameters {
                let _ = writeln!(
                    s,
                    "  adapts {:<22} from {:.4e} within [{:.4e}, {:.4e}] ({:.0} % of its information new)",
                    a.key,
                    a.nominal,
                    a.lower,
                    a.upper,
                    100.0 * a.new_information
                );
            }
            for (key, why) in &c.rejected {
                let _ = writeln!(s, "  keeps  {key:<22} {why}");
            }
            let _ = writeln!(
                s,
                "  record: {} samples per operation, every {} sample(s)",
                c.capacity, c.decimation
            );
        }
        Err(e) => {
            let _ = writeln!(s, "  not designed: {e}");
        }
    }
    s.push_str(
        "  warning: the emitted file does not carry the update yet; `reldesign loop --runs N` runs it",
    );
    s
}
