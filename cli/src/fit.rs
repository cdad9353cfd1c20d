//! `reldesign fit MODEL.toml DATA.csv --param PATH[=LO:HI] …`: fits
//! parameters of a description to a bench recording by replaying its
//! voltage (jiles-atherton-actuator-model [JA 80]); prints the fitted values,
//! the |φ̇|-weighted errors [JA 81] before and after, and which parameter
//! combinations the data cannot separate.
//!
//! `reldesign fit MODEL.toml TABLE.csv --gap mclyman-fit|mclyman`: fits the
//! gap model to a reluctance table (columns `z,r[,r_prime]`), [JA 75–77].
//!
//! `--out` writes the description with the fitted values (comments and
//! design sections kept, atomically); `--json` prints one JSON object.
//! Progress goes to stderr only when stderr is a terminal.

use std::path::PathBuf;

use designer::description::Description;
use designer::record::Record;
use miette::Report;
use reldesign_identify::edit::write_physics;
use reldesign_identify::em_fit::{FitProgress, FitReport, Sensitivities};
use reldesign_identify::gap_fit::{fit_gap, GapFit, GapModel, GapTable};
use reldesign_identify::params::{self, Domain};
use reldesign_identify::{current_wnrmse, fit, FitOptions, FitParam, Measured};
use serde_json::{json, Value};

use crate::progress::Progress;
use crate::{fail, finite};

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description (valve.toml)
    model: PathBuf,
    /// Measured data (CSV t,v,i[,z,phi,lambda]); with --gap, a reluctance table (CSV z,r[,r_prime])
    data: PathBuf,
    /// A parameter to fit, by TOML key path, with optional bounds: PATH or PATH=LO:HI (repeatable; default bounds value/10 … value·10)
    #[arg(long = "param", allow_hyphen_values = true)]
    params: Vec<String>,
    /// Number of starts (the description's values, then seeded draws within the bounds)
    #[arg(long, default_value_t = 1)]
    starts: usize,
    /// Solver iterations per start
    #[arg(long, default_value_t = 50)]
    max_iterations: usize,
    /// Leave the flux term out of the objective (current, and position if measured, only)
    #[arg(long)]
    no_flux: bool,
    /// Seed of the drawn starts
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Fit the gap model to a reluctance table instead of a recording
    #[arg(long, value_parser = ["mclyman-fit", "mclyman"])]
    gap: Option<String>,
    /// Write the description with the fitted values here (atomically)
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object on stdout
    #[arg(long)]
    json: bool,
}

pub fn run(args: &Args) -> Result<(), Report> {
    let description = crate::load(&args.model)?;
    match &args.gap {
        Some(model) => run_gap(args, &description, model),
        None => run_fit(args, &description),
    }
}

fn run_fit(args: &Args, description: &Description) -> Result<(), Report> {
    if args.params.is_empty() {
        return Err(fail(format!(
            "give at least one --param PATH[=LO:HI]; {} has: {}",
            args.model.display(),
            params::available(description).join(", ")
        )));
    }
    let fitted = args
        .params
        .iter()
        .map(|p| parse_param(description, p))
        .collect::<Result<Vec<_>, _>>()
        .map_err(fail)?;
    let data = Measured::read(&args.data).map_err(fail)?;
    let options = FitOptions {
        starts: args.starts.max(1),
        max_iterations: args.max_iterations,
        use_flux: !args.no_flux,
        seed: args.seed,
        ..FitOptions::default()
    };
    let before = current_wnrmse(description, &data).map_err(fail)?;
    let bar = Progress::new(
        (options.starts * options.max_iterations) as u64,
        "iterations at most",
    );
    let progress = |p: FitProgress| {
        bar.inc();
        bar.message(format!(
            "start {}/{} iteration {}: objective {:.4e}",
            p.start + 1,
            p.starts,
            p.iteration,
            p.objective
        ));
    };
    let report = fit(description, &data, &fitted, &options, &progress).map_err(fail);
    bar.finish();
    let report = report?;
    let written = write_out(args, description, &report.description)?;
    if args.json {
        println!(
            "{}",
            fit_json(description, &report, before, written.as_deref())
        );
    } else {
        print!(
            "{}",
            fit_text(args, description, &report, before, written.as_deref())
        );
    }
    Ok(())
}

