//! `reldesign limits MODEL.toml [--json] [--plot FILE.svg]`: what the device
//! can do, for a designer choosing t_f − t₀ and u_bound: per operation the
//! shortest energy-optimal motion within the supply (and within
//! `trajectory.u_bound` where given), its peak current and flux, J against the
//! motion time; and the statics `check` prints.

use std::fmt::Write;
use std::path::PathBuf;

use designer::description::{Description, Drive};
use designer::design::{motion_limits, Linearization, MotionLimits, OptimalError};
use designer::model::Model;
use miette::Report;
use plotters::prelude::*;
use rayon::prelude::*;

use crate::{atomic, fail};

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description (input-affine core: linear or saturating)
    model: PathBuf,
    /// Print JSON instead of text
    #[arg(long)]
    json: bool,
    /// Write J against the motion time as SVG (written atomically)
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// The limits of one operation: within the supply, and within u_bound.
struct Operation {
    name: &'static str,
    supply: MotionLimits,
    design: Option<MotionLimits>,
}

pub fn run(args: &Args) -> Result<(), Report> {
    let description = crate::load(&args.model)?;
    let file = args.model.display().to_string();
    let mut model = Model::build(&description);
    Linearization::derive(&mut model).map_err(|e| fail(format!("{file}: {e}")))?;
    let operations = operations(&description, &file)?;
    if let Some(path) = &args.plot {
        let svg = plot(&operations, &description).map_err(fail)?;
        atomic::write_all(&[(path.as_path(), svg.as_bytes())]).map_err(fail)?;
    }
    if args.json {
        println!("{}", json(&operations, &description));
    } else {
        print!("{}", text(&mut model, &operations, &file));
    }
    Ok(())
}

/// Closing and opening, within the supply and within u_bound (in parallel).
fn operations(d: &Description, file: &str) -> Result<Vec<Operation>, Report> {
    let m = &d.mechanics;
    let supply = (d.supply.u_min, d.supply.u_max);
    let design = match &d.trajectory {
        Some(t) if t.u_bound < d.supply.u_max => Some((d.supply.u_min.max(-t.u_bound), t.u_bound)),
        _ => None,
    };
    let moves = [("closing", m.z_max, m.z_min), ("opening", m.z_min, m.z_max)];
    let mut jobs: Vec<LimitsJob> = Vec::new();
    for &(_, z0, zf) in &moves {
        jobs.push((z0, zf, supply));
        jobs.extend(design.map(|b| (z0, zf, b)));
    }
    let mut results = device_limits(d, &jobs, start_time(d)).into_iter();
    let mut next = |name: &str| {
        results
            .next()
            .unwrap_or_else(|| {
                Err(designer::design::OptimalError::InvalidSpec(
                    "no result".into(),
                ))
            })
            .map_err(|e| fail(format!("{file}: the {name}: {e}")))
    };
    moves
        .iter()
        .map(|&(name, _, _)| {
            let supply = next(name)?;
            let design = match design {
                Some(_) => Some(next(name)?),
                None => None,
            };
            Ok(Operation {
                name,
                supply,
                design,
            })
        })
        .collect()
}

/// Where the search for a first motion starts: the description's motion
/// time, else three times the time the passive force alone needs to cross
/// the stroke from rest.
fn start_time(d: &Description) -> f64 {
    if let Some(t) = &d.trajectory {
        return t.landing - t.takeoff;
    }
    let m = &d.mechanics;
    let force = (m.stiffness * m.z_max + m.preload).abs().max(1e-6);
    (3.0 * (2.0 * m.mass * (m.z_max - m.z_min) / force).sqrt()).max(1e-3)
}

fn unit(d: &Description) -> &'static str {
    match d.supply.drive {
        Drive::Voltage => "V",
        Drive::Current => "A",
    }
}

fn limits_text(s: &mut String, l: &MotionLimits, what: &str, unit: &str) {
    let _ = writeln!(
        s,
        "  {what} [{:.4}, {:.4}] {unit}: shortest motion {:.4} ms (J = {:.5e} {unit}²·s), peak current {:.4} A, peak flux {:.4e} Wb",
        l.bounds.0,
        l.bounds.1,
        l.shortest * 1e3,
        l.fastest_cost,
        l.peak_current,
        l.peak_flux
    );
}

