//! The plots of `reldesign diagnose`: measured against simulated signals, the
//! current residual with the regions where it concentrates, and the flux
//! linkage–current loop of data and model.
//!
//! A bench record has tens of thousands of samples, far more than the plot has
//! pixel columns; each series is decimated to the minimum and maximum of every
//! column (consecutive samples, uniform in time by the measured-data spec), so a
//! 40 000-sample record draws as about 1 600 points with its spikes intact. The
//! λ–i loop is thinned instead to one point per plot cell it enters.

use plotters::coord::Shift;
use plotters::prelude::*;

/// Width of every plot [px].
const WIDTH: u32 = 900;
/// Height of one stacked panel, and of the title band [px].
const PANEL_HEIGHT: u32 = 300;
const TITLE_HEIGHT: u32 = 40;
/// Buckets a series is decimated to: about one per pixel column of the plot area.
const COLUMNS: usize = 800;
/// Measured and simulated colours, colours of extra simulated lines, region shades.
const MEASURED: RGBColor = BLUE;
const SIMULATED: RGBColor = RED;
const EXTRA: [RGBColor; 3] = [
    RGBColor(0, 150, 0),
    RGBColor(200, 0, 200),
    RGBColor(120, 80, 0),
];
const SHADES: [RGBColor; 5] = [
    RGBColor(255, 165, 0),
    RGBColor(0, 160, 0),
    RGBColor(160, 0, 200),
    RGBColor(0, 160, 200),
    RGBColor(200, 160, 0),
];

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Stacked panels against time in ms, one per distinct label (in order of
/// first appearance, measured first), each with its measured and simulated
/// series and a legend. A simulated label "<panel label>, <name>" (e.g.
/// "current i [A], extended (eddy-currents)") adds a line called <name> to
/// that panel instead of a panel of its own. `t` is in seconds; every series
/// has its samples; values are drawn in the unit their label names.
pub fn comparison_svg(
    title: &str,
    t: &[f64],
    measured: &[(&str, &[f64])],
    simulated: &[(&str, &[f64])],
) -> Result<String, String> {
    for (label, y) in measured.iter().chain(simulated) {
        check_len(label, y.len(), "t", t.len())?;
    }
    let (panels, lines) = comparison_lines(measured, simulated);
    if panels.is_empty() || t.is_empty() {
        return Err("comparison plot: no samples to draw".into());
    }
    let t_ms: Vec<f64> = t.iter().map(|x| x * 1e3).collect();
    let height = TITLE_HEIGHT + PANEL_HEIGHT * panels.len() as u32;
    render((WIDTH, height), title, |root| {
        for (area, panel) in root.split_evenly((panels.len(), 1)).iter().zip(&panels) {
            let mine: Vec<(&str, &[f64], RGBColor)> = lines
                .iter()
                .filter(|l| l.0 == *panel)
                .map(|l| (l.1, l.2, l.3))
                .collect();
            time_panel(area, &t_ms, panel, &mine, &[])?;
        }
        Ok(())
    })
}

/// The current residual against time in ms, with each (start [s], end [s],
/// label) region shaded, one colour and legend entry per distinct label.
pub fn residual_svg(
    title: &str,
    t: &[f64],
    residual: &[f64],
    regions: &[(f64, f64, &str)],
) -> Result<String, String> {
    check_len("residual", residual.len(), "t", t.len())?;
    if t.is_empty() {
        return Err("residual plot: no samples to draw".into());
    }
    let t_ms: Vec<f64> = t.iter().map(|x| x * 1e3).collect();
    let shaded: Vec<(f64, f64, &str)> = regions
        .iter()
        .map(|&(a, b, l)| (a * 1e3, b * 1e3, l))
        .collect();
    render((WIDTH, TITLE_HEIGHT + PANEL_HEIGHT + 100), title, |root| {
        let lines = [("i_sim − i_meas", residual, BLACK)];
        time_panel(root, &t_ms, "residual [A]", &lines, &shaded)
    })
}

/// The flux linkage–current loop of the data and of the model: λ [Wb] (drawn
/// in mWb) against i [A].
pub fn flux_current_loop_svg(
    title: &str,
    i_meas: &[f64],
    lambda_meas: &[f64],
    i_sim: &[f64],
    lambda_sim: &[f64],
) -> Result<String, String> {
    check_len("lambda_meas", lambda_meas.len(), "i_meas", i_meas.len())?;
    check_len("lambda_sim", lambda_sim.len(), "i_sim", i_sim.len())?;
    let to_mwb = |l: &[f64]| l.iter().map(|x| x * 1e3).collect::<Vec<f64>>();
    let curves = [
        (
            "measured",
            decimated_curve(i_meas, &to_mwb(lambda_meas)),
            MEASURED,
        ),
        (
            "simulated",
            decimated_curve(i_sim, &to_mwb(lambda_sim)),
            SIMULATED,
        ),
    ];
    let (x, y) = curves
        .iter()
        .flat_map(|c| c.1.iter())
        .copied()
        .unzip::<_, _, Vec<_>, Vec<_>>();
    if x.is_empty() {
        return Err("flux–current loop: no samples to draw".into());
    }
    render((WIDTH, WIDTH), title, |root| {
        let mut chart = ChartBuilder::on(root)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(padded(&x), padded(&y))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("current i [A]")
            .y_desc("flux linkage λ [mWb]")
            .draw()
            .map_err(err)?;
        for (label, points, color) in &curves {
            draw_line(&mut chart, points, label, *color)?;
        }
        legend(&mut chart)
    })
}

fn check_len(name: &str, len: usize, against: &str, n: usize) -> Result<(), String> {
    if len == n {
        Ok(())
    } else {
        Err(format!(
            "plot: `{name}` has {len} samples, `{against}` has {n}"
        ))
    }
}

/// A line of the comparison: (panel, legend, values, colour).
type Line<'a> = (&'a str, &'a str, &'a [f64], RGBColor);

