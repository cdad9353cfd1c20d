//! `reldesign build --plot FILE.svg` for the backstepping law: the (z₁, z₂)
//! plane of each target, as switched-force-backstepping's Fig. 5–6 draw it:
//! the line F_d = 0 (the magnet cannot push beyond it), the region of the
//! paper's V₁ = ½‖Z‖² (P = ½I, [SB lemma 1]), the region of the design's P
//! ([SB Theorem 3], extended to the spring's rest where needed), the
//! spring's rest X₀ and the target (the origin); dashed, the stroke's stops.
//! The lower row zooms to the stroke, where the armature can be: the regions'
//! extent in z₁ is far beyond it, their extent in velocity is what matters.

use designer::design::{BacksteppingDesign, Sym2};
use plotters::prelude::*;

/// The paper's P of V₁ = ½‖Z‖² [SB 11].
const HALF_IDENTITY: Sym2 = [0.5, 0.0, 0.5];

/// Points of the ellipse ZᵀPZ = C: Z = √C·L⁻ᵀ·(cos θ, sin θ), P = L·Lᵀ.
fn ellipse(p: Sym2, c: f64) -> Vec<(f64, f64)> {
    let [a, b, d] = p;
    let (l11, l21) = (a.sqrt(), b / a.sqrt());
    let l22 = (d - l21 * l21).sqrt();
    (0..=720)
        .map(|i| {
            let th = f64::from(i) * std::f64::consts::TAU / 720.0;
            let (w1, w2) = (th.cos() * c.sqrt(), th.sin() * c.sqrt());
            let z2 = w2 / l22;
            let z1 = (w1 - l21 * z2) / l11;
            (z1 * 1e3, z2)
        })
        .collect()
}

/// The ellipse ZᵀPZ = C over z₁ ∈ [x0, x1] [mm] as its two branches in z₂
/// (where it spans that z₁).
fn branches(p: Sym2, c: f64, x0: f64, x1: f64) -> [Vec<(f64, f64)>; 2] {
    let [a, b, d] = p;
    let mut out = [Vec::new(), Vec::new()];
    for i in 0..=400 {
        let x = x0 + (x1 - x0) * f64::from(i) / 400.0;
        let z1 = x * 1e-3;
        let disc = b * b * z1 * z1 - d * (a * z1 * z1 - c);
        if disc >= 0.0 {
            out[0].push((x, (-b * z1 + disc.sqrt()) / d));
            out[1].push((x, (-b * z1 - disc.sqrt()) / d));
        }
    }
    out
}

/// The SVG: per target, the whole regions above and the stroke below.
pub fn svg(b: &BacksteppingDesign, title: &str) -> Result<String, String> {
    let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let n = b.region.targets.len().max(1);
    let mut out = String::new();
    {
        let width = 700 * u32::try_from(n).unwrap_or(1);
        let root = SVGBackend::with_string(&mut out, (width, 1100)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
        let panels = root.split_evenly((2, n));
        for (i, area) in panels.iter().enumerate() {
            panel(b, i % n, i >= n, area)?;
        }
        root.present().map_err(e)?;
    }
    Ok(out)
}

/// One panel: target `index`, the whole regions or (`stroke`) zoomed to the stroke.
fn panel(
    b: &BacksteppingDesign,
    index: usize,
    stroke: bool,
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
) -> Result<(), String> {
    let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let r = &b.region;
    let (Some(target), Some(level), Some(identity)) = (
        r.targets.get(index),
        r.levels.get(index),
        r.identity.get(index),
    ) else {
        return Ok(());
    };
    let designed = ellipse(r.p, level.c);
    let paper = ellipse(HALF_IDENTITY, identity.c);
    let rest = (target.rest[0] * 1e3, target.rest[1]);
    let (mut x0, mut x1, mut y0, mut y1) = (rest.0, rest.0, rest.1, rest.1);
    for &(x, y) in designed.iter().chain(&paper) {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if stroke {
        (x0, x1) = (
            (b.z_min - target.position) * 1e3,
            (b.z_max - target.position) * 1e3,
        );
    }
    let (dx, dy) = (0.15 * (x1 - x0).max(1e-9), 0.15 * (y1 - y0).max(1e-9));
    let (x0, x1, y0, y1) = (x0 - dx, x1 + dx, y0 - dy, y1 + dy);
    let caption = if stroke {
        format!("y_r = {:.3} mm, within the stroke", target.position * 1e3)
    } else {
        format!(
            "y_r = {:.3} mm: F_d = g − kᵀZ, g = {:.3} N",
            target.position * 1e3,
            target.holding_force
        )
    };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 16))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("z₁ = z − y_r [mm]")
        .y_desc("z₂ = v + α₁·z₁ [m/s]")
        .draw()
        .map_err(e)?;
    // F_d = 0: k₁·z₁ + k₂·z₂ = g, drawn across the panel
    let [k1, k2] = r.force_gradient;
    let g = target.holding_force;
    let line: Vec<(f64, f64)> = if k2.abs() > 1e-300 {
        (0..=400)
            .map(|i| x0 + (x1 - x0) * f64::from(i) / 400.0)
            .map(|x| (x, (g - k1 * x * 1e-3) / k2))
            .filter(|&(_, y)| y >= y0 && y <= y1)
            .collect()
    } else {
        let x = g / k1 * 1e3;
        vec![(x, y0), (x, y1)]
    };
    // the curves' runs inside the panel, each drawn on its own
    let runs = |pts: Vec<(f64, f64)>| -> Vec<Vec<(f64, f64)>> {
        let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for (x, y) in pts {
            if (x0..=x1).contains(&x) && (y0..=y1).contains(&y) {
                runs.last_mut().map(|r| r.push((x, y)));
            } else if runs.last().is_some_and(|r| !r.is_empty()) {
                runs.push(Vec::new());
            }
        }
        runs
    };
    chart
        .draw_series(LineSeries::new(line, RED.stroke_width(2)))
        .map_err(e)?
        .label("F_d = 0")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
    let curves = [
        (
            paper,
            HALF_IDENTITY,
            identity.c,
            BLUE.stroke_width(2),
            "D of V₁ = ½‖Z‖²",
        ),
        (
            designed,
            r.p,
            level.c,
            GREEN.stroke_width(3),
            "D of ZᵀPZ, the LMI's P",
        ),
    ];
    for (points, p, c, style, name) in curves {
        let label = format!("{name} (C = {c:.3e})");
        let pieces = if stroke {
            branches(p, c, x0, x1)
                .into_iter()
                .flat_map(runs)
                .collect::<Vec<_>>()
        } else {
            runs(points)
        };
        for (k, run) in pieces.into_iter().enumerate() {
            let series = chart.draw_series(LineSeries::new(run, style)).map_err(e)?;
            if k == 0 {
                series
                    .label(label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            }
        }
    }
    for z in [b.z_min, b.z_max] {
        let x = (z - target.position) * 1e3;
        if x > x0 && x < x1 {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x, y0), (x, y1)],
                    6,
                    4,
                    BLACK.mix(0.5).into(),
                ))
                .map_err(e)?;
        }
    }
    chart
        .draw_series([Circle::new(rest, 6, BLACK.filled())])
        .map_err(e)?
        .label(format!(
            "X₀: the spring's rest (z = {:.3} mm)",
            b.rest * 1e3
        ))
        .legend(|(x, y)| Circle::new((x + 10, y), 5, BLACK.filled()));
    chart
        .draw_series([Cross::new((0.0, 0.0), 6, BLACK.stroke_width(2))])
        .map_err(e)?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .draw()
        .map_err(e)?;
    Ok(())
}
