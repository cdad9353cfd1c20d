//! `reldesign sweep MODEL.toml [--plant PLANT.toml] [--sample-periods S,S,…]
//! [--json] [--plot FILE.svg] [--compare OTHER.toml]`: the design redone at each
//! sample period and run in closed loop; per operation the first impact,
//! RMSE_z and bounces, against the uncontrolled switching (u_max, then 0 V).
//! The plot is model-free-sliding-mode-soft-landing Fig. 6: the impact
//! velocity against T_s, making and breaking, with the switching baseline.

use std::fmt::Write as _;
use std::path::PathBuf;

use designer::closed_loop::{sweep, switching_baseline, SweepRow};
use designer::description::{Description, Operation};
use designer::sim::Options;
use miette::Report;
use plotters::prelude::*;
use serde_json::{json, Value};

use crate::{atomic, fail, finite};

/// The paper's range, 1 µs to 100 µs.
const DEFAULT_PERIODS: [f64; 7] = [1e-6, 2e-6, 5e-6, 1e-5, 2e-5, 5e-5, 1e-4];

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description, with [trajectory] and [controller]
    model: PathBuf,
    /// The plant's description (default: MODEL itself)
    #[arg(long)]
    plant: Option<PathBuf>,
    /// Sample periods [s], comma-separated (default 1e-6,2e-6,5e-6,1e-5,2e-5,5e-5,1e-4)
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    sample_periods: Vec<f64>,
    /// Print JSON instead of text
    #[arg(long)]
    json: bool,
    /// Draw the impact velocities against T_s (SVG, written atomically)
    #[arg(long)]
    plot: Option<PathBuf>,
    /// A second design (e.g. the other law on the same valve) swept on the same plant and periods
    #[arg(long)]
    compare: Option<PathBuf>,
}

/// One swept design.
struct Swept {
    law: &'static str,
    file: String,
    rows: Vec<SweepRow>,
}

pub fn run(args: &Args) -> Result<(), Report> {
    let periods = periods(&args.sample_periods)?;
    let description = crate::load(&args.model)?;
    let plant = args.plant.as_deref().map(crate::load).transpose()?;
    let main = swept(&description, &args.model, plant.as_ref(), &periods)?;
    let other = match &args.compare {
        Some(path) => Some(swept(&crate::load(path)?, path, plant.as_ref(), &periods)?),
        None => None,
    };
    let file = args.model.display().to_string();
    // the uncontrolled switching needs no design: the supply and the timing
    let baseline = switching_baseline(&description, plant.as_ref(), &Options::default())
        .map_err(|e| fail(format!("{file}: {e}")))?;
    let sweeps: Vec<&Swept> = std::iter::once(&main).chain(other.as_ref()).collect();
    if let Some(path) = &args.plot {
        let svg = plot(&sweeps, &baseline, &description).map_err(fail)?;
        atomic::write_all(&[(path.as_path(), svg.as_bytes())]).map_err(fail)?;
    }
    if args.json {
        println!("{}", to_json(&sweeps, &baseline));
    } else {
        print!("{}", text(&sweeps, &baseline));
    }
    Ok(())
}

fn periods(given: &[f64]) -> Result<Vec<f64>, Report> {
    if given.is_empty() {
        return Ok(DEFAULT_PERIODS.to_vec());
    }
    for &ts in given {
        if !(ts.is_finite() && ts > 0.0) {
            return Err(fail(format!(
                "--sample-periods: expected positive numbers of seconds, found {ts}"
            )));
        }
    }
    Ok(given.to_vec())
}

fn swept(
    d: &Description,
    path: &std::path::Path,
    plant: Option<&Description>,
    periods: &[f64],
) -> Result<Swept, Report> {
    let file = path.display().to_string();
    let Some(c) = &d.controller else {
        return Err(fail(format!(
            "{file}: `sweep` runs the designed controller: the description needs [trajectory] and [controller]"
        )));
    };
    let rows =
        sweep(d, plant, periods, &Options::default()).map_err(|e| fail(format!("{file}: {e}")))?;
    Ok(Swept {
        law: c.law.name(),
        file,
        rows,
    })
}

/// An optional number for JSON: absent or not finite → null.
fn number(x: Option<f64>) -> Value {
    x.map_or(Value::Null, finite)
}