/// The panels (distinct labels, measured first) and the lines drawn in them; a
/// simulated "<panel>, <name>" joins <panel> as an extra line called <name>.
fn comparison_lines<'a>(
    measured: &[(&'a str, &'a [f64])],
    simulated: &[(&'a str, &'a [f64])],
) -> (Vec<&'a str>, Vec<Line<'a>>) {
    let mut panels: Vec<&str> = Vec::new();
    let mut lines = Vec::new();
    for &(label, y) in measured {
        if !panels.contains(&label) {
            panels.push(label);
        }
        lines.push((label, "measured", y, MEASURED));
    }
    let mut extra = 0;
    for &(label, y) in simulated {
        if let Some((panel, name)) = joined_panel(&panels, label) {
            lines.push((panel, name, y, EXTRA[extra % EXTRA.len()]));
            extra += 1;
        } else {
            if !panels.contains(&label) {
                panels.push(label);
            }
            lines.push((label, "simulated", y, SIMULATED));
        }
    }
    (panels, lines)
}

/// The panel and line name of a label "<panel>, <name>" that is not itself a
/// panel.
fn joined_panel<'a>(panels: &[&'a str], label: &'a str) -> Option<(&'a str, &'a str)> {
    if panels.contains(&label) {
        return None;
    }
    panels.iter().find_map(|p| {
        let name = label.strip_prefix(p)?.strip_prefix(", ")?;
        (!name.is_empty()).then_some((*p, name))
    })
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// An SVG of `size` with a white background and a title; `draw` fills the rest.
fn render(
    size: (u32, u32),
    title: &str,
    draw: impl FnOnce(&Area) -> Result<(), String>,
) -> Result<String, String> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let body = root.titled(title, ("sans-serif", 22)).map_err(err)?;
        draw(&body)?;
        root.present().map_err(err)?;
    }
    Ok(out)
}