/// `PATH` or `PATH=LO:HI`.
fn parse_param(d: &Description, text: &str) -> Result<FitParam, String> {
    let (path, range) = match text.split_once('=') {
        Some((p, r)) => (p.trim(), Some(r)),
        None => (text.trim(), None),
    };
    let value = params::get(d, path).map_err(|e| e.to_string())?;
    let (lower, upper) = match range {
        Some(r) => {
            let parts: Vec<Result<f64, _>> =
                r.split(':').map(|x| x.trim().parse::<f64>()).collect();
            match parts.as_slice() {
                [Ok(lo), Ok(hi)] if lo < hi => (*lo, *hi),
                _ => {
                    return Err(format!(
                        "--param {text}: expected PATH=LO:HI with numbers LO < HI"
                    ))
                }
            }
        }
        None => default_bounds(d, path, value)?,
    };
    Ok(FitParam {
        path: path.to_owned(),
        lower,
        upper,
    })
}

/// value/10 … value·10 (within the domain), or the unit interval.
fn default_bounds(d: &Description, path: &str, value: f64) -> Result<(f64, f64), String> {
    let domain = params::domain(d, path).map_err(|e| e.to_string())?;
    match domain {
        Domain::Unit => return Ok((0.0, 1.0)),
        Domain::UnitOpen => return Ok((0.0, 0.999)),
        _ => {}
    }
    if value == 0.0 {
        return Err(format!(
            "--param {path}: its value is 0, which gives no scale for default bounds; give PATH=LO:HI"
        ));
    }
    let (a, b) = (value / 10.0, value * 10.0);
    Ok(if value > 0.0 { (a, b) } else { (b, a) })
}

/// Writes the fitted description to `--out`, keeping the original text's
/// comments and design sections.
fn write_out(
    args: &Args,
    original: &Description,
    fitted: &Description,
) -> Result<Option<String>, Report> {
    let Some(path) = &args.out else {
        return Ok(None);
    };
    let text =
        write_physics(&original.source.text, &original.source.file_name, fitted).map_err(fail)?;
    crate::atomic::write_all(&[(path.as_path(), text.as_bytes())]).map_err(fail)?;
    Ok(Some(path.display().to_string()))
}

fn fit_text(
    args: &Args,
    d: &Description,
    r: &FitReport,
    before: f64,
    written: Option<&str>,
) -> String {
    let mut s = format!(
        "fit of {} to {}: {} parameter(s), {} start(s)\n",
        args.model.display(),
        args.data.display(),
        r.values.len(),
        args.starts.max(1)
    );
    for (path, value) in &r.values {
        let old = params::get(d, path).unwrap_or(f64::NAN);
        s += &format!("  {path:<28} {old:<12.6e} -> {value:.6e}\n");
    }
    s += &format!(
        "wNRMSE current (81): {:.4} % before, {:.4} % after\n",
        100.0 * before,
        100.0 * r.wnrmse_current
    );
    if let Some(f) = r.wnrmse_flux {
        s += &format!("wNRMSE flux (81): {:.4} % after\n", 100.0 * f);
    }
    if let Some(z) = r.nrmse_position {
        s += &format!("RMS position error / stroke: {:.4} % after\n", 100.0 * z);
    }
    s += &format!(
        "objective (80): {:.4e}; {} iterations, {} replays, best start {}, stopped: {:?}; \
         Jacobian: {}\n",
        r.cost,
        r.iterations,
        r.simulations,
        r.best_start,
        r.status,
        jacobian_name(r)
    );
    s += &r.sensitivity.to_string();
    if let Some(p) = written {
        s += &format!("wrote {p}\n");
    }
    s
}

