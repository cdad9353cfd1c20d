//! `reldesign loop --runs N --plot FILE.svg`: the run-to-run picture, run on
//! the x axis: each operation's first impact speed (log scale, beside the
//! uncontrolled switching's, dashed), and each adapted parameter relative to
//! the design's value (θ/θ_d) during the run.

use designer::calibrate::Run;
use designer::description::Operation;
use plotters::prelude::*;

/// Colours of successive lines.
const COLOURS: [RGBColor; 10] = [
    BLUE,
    RED,
    GREEN,
    MAGENTA,
    CYAN,
    BLACK,
    RGBColor(230, 140, 0),
    RGBColor(120, 60, 160),
    RGBColor(100, 100, 100),
    RGBColor(0, 120, 120),
];

type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

fn err(e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>) -> String {
    e.to_string()
}

/// The SVG of `runs` against the switching `baseline`.
pub fn svg(
    runs: &[Run],
    baseline: &[(Operation, Option<f64>)],
    title: &str,
) -> Result<String, String> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (900, 800)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        impacts(&panels[0], runs, baseline)?;
        parameters(&panels[1], runs)?;
        root.present().map_err(err)?;
    }
    Ok(out)
}

/// |first impact| [mm/s] per run and operation (a run that never reached the
/// stop is left out), log scale, with the switching's as dashed lines.
fn impacts(area: &Area, runs: &[Run], baseline: &[(Operation, Option<f64>)]) -> Result<(), String> {
    let operations: Vec<Operation> = baseline.iter().map(|(op, _)| *op).collect();
    let series: Vec<(Operation, Vec<(f64, f64)>)> = operations
        .iter()
        .map(|&op| {
            let points = runs
                .iter()
                .filter_map(|r| {
                    let o = r.operations.iter().find(|o| o.outcome.operation == op)?;
                    let v = o.outcome.impact_velocity?.abs() * 1e3;
                    (v > 0.0).then_some((r.run as f64, v))
                })
                .collect();
            (op, points)
        })
        .collect();
    let switching: Vec<(Operation, f64)> = baseline
        .iter()
        .filter_map(|(op, v)| v.map(|v| (*op, v.abs() * 1e3)))
        .collect();
    let values = (series.iter().flat_map(|(_, p)| p.iter().map(|p| p.1)))
        .chain(switching.iter().map(|s| s.1));
    let (lo, hi) = values.fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
    let (lo, hi) = if lo.is_finite() {
        (lo / 2.0, hi * 2.0)
    } else {
        (0.1, 10.0)
    };
    let n = runs.len().max(2) as f64;
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(0.5..n + 0.5, (lo..hi).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("run")
        .y_desc("|first impact| [mm/s]")
        .draw()
        .map_err(err)?;
    for (k, (op, points)) in series.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        chart
            .draw_series(LineSeries::new(points.iter().copied(), colour))
            .map_err(err)?
            .label(op.name())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour));
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(err)?;
        if let Some((_, v)) = switching.iter().find(|(o, _)| o == op) {
            let dashed = DashedLineSeries::new([(0.5, *v), (n + 0.5, *v)], 6, 4, colour.into());
            chart
                .draw_series(dashed)
                .map_err(err)?
                .label(format!("{} switching", op.name()))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour));
        }
    }
    legend(&mut chart)
}

/// θ/θ_d per adapted parameter, during each run.
fn parameters(area: &Area, runs: &[Run]) -> Result<(), String> {
    let Some(first) = runs.first() else {
        return Ok(());
    };
    let keys: Vec<&str> = first.parameters.iter().map(|(k, _)| *k).collect();
    let design: Vec<f64> = first.parameters.iter().map(|(_, v)| *v).collect();
    let series: Vec<Vec<(f64, f64)>> = (0..keys.len())
        .map(|j| {
            runs.iter()
                .filter_map(|r| {
                    let v = r.parameters.get(j)?.1 / design[j];
                    v.is_finite().then_some((r.run as f64, v))
                })
                .collect()
        })
        .collect();
    let (lo, hi) =
        (series.iter().flatten()).fold((1.0_f64, 1.0_f64), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let pad = ((hi - lo) * 0.1).max(0.02);
    let n = runs.len().max(2) as f64;
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(0.5..n + 0.5, (lo - pad)..(hi + pad))
        .map_err(err)?;
    let y = if keys.is_empty() {
        "no self-calibration"
    } else {
        "θ / θ_d during the run"
    };
    chart
        .configure_mesh()
        .x_desc("run")
        .y_desc(y)
        .draw()
        .map_err(err)?;
    for (j, (key, points)) in keys.iter().zip(&series).enumerate() {
        let colour = COLOURS[j % COLOURS.len()];
        chart
            .draw_series(LineSeries::new(points.iter().copied(), colour))
            .map_err(err)?
            .label(*key)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour));
    }
    if keys.is_empty() {
        return Ok(());
    }
    legend(&mut chart)
}

fn legend<'a, X: Ranged<ValueType = f64>, Y: Ranged>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)
}
