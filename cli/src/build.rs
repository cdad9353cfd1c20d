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
    }
    let report = args
        .report_json
        .as_ref()
        .map(|path| (path, designer::design_json::report_json(&design)));
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
