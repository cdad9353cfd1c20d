//! `reldesign`: the command line. Each subcommand is a thin layer over the
//! library (`designer`): parse arguments, call, format, write atomically.
//! Errors go to stderr with the file, key or row they concern, exit status 1;
//! never a panic or a backtrace.

mod atomic;
mod build;
mod check;
mod closed_loop;
mod diagnose;
mod diagnose_plot;
#[cfg(test)]
mod doc_commands;
mod eval;
mod fit;
mod limits;
mod loop_runs;
mod observe;
mod plot;
mod position_loop;
mod progress;
mod region_plot;
mod robustness;
mod runs_plot;
mod simulate;
mod sweep;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use designer::description::{parse_file, Description};
use miette::Report;

#[derive(Parser)]
#[command(
    name = "reldesign",
    version,
    about = "Control-design compiler for single-coil reluctance actuators"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a description and print a readable summary.
    Check {
        /// The actuator description (valve.toml)
        model: PathBuf,
    },
    /// Evaluate model quantities at given states (JSON in, JSON out).
    Eval {
        model: PathBuf,
        /// {"x": [[z, v, phi(, Hc)], …], "u": [u, …], "t": [t, …] (optional)}
        states: PathBuf,
    },
    /// Replay an input through the hybrid model from rest at z_max.
    Simulate(simulate::Args),
    /// Design the soft-landing controller and emit its no_std Rust code.
    Build(build::Args),
    /// Run the model-free estimators of [observer] over a recording (semera, integral).
    Observe(observe::Args),
    /// Fit description parameters to a recording (--param PATH[=LO:HI]), or the gap model to a reluctance table (--gap).
    Fit(fit::Args),
    /// Replay a recording, name what the model gets wrong, write the extended model and plots.
    Diagnose(diagnose::Args),
    /// The device's limits: shortest energy-optimal motion per operation, its peak current and flux, J against the motion time.
    Limits(limits::Args),
    /// Run the designed controller in a sampled loop on the hybrid model (of the description or of --plant).
    Loop(closed_loop::Args),
    /// Closed loops of the design at several sample periods, against the uncontrolled switching.
    Sweep(sweep::Args),
    /// The sliding-mode law's supply bound along the design's references, and its Monte-Carlo worst case over parameter bounds.
    Robustness(robustness::Args),
}

fn main() -> ExitCode {
    // Messages name files as `path:line:column`: never wrap them (a long path
    // would be split across lines, and grep or an editor could not find it).
    let _ = miette::set_hook(Box::new(|_| {
        Box::new(miette::MietteHandlerOpts::new().wrap_lines(false).build())
    }));
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check { model } => check::run(&model),
        Command::Eval { model, states } => eval::run(&model, &states),
        Command::Simulate(args) => simulate::run(&args),
        Command::Build(args) => build::run(&args),
        Command::Observe(args) => observe::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Diagnose(args) => diagnose::run(&args),
        Command::Limits(args) => limits::run(&args),
        Command::Robustness(args) => robustness::run(&args),
        // `loop --runs N`: successive runs, the self-calibration between them
        Command::Loop(args) if args.runs.is_some() => loop_runs::run(&args),
        Command::Loop(args) => closed_loop::run(&args),
        Command::Sweep(args) => sweep::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(report) => {
            eprintln!("{report:?}");
            ExitCode::FAILURE
        }
    }
}

/// Reads and validates a description; errors render with source and caret.
pub fn load(path: &Path) -> Result<Description, Report> {
    let description = parse_file(path).map_err(Report::new)?;
    for warning in &description.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(description)
}

/// A number for JSON, which has no ∞ or NaN: those become null.
pub fn finite(x: f64) -> serde_json::Value {
    if x.is_finite() {
        serde_json::json!(x)
    } else {
        serde_json::Value::Null
    }
}

/// A plain error message as a report.
pub fn fail(message: impl std::fmt::Display) -> Report {
    miette::miette!("{message}")
}