/// One panel against time [ms]: shaded (start, end, label) regions under
/// decimated lines, and a legend.
fn time_panel(
    area: &Area,
    t_ms: &[f64],
    y_desc: &str,
    lines: &[(&str, &[f64], RGBColor)],
    shaded: &[(f64, f64, &str)],
) -> Result<(), String> {
    let keep: Vec<Vec<usize>> = lines
        .iter()
        .map(|(_, y, _)| decimate(y.len(), COLUMNS, &[y]))
        .collect();
    let points: Vec<Vec<(f64, f64)>> = keep
        .iter()
        .zip(lines)
        .map(|(idx, (_, y, _))| idx.iter().map(|&k| (t_ms[k], y[k])).collect())
        .collect();
    let ys: Vec<f64> = points.iter().flatten().map(|p| p.1).collect();
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(
            padded(&[t_ms[0], t_ms[t_ms.len() - 1]]),
            legend_room(padded(&ys), lines.len() + distinct(shaded)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("t [ms]")
        .y_desc(y_desc)
        .draw()
        .map_err(err)?;
    shade(&mut chart, shaded)?;
    for ((label, _, color), pts) in lines.iter().zip(&points) {
        draw_line(&mut chart, pts, label, *color)?;
    }
    legend(&mut chart)
}

type Chart<'a> = ChartContext<
    'a,
    SVGBackend<'a>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Translucent full-height bands (clipped to the time axis), one colour and
/// legend entry per distinct label.
fn shade<'a>(chart: &mut Chart<'a>, regions: &[(f64, f64, &str)]) -> Result<(), String> {
    let (x, y) = (chart.x_range(), chart.y_range());
    let mut labels: Vec<&str> = Vec::new();
    for &(_, _, l) in regions {
        if !labels.contains(&l) {
            labels.push(l);
        }
    }
    for (n, label) in labels.iter().enumerate() {
        let color = SHADES[n % SHADES.len()].mix(0.25);
        let bands = regions
            .iter()
            .filter(|r| r.2 == *label)
            .map(|&(a, b, _)| (a.max(x.start), b.min(x.end)))
            .filter(|(a, b)| a < b)
            .map(|(a, b)| Rectangle::new([(a, y.start), (b, y.end)], color.filled()));
        chart
            .draw_series(bands)
            .map_err(err)?
            .label(*label)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 15, y + 5)], color.filled()));
    }
    Ok(())
}

/// A line through the finite points, broken where a value is not finite; one
/// legend entry.
fn draw_line<'a>(
    chart: &mut Chart<'a>,
    points: &[(f64, f64)],
    label: &str,
    color: RGBColor,
) -> Result<(), String> {
    let runs = points
        .split(|p| !(p.0.is_finite() && p.1.is_finite()))
        .filter(|run| !run.is_empty())
        .map(|run| PathElement::new(run.to_vec(), color));
    chart
        .draw_series(runs)
        .map_err(err)?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], color));
    Ok(())
}

fn legend<'a>(chart: &mut Chart<'a>) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

/// `y` raised at the top by a band per legend entry (a tenth of the span
/// each), so that the legend in the upper right covers no data.
fn legend_room(y: std::ops::Range<f64>, entries: usize) -> std::ops::Range<f64> {
    let span = y.end - y.start;
    y.start..y.end + 0.1 * span * entries as f64
}

/// The number of distinct labels of `regions`.
fn distinct(regions: &[(f64, f64, &str)]) -> usize {
    let mut labels: Vec<&str> = regions.iter().map(|r| r.2).collect();
    labels.sort_unstable();
    labels.dedup();
    labels.len()
}

/// The finite range of `v`, padded by 5 % (a unit-wide range around a constant).
fn padded(v: &[f64]) -> std::ops::Range<f64> {
    let (lo, hi) = v
        .iter()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    if lo > hi {
        // No finite value.
        return -1.0..1.0;
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1.0)
    };
    (lo - pad)..(hi + pad)
}

/// A curve (x, y) thinned to the plot's resolution: on a `COLUMNS` × `COLUMNS`
/// grid over the curve's range, a point is kept when its cell differs from the
/// last kept point's (so every dropped point lies in the cell of a kept one),
/// and non-finite points are kept to break the line. Min/max per column does
/// not apply to a loop, which may cross many columns between two samples.
fn decimated_curve(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let (gx, gy) = (grid(x), grid(y));
    let mut last = None;
    let mut out = Vec::new();
    for (&a, &b) in x.iter().zip(y) {
        let cell = gx(a).zip(gy(b));
        if cell.is_none() || cell != last {
            out.push((a, b));
        }
        last = cell;
    }
    out
}

/// The column of a value on a `COLUMNS`-cell grid over the finite range of `v`
/// (`None` for a non-finite value).
fn grid(v: &[f64]) -> impl Fn(f64) -> Option<i64> {
    let r = padded(v);
    let cell = (r.end - r.start) / COLUMNS as f64;
    move |x: f64| x.is_finite().then(|| ((x - r.start) / cell).floor() as i64)
}

