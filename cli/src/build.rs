//! `reldesign build MODEL.toml [--out FILE.rs]`: designs the controller of the
//! description's `[trajectory]` and `[controller]` sections and emits its code.
//! The design report goes to stderr; the code to FILE (atomically) or stdout.

use std::path::PathBuf;

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
    /// saturation switches, mesh size, residuals, table size, the sensorless
    /// precision; the backstepping law's certified region)
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
    // one noise-free loop states the precision for the report and the JSON
    let precision = (!args.quiet || args.report_json.is_some())
        .then(|| designer::precision::at_approaches(&design));
    if !args.quiet {
        let text = match &precision {
            Some(Ok(found)) => designer::precision::report(&design, found),
            Some(Err(e)) => Err(e.clone()),
            None => Ok(None),
        };
        match text {
            Ok(Some(text)) => eprintln!("{text}"),
            Ok(None) => {}
            Err(e) => {
                eprintln!("sensorless precision: not stated (its noise-free loop failed: {e})")
            }
        }
    }
    let stated = match &precision {
        Some(Ok(found)) => found.as_slice(),
        _ => &[],
    };
    let report = (args.report_json.as_ref()).map(|path| {
        (
            path,
            designer::design_json::report_json_with(&design, stated),
        )
    });
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

/// What the self-calibration adapts and why (the identifiability of the
/// planned operations), and whether the emitted file carries the update.
fn calibration_report(design: &designer::design::Design, sample_period: f64) -> String {
    use std::fmt::Write as _;
    let mut s = String::from("self-calibration (controller.self_calibration):\n");
    let chosen = designer::calibrate::choose(design, sample_period);
    match &chosen {
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
            let per = match c.method {
                designer::calibrate::Method::Innovations => "run (every operation)",
                designer::calibrate::Method::Replay => "operation",
            };
            let _ = writeln!(
                s,
                "  record: {} samples per {per}, every {} sample(s)",
                c.capacity, c.decimation
            );
            if c.unexplained.is_finite() {
                let _ = writeln!(
                    s,
                    "  unexplained: an update that leaves a mean squared current error above {:.3e} A² \
                     ({}·σ_i²) counts towards Calibration::unexplained (the model does not follow \
                     this valve)",
                    c.unexplained,
                    designer::calibrate::UNEXPLAINED
                );
            }
        }
        Err(e) => {
            let _ = writeln!(s, "  not designed: {e}");
        }
    }
    s.push_str(match &chosen {
        Ok(c) if c.method == designer::calibrate::Method::Innovations => {
            "  emitted: θ read at run time by the law and the filter; `ukf::…::calibrate` after each run"
        }
        Ok(_) => {
            "  emitted: θ read at run time by the law; `f64::calibrate` / `f32::calibrate` after each operation"
        }
        Err(_) => "",
    });
    s
}