fn to_json(sweeps: &[&Swept], baseline: &[(Operation, Option<f64>)]) -> String {
    let rows: Vec<Value> = sweeps
        .iter()
        .flat_map(|s| {
            s.rows.iter().flat_map(move |r| {
                r.outcomes.iter().map(move |o| {
                    json!({
                        "law": s.law,
                        "design": s.file,
                        "sample_period": r.sample_period,
                        "operation": o.operation.name(),
                        "impact_velocity": number(o.impact_velocity),
                        "rmse_z": number(o.rmse_z),
                        "bounces": o.bounces,
                    })
                })
            })
        })
        .collect();
    let switching: Vec<Value> = baseline
        .iter()
        .map(|(op, v)| json!({ "operation": op.name(), "impact_velocity": number(*v) }))
        .collect();
    serde_json::to_string_pretty(&json!({ "rows": rows, "switching": switching }))
        .unwrap_or_default()
}

fn text(sweeps: &[&Swept], baseline: &[(Operation, Option<f64>)]) -> String {
    let mut s = String::new();
    for sw in sweeps {
        let _ = writeln!(s, "{} ({})", sw.law, sw.file);
        let _ = writeln!(
            s,
            "  {:>10}  {:<8} {:>14} {:>12} {:>8}",
            "T_s [s]", "op", "impact [m/s]", "RMSE_z [m]", "bounces"
        );
        for r in &sw.rows {
            for o in &r.outcomes {
                let v = o
                    .impact_velocity
                    .map_or("never".into(), |v| format!("{v:+.4e}"));
                let _ = writeln!(
                    s,
                    "  {:>10.1e}  {:<8} {v:>14} {:>12} {:>8}",
                    r.sample_period,
                    o.operation.name(),
                    o.rmse_z.map_or("—".into(), |r| format!("{r:.3e}")),
                    o.bounces
                );
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

/// Fig. 6: |impact velocity| against T_s (log–log), one panel per operation.
fn plot(
    sweeps: &[&Swept],
    baseline: &[(Operation, Option<f64>)],
    d: &Description,
) -> Result<String, String> {
    let mut out = String::new();
    {
        let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| e.to_string();
        let root = SVGBackend::with_string(&mut out, (1100, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let root = root
            .titled(
                &format!("{}: first impact against the sample period", d.name),
                ("sans-serif", 22),
            )
            .map_err(e)?;
        let operations: Vec<Operation> = baseline.iter().map(|(op, _)| *op).collect();
        let panels = root.split_evenly((1, operations.len().max(1)));
        for (panel, &op) in panels.iter().zip(&operations) {
            let base = baseline
                .iter()
                .find(|(o, _)| *o == op)
                .and_then(|(_, v)| *v);
            panel_plot(panel, sweeps, op, base)?;
        }
        root.present().map_err(e)?;
    }
    Ok(out)
}

fn panel_plot(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    sweeps: &[&Swept],
    op: Operation,
    base: Option<f64>,
) -> Result<(), String> {
    let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let points = |sw: &Swept| -> Vec<(f64, f64)> {
        sw.rows
            .iter()
            .filter_map(|r| {
                let o = r.outcomes.iter().find(|o| o.operation == op)?;
                Some((r.sample_period * 1e6, o.impact_velocity?.abs().max(1e-6)))
            })
            .collect()
    };
    let all: Vec<(f64, f64)> = sweeps.iter().flat_map(|s| points(s)).collect();
    let x_lo = all
        .iter()
        .map(|p| p.0)
        .fold(f64::INFINITY, f64::min)
        .min(1.0);
    let x_hi = all.iter().map(|p| p.0).fold(0.0, f64::max).max(x_lo * 10.0);
    let y_hi = all
        .iter()
        .map(|p| p.1)
        .chain(base.map(f64::abs))
        .fold(1e-3, f64::max);
    let y_lo = all.iter().map(|p| p.1).fold(y_hi, f64::min) / 2.0;
    let name = match op {
        Operation::Closing => "closing (making)",
        Operation::Opening => "opening (breaking)",
    };
    let mut chart = ChartBuilder::on(area)
        .caption(name, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (x_lo / 1.5..x_hi * 1.5).log_scale(),
            (y_lo..y_hi * 2.0).log_scale(),
        )
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("T_s [µs]")
        .y_desc("|impact velocity| [m/s]")
        .draw()
        .map_err(e)?;
    for (sw, color) in sweeps.iter().zip([BLUE, RED]) {
        let pts = points(sw);
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
            .map_err(e)?
            .label(sw.law)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        chart
            .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, color.filled())))
            .map_err(e)?;
    }
    if let Some(v) = base {
        let v = v.abs();
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x_lo / 1.5, v), (x_hi * 1.5, v)],
                8,
                5,
                BLACK.stroke_width(1),
            ))
            .map_err(e)?
            .label(format!("switching: {v:.2} m/s"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()
        .map_err(e)?;
    Ok(())
}