/// The indices to draw of `n` samples: cut into `buckets` runs of consecutive
/// samples, each keeps the samples holding the minimum and the maximum of every
/// key, in sample order; the first and the last sample are always kept. At most
/// 2 · buckets · keys + 2 indices; all of them when `n` is not larger. Non-finite
/// values are never an extremum (a bucket of them only keeps nothing).
fn decimate(n: usize, buckets: usize, keys: &[&[f64]]) -> Vec<usize> {
    let bound = 2 * buckets * keys.len() + 2;
    if n <= bound || buckets == 0 {
        return (0..n).collect();
    }
    let mut keep = vec![0, n - 1];
    for b in 0..buckets {
        let (start, end) = (b * n / buckets, (b + 1) * n / buckets);
        for key in keys {
            keep.extend(
                extrema(&key[start..end])
                    .into_iter()
                    .flatten()
                    .map(|k| start + k),
            );
        }
    }
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// Positions of the minimum and the maximum of the finite values.
fn extrema(v: &[f64]) -> [Option<usize>; 2] {
    let finite = || v.iter().enumerate().filter(|(_, x)| x.is_finite());
    [
        finite().min_by(|a, b| a.1.total_cmp(b.1)).map(|p| p.0),
        finite().max_by(|a, b| a.1.total_cmp(b.1)).map(|p| p.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: usize = 40_000;

    /// A noisy-looking deterministic signal with one spike up and one down.
    fn record() -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..N).map(|k| k as f64 * 25e-6).collect();
        let mut y: Vec<f64> = (0..N)
            .map(|k| (k as f64 * 0.37).sin() * 0.01 + (k as f64 * 1e-3).sin())
            .collect();
        y[12_345] = 5.0;
        y[33_333] = -4.0;
        (t, y)
    }

    /// Points of the data lines of an SVG: the `<polyline points="x,y x,y …">`
    /// with more than two points (axes, ticks and legend marks have two).
    fn line_points(svg: &str) -> usize {
        svg.split("points=\"")
            .skip(1)
            .map(|s| s[..s.find('"').unwrap_or(0)].split_whitespace().count())
            .filter(|&n| n > 2)
            .sum()
    }

    #[test]
    fn decimation_keeps_the_extrema_and_is_bounded() {
        let (_, y) = record();
        let keep = decimate(N, COLUMNS, &[&y]);
        assert!(keep.len() <= 2 * COLUMNS + 2, "{}", keep.len());
        assert!(keep.windows(2).all(|w| w[0] < w[1]));
        assert!(keep.contains(&12_345) && keep.contains(&33_333));
        assert_eq!((keep[0], keep[keep.len() - 1]), (0, N - 1));
        // Every bucket's envelope survives: the decimated min/max of each bucket
        // equal the original ones.
        for b in 0..COLUMNS {
            let (s, e) = (b * N / COLUMNS, (b + 1) * N / COLUMNS);
            let orig = extrema(&y[s..e]).map(|k| y[s + k.unwrap()]);
            let kept: Vec<f64> = keep
                .iter()
                .filter(|&&k| k >= s && k < e)
                .map(|&k| y[k])
                .collect();
            let lo = kept.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = kept.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            assert_eq!([lo, hi], orig, "bucket {b}");
        }
    }

    #[test]
    fn short_series_are_not_decimated() {
        assert_eq!(
            decimate(10, COLUMNS, &[&[0.0; 10]]),
            (0..10).collect::<Vec<_>>()
        );
    }

    #[test]
    fn curves_keep_every_pixel_they_cross() {
        // Two slow loops: 20 000 samples per loop, about 2 300 cells around it.
        let angle = |k: usize| k as f64 * 4.0 * std::f64::consts::PI / N as f64;
        let x: Vec<f64> = (0..N).map(|k| angle(k).cos()).collect();
        let y: Vec<f64> = (0..N).map(|k| angle(k).sin()).collect();
        let curve = decimated_curve(&x, &y);
        assert!(curve.len() < N / 4, "{}", curve.len());
        // Every original point lies within one grid cell of a kept point.
        let (rx, ry) = (padded(&x), padded(&y));
        let cell = ((rx.end - rx.start) / COLUMNS as f64).max((ry.end - ry.start) / COLUMNS as f64);
        for k in (0..N).step_by(7) {
            let near = curve
                .iter()
                .any(|p| (p.0 - x[k]).abs() <= cell && (p.1 - y[k]).abs() <= cell);
            assert!(near, "sample {k} lost");
        }
        // A fast curve (cells apart between samples) keeps every sample.
        let fast: Vec<usize> = (0..N).step_by(50).collect();
        let (xf, yf): (Vec<f64>, Vec<f64>) = fast.iter().map(|&k| (x[k], y[k])).unzip();
        assert_eq!(decimated_curve(&xf, &yf).len(), fast.len());
    }

    #[test]
    fn non_finite_values_are_skipped() {
        let mut y = vec![1.0; 100];
        y[3] = f64::NAN;
        y[4] = -2.0;
        y[7] = 3.0;
        assert_eq!(extrema(&y[..10]), [Some(4), Some(7)]);
        assert_eq!(extrema(&[f64::NAN, f64::INFINITY]), [None, None]);
    }

    #[test]
    fn comparison_has_a_panel_per_signal_and_a_legend() {
        let (t, y) = record();
        let z: Vec<f64> = y.iter().map(|v| 0.5 * v).collect();
        let svg = comparison_svg(
            "valve A",
            &t,
            &[("current i [A]", &y), ("position z [mm]", &z)],
            &[("current i [A]", &z), ("position z [mm]", &y)],
        )
        .unwrap();
        for text in [
            "valve A",
            "current i [A]",
            "position z [mm]",
            "measured",
            "simulated",
            "t [ms]",
        ] {
            assert!(svg.contains(text), "missing {text}");
        }
        // Four decimated series of ≤ 2·COLUMNS + 2 points each.
        let drawn = line_points(&svg);
        assert!(
            drawn > 4 * COLUMNS && drawn <= 4 * (2 * COLUMNS + 2),
            "{drawn}"
        );
    }

    #[test]
    fn an_extended_simulation_joins_its_panel() {
        let (t, y) = record();
        let svg = comparison_svg(
            "x",
            &t,
            &[("current i [A]", &y)],
            &[
                ("current i [A]", &y),
                ("current i [A], extended (eddy-currents)", &y),
            ],
        )
        .unwrap();
        assert!(svg.contains("extended (eddy-currents)"), "legend entry");
        assert!(
            !svg.contains("current i [A], extended"),
            "no panel of its own"
        );
        assert_eq!(svg.matches("t [ms]").count(), 1, "one panel");
        let (panels, lines) = comparison_lines(
            &[("a", &y), ("b", &y)],
            &[("b", &y), ("b, fit", &y), ("c", &y), ("a, ", &y)],
        );
        assert_eq!(panels, ["a", "b", "c", "a, "]);
        let named: Vec<(&str, &str)> = lines.iter().map(|l| (l.0, l.1)).collect();
        assert_eq!(
            named,
            [
                ("a", "measured"),
                ("b", "measured"),
                ("b", "simulated"),
                ("b", "fit"),
                ("c", "simulated"),
                ("a, ", "simulated")
            ]
        );
    }

    #[test]
    fn comparison_rejects_mismatched_lengths() {
        let (t, y) = record();
        let e = comparison_svg("x", &t, &[("i", &y[1..])], &[]).unwrap_err();
        assert!(e.contains("`i` has 39999 samples"), "{e}");
    }

    #[test]
    fn residual_shows_labelled_regions() {
        let (t, y) = record();
        let regions = [
            (0.1, 0.2, "after voltage steps"),
            (0.5, 0.6, "after voltage steps"),
            (0.8, 0.85, "after impacts"),
        ];
        let svg = residual_svg("residual", &t, &y, &regions).unwrap();
        for text in [
            "after voltage steps",
            "after impacts",
            "i_sim − i_meas",
            "residual [A]",
        ] {
            assert!(svg.contains(text), "missing {text}");
        }
        assert_eq!(
            svg.matches("after voltage steps").count(),
            1,
            "one legend entry per label"
        );
        assert!(line_points(&svg) <= 2 * COLUMNS + 2);
        // A band is one rectangle; one outside the record draws nothing.
        let rects = |regions: &[(f64, f64, &str)]| {
            let svg = residual_svg("residual", &t, &y, regions).unwrap();
            svg.matches("<rect").count()
        };
        let outside = [
            regions[0],
            regions[1],
            regions[2],
            (5.0, 6.0, "after impacts"),
        ];
        assert_eq!(
            rects(&regions) - rects(&regions[..2]),
            1 + 1,
            "band and legend mark"
        );
        assert_eq!(rects(&outside), rects(&regions));
    }

    #[test]
    fn loop_draws_both_curves_with_a_gap_at_nan() {
        let i: Vec<f64> = (0..N).map(|k| 1.0 + (k as f64 * 1e-3).cos()).collect();
        let mut l: Vec<f64> = i.iter().map(|x| 0.02 * x.tanh()).collect();
        l[100] = f64::NAN;
        let svg = flux_current_loop_svg("loop", &i, &l, &i, &l).unwrap();
        for text in [
            "loop",
            "measured",
            "simulated",
            "current i [A]",
            "flux linkage λ [mWb]",
        ] {
            assert!(svg.contains(text), "missing {text}");
        }
        assert!(!svg.contains("NaN"));
        assert!(line_points(&svg) < 2 * N);
    }
}
