//! `reldesign robustness MODEL.toml [--vary KEY=±P% …] [--draws N] [--seed S] [--json]`:
//! the sliding-mode law's supply bound along the design's references
//! (model-free-sliding-mode-soft-landing [SM §4.1]) and its Monte-Carlo worst
//! case over parameter bounds.

use std::fmt::Write as _;
use std::path::PathBuf;

use designer::design::{Analysis, ErrorBounds, MonteCarlo, Nominal, Robustness, Variation};
use miette::Report;
use serde_json::{json, Value};

use crate::progress::Progress;
use crate::{fail, finite};

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description, with [trajectory] and [controller] law = "sliding-mode"
    model: PathBuf,
    /// Vary a model parameter uniformly within ±P % of its value (repeatable), e.g. coil.resistance=±10%
    #[arg(long, value_name = "KEY=±P%")]
    vary: Vec<String>,
    /// Monte-Carlo draws (with --vary), at most 10 000 000
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    draws: u32,
    /// Seed of the draws: the same seed gives the same draws, whatever the thread count
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Velocity error bound |ṽ| as a percentage of max |v_ref| [SM 52]
    #[arg(long, default_value_t = 20.0, value_name = "P")]
    velocity_error: f64,
    /// Acceleration error bound |ã| as a percentage of max |a_ref| [SM 52]
    #[arg(long, default_value_t = 20.0, value_name = "P")]
    acceleration_error: f64,
    /// Instants per operation (10 to 1 000 000)
    #[arg(long, default_value_t = 2000, value_parser = clap::value_parser!(u32).range(10..=1_000_000))]
    samples: u32,
    /// Print JSON instead of text
    #[arg(long)]
    json: bool,
}

pub fn run(args: &Args) -> Result<(), Report> {
    let description = crate::load(&args.model)?;
    let file = args.model.display().to_string();
    let bounds = error_bounds(args)?;
    let analysis = Analysis::new(&description, bounds, args.samples as usize)
        .map_err(|e| fail(format!("{file}: {e}")))?;
    let variations = args
        .vary
        .iter()
        .map(|v| Variation::parse(v, &description))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| fail(format!("{file}: {e}")))?;
    let nominal = analysis.nominal();
    let monte_carlo = if variations.is_empty() {
        None
    } else {
        Some(run_draws(&analysis, &variations, args).map_err(|e| fail(format!("{file}: {e}")))?)
    };
    if args.json {
        println!("{}", json_report(&nominal, monte_carlo.as_ref(), args));
    } else {
        print!("{}", text(&nominal, monte_carlo.as_ref(), args, &file));
    }
    Ok(())
}

fn error_bounds(args: &Args) -> Result<ErrorBounds, Report> {
    let fraction = |name: &str, p: f64| {
        if p.is_finite() && p >= 0.0 {
            Ok(p / 100.0)
        } else {
            Err(fail(format!(
                "--{name}: expected a percentage ≥ 0, found {p}"
            )))
        }
    };
    Ok(ErrorBounds {
        velocity: fraction("velocity-error", args.velocity_error)?,
        acceleration: fraction("acceleration-error", args.acceleration_error)?,
    })
}

/// The draws, with a progress bar on a terminal.
fn run_draws(
    analysis: &Analysis,
    variations: &[Variation],
    args: &Args,
) -> Result<MonteCarlo, designer::design::RobustnessError> {
    let bar = Progress::new(u64::from(args.draws), "draws");
    let result = analysis.monte_carlo(variations, args.draws as usize, args.seed, &|| bar.inc());
    bar.finish();
    result
}