fn text(model: &mut Model, ops: &[Operation], file: &str) -> String {
    let d = model.description.clone();
    let unit = unit(&d);
    let mut s = format!("{file}: limits of `{}`\n", d.name);
    for op in ops {
        let _ = writeln!(s, "\n{}:", op.name);
        limits_text(&mut s, &op.supply, "within the supply", unit);
        if let Some(l) = &op.design {
            limits_text(&mut s, l, "within trajectory.u_bound", unit);
        }
        let l = op.design.as_ref().unwrap_or(&op.supply);
        let _ = write!(s, "  J against t_f − t₀ [ms: {unit}²·s]:");
        for p in &l.curve {
            let _ = write!(
                s,
                " {:.2}: {:.4e}{}",
                p.duration * 1e3,
                p.cost,
                if p.rests { "*" } else { "" }
            );
        }
        let _ = writeln!(s);
        match l.resting_from {
            Some(from) => {
                let _ = writeln!(
                    s,
                    "  (*) from about {:.3} ms on, the energy-optimal motion lasts about that long and rests the remaining time, which costs less than moving slower",
                    from * 1e3
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "  J decreases over the whole range: a slower motion saves energy"
                );
            }
        }
    }
    if let Some(a) = d.trajectory.as_ref().and_then(|t| t.approach()) {
        let _ = writeln!(
            s,
            "\nwith [trajectory] standoff: t_f − t₀ holds the approach too, 5·standoff/(4·approach_speed) = {:.4} ms beyond the move (the motions above cross the whole stroke)",
            a.duration() * 1e3
        );
    }
    let _ = write!(s, "\n{}", crate::check::statics_text(model));
    s
}

fn limits_json(l: &MotionLimits) -> serde_json::Value {
    serde_json::json!({
        "u_min": l.bounds.0,
        "u_max": l.bounds.1,
        "shortest_motion": l.shortest,
        "fastest_cost": l.fastest_cost,
        "peak_current": l.peak_current,
        "peak_flux": l.peak_flux,
        "resting_from": l.resting_from,
        "cost_curve": l.curve.iter().map(|p| serde_json::json!({
            "motion_time": p.duration, "cost": p.cost, "rests": p.rests,
        })).collect::<Vec<_>>(),
    })
}

fn json(ops: &[Operation], d: &Description) -> serde_json::Value {
    let approach = d.trajectory.as_ref().and_then(|t| t.approach());
    serde_json::json!({
        "name": d.name,
        "approach_time": approach.map(|a| a.duration()),
        "operations": ops.iter().map(|op| serde_json::json!({
            "operation": op.name,
            "supply": limits_json(&op.supply),
            "u_bound": op.design.as_ref().map(limits_json),
        })).collect::<Vec<_>>(),
    })
}

/// J against the motion time, one curve per operation (within u_bound where
/// given), the shortest motion marked.
fn plot(ops: &[Operation], d: &Description) -> Result<String, String> {
    let mut out = String::new();
    {
        let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| e.to_string();
        let root = SVGBackend::with_string(&mut out, (900, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let curves: Vec<(&str, &MotionLimits)> = ops
            .iter()
            .map(|op| (op.name, op.design.as_ref().unwrap_or(&op.supply)))
            .collect();
        let points = curves.iter().flat_map(|(_, l)| l.curve.iter());
        let (mut x1, mut y1) = (0.0f64, 0.0f64);
        for p in points {
            x1 = x1.max(p.duration * 1e3);
            y1 = y1.max(p.cost);
        }
        let unit = unit(d);
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("{}: energy J against the motion time", d.name),
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..x1 * 1.05, 0.0..y1 * 1.1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("t_f − t₀ [ms]")
            .y_desc(format!("J = ∫u² dt [{unit}²·s]"))
            .draw()
            .map_err(e)?;
        for ((name, l), color) in curves.iter().zip([BLUE, RED]) {
            let line: Vec<(f64, f64)> =
                l.curve.iter().map(|p| (p.duration * 1e3, p.cost)).collect();
            chart
                .draw_series(LineSeries::new(line, color.stroke_width(2)))
                .map_err(e)?
                .label(format!("{name} (shortest {:.3} ms)", l.shortest * 1e3))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
            chart
                .draw_series(std::iter::once(Circle::new(
                    (l.shortest * 1e3, l.fastest_cost),
                    5,
                    color.filled(),
                )))
                .map_err(e)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE)
            .border_style(BLACK)
            .draw()
            .map_err(e)?;
        root.present().map_err(e)?;
    }
    Ok(out)
}

/// One motion to find the limits of: (z₀, z_f, (u_min, u_max)).
type LimitsJob = (f64, f64, (f64, f64));

/// [`motion_limits`] of several motions in parallel (one model each).
fn device_limits(
    description: &Description,
    jobs: &[LimitsJob],
    start: f64,
) -> Vec<Result<MotionLimits, OptimalError>> {
    jobs.par_iter()
        .map(|&(z0, zf, bounds)| {
            let mut model = Model::build(description);
            let lin = Linearization::derive(&mut model)
                .map_err(|e| OptimalError::InvalidSpec(e.to_string()))?;
            motion_limits(&mut model, &lin, z0, zf, bounds, start)
        })
        .collect()
}
