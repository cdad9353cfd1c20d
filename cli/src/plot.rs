//! `--plot out.svg`: current, flux and position of a replay, stacked; the
//! panel against time that `simulate` and `loop` draw.

use designer::replay::Replay;
use plotters::prelude::*;

pub fn svg(r: &Replay, title: &str) -> Result<String, String> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (900, 900)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(title, ("sans-serif", 22))
            .map_err(|e| e.to_string())?;
        let panels = root.split_evenly((3, 1));
        let t_ms: Vec<f64> = r.trajectory.t.iter().map(|t| t * 1e3).collect();
        let flux: Vec<f64> = r.trajectory.x.iter().map(|x| x[2] * 1e6).collect();
        let z: Vec<f64> = r.trajectory.x.iter().map(|x| x[0] * 1e3).collect();
        let series: [(&str, &[f64], RGBColor); 3] = [
            ("current i [A]", &r.current, BLUE),
            ("flux φ [µWb]", &flux, RED),
            ("position z [mm]", &z, BLACK),
        ];
        for (area, (label, ys, color)) in panels.iter().zip(series) {
            panel(area, &t_ms, &[(ys, color, label)], label)?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// One panel against t [ms]: each line (values, colour, name) where finite,
/// with a legend when there is more than one.
pub fn panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    t: &[f64],
    lines: &[(&[f64], RGBColor, &str)],
    label: &str,
) -> Result<(), String> {
    let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(1.0),
    );
    let (lo, hi) = lines
        .iter()
        .flat_map(|(y, _, _)| y.iter())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let pad = ((hi - lo).abs() * 0.05).max(1e-12);
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(t0..t1.max(t0 + 1e-12), (lo - pad)..(hi + pad))
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("t [ms]")
        .y_desc(label)
        .draw()
        .map_err(e)?;
    for &(y, color, name) in lines {
        let points: Vec<(f64, f64)> = t
            .iter()
            .copied()
            .zip(y.iter().copied())
            .filter(|(_, v)| v.is_finite())
            .collect();
        let series = chart
            .draw_series(LineSeries::new(envelope(&points), &color))
            .map_err(e)?;
        if lines.len() > 1 {
            series
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
    }
    if lines.len() > 1 {
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE.mix(0.8))
            .draw()
            .map_err(e)?;
    }
    Ok(())
}

/// At most this many points per line: more than a panel has pixels across.
const MOST_POINTS: usize = 4000;

/// `points` thinned to [`MOST_POINTS`]: per bucket of consecutive points the
/// lowest and the highest, in time order, so peaks and ripple stay visible
/// (an SVG of every sample of a long loop runs to megabytes).
fn envelope(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    if points.len() <= MOST_POINTS {
        return points.to_vec();
    }
    let bucket = points.len().div_ceil(MOST_POINTS / 2);
    let mut out = Vec::with_capacity(MOST_POINTS + 2);
    for chunk in points.chunks(bucket) {
        let lo = chunk
            .iter()
            .copied()
            .fold(chunk[0], |a, b| if b.1 < a.1 { b } else { a });
        let hi = chunk
            .iter()
            .copied()
            .fold(chunk[0], |a, b| if b.1 > a.1 { b } else { a });
        if lo.0 <= hi.0 {
            out.extend([lo, hi]);
        } else {
            out.extend([hi, lo]);
        }
    }
    out
}
