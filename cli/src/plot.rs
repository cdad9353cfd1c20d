//! `--plot out.svg`: current, flux and position of a replay, stacked.

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
        for (panel, (label, ys, color)) in panels.iter().zip(series) {
            draw(panel, &t_ms, ys, label, color)?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

fn draw<'a>(
    area: &DrawingArea<SVGBackend<'a>, plotters::coord::Shift>,
    t: &[f64],
    y: &[f64],
    label: &str,
    color: RGBColor,
) -> Result<(), String> {
    let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(1.0),
    );
    let (lo, hi) = y
        .iter()
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
    chart
        .draw_series(LineSeries::new(
            t.iter().copied().zip(y.iter().copied()),
            &color,
        ))
        .map_err(e)?;
    Ok(())
}