fn json_report(nominal: &Nominal, mc: Option<&MonteCarlo>, args: &Args) -> String {
    let operations: Vec<Value> = nominal
        .operations
        .iter()
        .map(|(op, r)| {
            json!({
                "operation": op.name(),
                "feasible": r.feasible,
                "infeasible_between": r.infeasible.map(|(a, b)| [a, b]),
                "max_u_star": finite(r.max_u_star),
                "max_u_star_t": finite(r.max_u_star_t),
                "min_b_j": finite(r.min_b_j),
                "max_epsilon": finite(r.max_epsilon),
                "required_u_max": finite(r.required_u_max),
                "required_u_min": finite(r.required_u_min),
                "u_max": nominal.u_max,
                "u_min": nominal.u_min,
                "met": r.met(nominal.u_min, nominal.u_max),
            })
        })
        .collect();
    let mut value = json!({ "operations": operations });
    if let (Some(mc), Some(map)) = (mc, value.as_object_mut()) {
        let worst: serde_json::Map<String, Value> = mc
            .worst
            .values
            .iter()
            .map(|(k, v)| (k.clone(), json!(v)))
            .collect();
        map.insert(
            "monte_carlo".into(),
            json!({
                "draws": mc.draws,
                "seed": args.seed,
                "worst_required_u_max": finite(mc.worst.required_u_max),
                "worst_draw": worst,
                "worst_draw_index": mc.worst.index,
                "share_met": mc.share_met,
            }),
        );
    }
    serde_json::to_string_pretty(&value).unwrap_or_default()
}

fn text(nominal: &Nominal, mc: Option<&MonteCarlo>, args: &Args, file: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{file}: sliding-mode robustness (model-free-sliding-mode §4.1), error bounds |ṽ| ≤ {}·max|v_ref|, |ã| ≤ {}·max|a_ref| (52)",
        args.velocity_error / 100.0,
        args.acceleration_error / 100.0
    );
    for (op, r) in &nominal.operations {
        let _ = write!(
            s,
            "{}",
            operation_text(op.name(), r, nominal.u_min, nominal.u_max)
        );
    }
    if let Some(mc) = mc {
        let _ = writeln!(
            s,
            "\nMonte Carlo: {} draws (seed {}), the supply u_max = {} covers {:.1} % of them",
            mc.draws,
            args.seed,
            nominal.u_max,
            100.0 * mc.share_met
        );
        let values: Vec<String> = mc
            .worst
            .values
            .iter()
            .map(|(k, v)| format!("{k} = {v:.6e}"))
            .collect();
        let _ = writeln!(
            s,
            "  worst draw #{}: required u_max {}\n    {}",
            mc.worst.index,
            volts(mc.worst.required_u_max),
            values.join(", ")
        );
    }
    s
}

fn volts(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}")
    } else {
        "∞ (a reference is infeasible for this device)".into()
    }
}

fn operation_text(name: &str, r: &Robustness, u_min: f64, u_max: f64) -> String {
    let mut s = format!("\n{name}:\n");
    if let Some((a, b)) = r.infeasible {
        let _ = writeln!(
            s,
            "  INFEASIBLE between t = {:.4} and {:.4} ms: F*_mag (13) would have to repel or exceed saturation (14); u* → ∞ there",
            a * 1e3,
            b * 1e3
        );
    }
    let _ = writeln!(
        s,
        "  max u* (48)           {} at t = {:.4} ms",
        volts(r.max_u_star),
        r.max_u_star_t * 1e3
    );
    let _ = writeln!(
        s,
        "  min |B_j| (26)        {:.6e} at t = {:.4} ms",
        r.min_b_j,
        r.min_b_j_t * 1e3
    );
    let _ = writeln!(s, "  max |ε| (50)          {:.6e} m/s³", r.max_epsilon);
    let _ = writeln!(
        s,
        "  required u_max (49)   {}; the supply's u_max = {u_max}",
        volts(r.required_u_max)
    );
    let _ = writeln!(
        s,
        "  required u_min        {} (the same margin below min u_r); the supply's u_min = {u_min}",
        volts(r.required_u_min)
    );
    let _ = writeln!(
        s,
        "  the supply [{u_min}, {u_max}]: {}",
        if r.met(u_min, u_max) {
            "met"
        } else {
            "NOT met"
        }
    );
    s
}