fn fit_json(d: &Description, r: &FitReport, before: f64, written: Option<&str>) -> Value {
    let sens = &r.sensitivity;
    let values: serde_json::Map<String, Value> = r
        .values
        .iter()
        .map(|(p, v)| (p.clone(), json!(v)))
        .collect();
    let initial: serde_json::Map<String, Value> = r
        .values
        .iter()
        .map(|(p, _)| (p.clone(), json!(params::get(d, p).ok())))
        .collect();
    let std_errors: serde_json::Map<String, Value> = sens
        .names
        .iter()
        .zip(&sens.relative_std_errors)
        .map(|(n, e)| (n.clone(), finite(*e)))
        .collect();
    let weak: Vec<Value> = sens
        .weak_directions
        .iter()
        .map(|dir| {
            Value::Array(
                dir.iter()
                    .map(|(n, c)| json!({"param": n, "weight": c}))
                    .collect(),
            )
        })
        .collect();
    json!({
        "values": values,
        "initial": initial,
        "wnrmse_current_before": finite(before),
        "wnrmse_current": finite(r.wnrmse_current),
        "wnrmse_flux": r.wnrmse_flux.map(finite),
        "nrmse_position": r.nrmse_position.map(finite),
        "cost": finite(r.cost),
        "iterations": r.iterations,
        "simulations": r.simulations,
        "jacobian": jacobian_name(r),
        "jacobians_differenced": r.differenced_jacobians,
        "status": format!("{:?}", r.status),
        "singular_values": sens.singular_values.iter().map(|s| finite(*s)).collect::<Vec<_>>(),
        "condition": finite(sens.condition),
        "relative_std_errors": std_errors,
        "weak_directions": weak,
        "out": written,
    })
}

fn run_gap(args: &Args, description: &Description, model: &str) -> Result<(), Report> {
    let model = match model {
        "mclyman" => GapModel::McLyman,
        _ => GapModel::McLymanFit,
    };
    let record = Record::read(&args.data).map_err(fail)?;
    let table = GapTable::from_record(&record).map_err(fail)?;
    let result = fit_gap(&table, model).map_err(fail)?;
    let mut fitted = description.clone();
    fitted.gap = result.gap.clone();
    let written = write_out(args, description, &fitted)?;
    if args.json {
        println!("{}", gap_json(&result, written.as_deref()));
    } else {
        let mut s = format!(
            "gap fit of {} ({} points):\n",
            args.data.display(),
            table.z.len()
        );
        for (name, value) in &result.values {
            s += &format!("  gap.{name:<16} {value:.6e}\n");
        }
        s += &format!("NRMSE R_gap (77): {:.4} %\n", 100.0 * result.nrmse_r);
        if let Some(e) = result.nrmse_r_prime {
            s += &format!("NRMSE R_gap' (77): {:.4} %\n", 100.0 * e);
        }
        if let Some(p) = written {
            s += &format!("wrote {p}\n");
        }
        print!("{s}");
    }
    Ok(())
}

fn gap_json(r: &GapFit, written: Option<&str>) -> Value {
    let values: serde_json::Map<String, Value> = r
        .values
        .iter()
        .map(|(p, v)| (format!("gap.{p}"), json!(v)))
        .collect();
    json!({
        "values": values,
        "nrmse_r": finite(r.nrmse_r),
        "nrmse_r_prime": r.nrmse_r_prime.map(finite),
        "iterations": r.iterations,
        "out": written,
    })
}

/// How the fit's Jacobian was obtained.
fn jacobian_name(r: &FitReport) -> String {
    match (r.sensitivities, r.differenced_jacobians) {
        (Sensitivities::Analytic, 0) => "analytic forward sensitivities".into(),
        (Sensitivities::Analytic, n) => format!(
            "analytic forward sensitivities ({n} of them by finite differences of whole \
             replays, where the sensitivities gave up: a field too stiff for them, or a \
             failed replay)"
        ),
        (Sensitivities::FiniteDifference, _) => "finite differences of whole replays".into(),
    }
}
