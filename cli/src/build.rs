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
}

pub fn run(args: &Args) -> Result<(), Report> {
    let description = crate::load(&args.model)?;
    let design = codegen::Design::new(&description).map_err(fail)?;
    let code = design.emit().map_err(fail)?;
    if !args.quiet {
        eprintln!(
            "{}: design of `{}`\n{}",
            args.model.display(),
            description.name,
            design.report()
        );
    }
    match &args.out {
        Some(path) => {
            crate::atomic::write_all(&[(path.as_path(), code.as_bytes())]).map_err(fail)?
        }
        None => print!("{code}"),
    }
    Ok(())
}
