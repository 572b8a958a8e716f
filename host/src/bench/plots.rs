//! Log-log PNGs: work-precision per scene (error against median time, and against
//! evaluations; one line per method and number format, the peer included) and the
//! stability-criteria ladder (error against k; error against cost with Floquet's convergence).
//!
//! Text uses the bundled DejaVu Sans (see [`crate::plot`]); the legend sits in a strip to the
//! right of the chart, so it never covers data.

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::Path;

use super::measure::{Family, Point};
use super::ratio::{curve_label, curves};
use super::{Results, TARGETS};
use kapitza_core::sim::Format;
use kapitza_core::stability::Criterion;

const FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
const SIZE: (u32, u32) = (1280, 760);
const HEADER: u32 = 70;
const LEGEND: u32 = 330;
/// Errors are drawn no lower than this (an exact match would sit at −∞).
const FLOOR: f64 = 1e-17;

fn register() -> Result<()> {
    register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| anyhow!("the bundled font could not be loaded"))
}

fn colour(f: Family) -> RGBColor {
    match f {
        Family::Rk4 => RGBColor(31, 119, 180),
        Family::Dop853 => RGBColor(214, 39, 40),
        Family::Rkn86 => RGBColor(23, 190, 207),
        Family::Dop853Pi => RGBColor(247, 129, 191),
        Family::Rkn1210 => RGBColor(0, 90, 160),
        Family::Verlet => RGBColor(44, 160, 44),
        Family::Yoshida4 => RGBColor(148, 103, 189),
        Family::Yoshida6 => RGBColor(140, 86, 75),
        Family::AveragedDop853 => RGBColor(255, 127, 14),
        Family::AveragedRkn86 => RGBColor(188, 189, 34),
        Family::AveragedRkn86Pi => RGBColor(127, 63, 0),
        Family::PeerDopri5 => RGBColor(120, 120, 120),
        Family::PeerDop853 => RGBColor(190, 190, 60),
        Family::PeerDop853Autonomous => RGBColor(0, 0, 0),
    }
}

/// How a line is drawn.
#[derive(Clone, Copy)]
enum Mark {
    /// Solid line, filled circles (ours, f64).
    Solid,
    /// Dashed line, hollow circles (ours, f32).
    Dashed,
    /// Solid line, filled triangles (the peer).
    Triangle,
    /// Filled circles, no line.
    Dot,
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

fn e<E: std::fmt::Debug>(x: E) -> anyhow::Error {
    anyhow!("drawing failed: {x:?}")
}

fn header(area: &Area, title: &str, subtitle: &str) -> Result<()> {
    area.draw(&Text::new(
        title.to_string(),
        (14, 8),
        ("sans-serif", 24).into_font(),
    ))
    .map_err(e)?;
    area.draw(&Text::new(
        subtitle.to_string(),
        (14, 40),
        ("sans-serif", 16).into_font().color(&RGBColor(60, 60, 60)),
    ))
    .map_err(e)?;
    Ok(())
}

/// A white page: the header on top, the chart's area on the left and the legend's strip on the
/// right, so the legend never covers data. Returns (page, chart area, legend area).
fn page<'a>(path: &'a Path, title: &str, subtitle: &str) -> Result<(Area<'a>, Area<'a>, Area<'a>)> {
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let (top, body) = root.split_vertically(HEADER);
    let (left, right) = body.split_horizontally(SIZE.0 - LEGEND);
    header(&top, title, subtitle)?;
    Ok((root, left, right))
}

/// The chart in its area, with room for the axis labels.
fn builder<'a, 'b>(area: &'a Area<'b>) -> ChartBuilder<'a, 'b, BitMapBackend<'b>> {
    let mut b = ChartBuilder::on(area);
    b.margin(14)
        .margin_right(24)
        .x_label_area_size(50)
        .y_label_area_size(80);
    b
}

fn legend(area: &Area, entries: &[(String, RGBColor, Mark)], notes: &[String]) -> Result<()> {
    let mut y = 24;
    for (text, c, mark) in entries {
        let (x0, x1) = (10, 44);
        match mark {
            Mark::Solid | Mark::Triangle => {
                area.draw(&PathElement::new(vec![(x0, y), (x1, y)], c.stroke_width(2)))
                    .map_err(e)?;
            }
            Mark::Dashed => {
                for dx in [0, 13, 26] {
                    area.draw(&PathElement::new(
                        vec![(x0 + dx, y), (x0 + dx + 7, y)],
                        c.stroke_width(2),
                    ))
                    .map_err(e)?;
                }
            }
            Mark::Dot => {}
        }
        let centre = ((x0 + x1) / 2, y);
        match mark {
            Mark::Solid | Mark::Dot => area.draw(&Circle::new(centre, 4, c.filled())).map_err(e)?,
            Mark::Dashed => area
                .draw(&Circle::new(centre, 4, c.stroke_width(2)))
                .map_err(e)?,
            Mark::Triangle => area
                .draw(&TriangleMarker::new(centre, 6, c.filled()))
                .map_err(e)?,
        }
        area.draw(&Text::new(
            text.clone(),
            (x1 + 10, y - 9),
            ("sans-serif", 16).into_font(),
        ))
        .map_err(e)?;
        y += 26;
    }
    y += 10;
    for n in notes {
        area.draw(&Text::new(
            n.clone(),
            (10, y),
            ("sans-serif", 14).into_font().color(&RGBColor(70, 70, 70)),
        ))
        .map_err(e)?;
        y += 20;
    }
    Ok(())
}

fn log_range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (1e-3, 1.0);
    }
    (lo / pad, hi * pad)
}

/// Exponent labels: 1e-6 rather than 0.000001.
fn pow10(v: &f64) -> String {
    let l = v.log10();
    if (l - l.round()).abs() < 1e-6 {
        format!("1e{}", l.round() as i32)
    } else {
        format!("{v:.1e}")
    }
}

/// What the x axis of a work-precision plot measures.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    Time,
    Evals,
}

fn x_of(p: &Point, axis: Axis) -> f64 {
    match axis {
        Axis::Time => p.wall_s,
        Axis::Evals => p.rhs_evals as f64,
    }
}

/// A scene's work-precision plot.
pub fn work_precision(path: &Path, r: &Results, scene: &str, axis: Axis) -> Result<()> {
    register()?;
    let Some(info) = r.scenes.iter().find(|s| s.name == scene) else {
        return Err(anyhow!("no scene {scene}"));
    };
    let lines = curves(&r.measurements, scene);
    let all = || lines.iter().flat_map(|(_, v)| v.iter());
    let (x0, x1) = log_range(all().map(|p| x_of(p, axis)), 1.6);
    let check = info.reference.check_difference.max(FLOOR);
    let (y0, y1) = log_range(
        all().map(|p| p.error.max(FLOOR)).chain([check, TARGETS[1]]),
        4.0,
    );
    let what = match axis {
        Axis::Time => "median wall time per run",
        Axis::Evals => "right-hand-side evaluations per run",
    };
    let (root, left, right) = page(
        path,
        &format!("Work-precision: {scene} ({:.2} s simulated, {:.0} drive periods)", info.horizon_s, info.periods),
        &format!(
            "error = max(|Δθ|, |Δθ'|/ω) at the end against DOP853 at 1e-13, against {what}; lower left is better"
        ),
    )?;
    let mut chart = builder(&left)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(match axis {
            Axis::Time => "wall time (s), median",
            Axis::Evals => "evaluations of the acceleration",
        })
        .y_desc("error at the end time")
        .axis_desc_style(("sans-serif", 18))
        .label_style(("sans-serif", 15))
        .x_label_formatter(&pow10)
        .y_label_formatter(&pow10)
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(e)?;
    let grey = RGBColor(150, 150, 150);
    for t in TARGETS {
        chart
            .draw_series(DashedLineSeries::new(
                [(x0, t), (x1, t)],
                8,
                6,
                grey.stroke_width(1),
            ))
            .map_err(e)?;
    }
    chart
        .draw_series(DashedLineSeries::new(
            [(x0, check), (x1, check)],
            2,
            4,
            RGBColor(200, 60, 160).stroke_width(2),
        ))
        .map_err(e)?;
    let mut entries = Vec::new();
    for ((family, format), pts) in &lines {
        let mut pts = pts.clone();
        pts.sort_by_key(|p| p.rhs_evals);
        let c = colour(*family);
        let xy: Vec<(f64, f64)> = pts
            .iter()
            .map(|p| (x_of(p, axis), p.error.max(FLOOR)))
            .collect();
        let mark = if family.is_peer() {
            Mark::Triangle
        } else if *format == Format::F32 {
            Mark::Dashed
        } else {
            Mark::Solid
        };
        match mark {
            Mark::Dashed => {
                chart
                    .draw_series(DashedLineSeries::new(xy.clone(), 9, 6, c.stroke_width(2)))
                    .map_err(e)?;
                chart
                    .draw_series(xy.iter().map(|&q| Circle::new(q, 4, c.stroke_width(2))))
                    .map_err(e)?;
            }
            Mark::Triangle => {
                chart
                    .draw_series(LineSeries::new(xy.clone(), c.stroke_width(2)))
                    .map_err(e)?;
                chart
                    .draw_series(xy.iter().map(|&q| TriangleMarker::new(q, 6, c.filled())))
                    .map_err(e)?;
            }
            _ => {
                chart
                    .draw_series(LineSeries::new(xy.clone(), c.stroke_width(2)))
                    .map_err(e)?;
                chart
                    .draw_series(xy.iter().map(|&q| Circle::new(q, 4, c.filled())))
                    .map_err(e)?;
            }
        }
        entries.push((curve_label(*family, *format), c, mark));
    }
    let notes = vec![
        "grey dashes: target errors 1e-6, 1e-9".to_string(),
        format!(
            "pink dots: reference check, {:.1e}",
            info.reference.check_difference
        ),
        "(errors below it are not resolved)".to_string(),
        "dashed lines, hollow circles: f32".to_string(),
        "triangles: the peer (ode_solvers, f64)".to_string(),
    ];
    legend(&right, &entries, &notes)?;
    root.present().map_err(e)?;
    Ok(())
}

fn criterion_colour(c: Criterion) -> RGBColor {
    match c {
        Criterion::Averaging => RGBColor(255, 127, 14),
        Criterion::Mathieu => RGBColor(31, 119, 180),
        Criterion::HarmonicBalance => RGBColor(44, 160, 44),
        Criterion::Floquet => RGBColor(0, 0, 0),
    }
}

/// Each cheaper criterion's error against Floquet as k varies.
pub fn stability_error(path: &Path, r: &Results) -> Result<()> {
    register()?;
    let rows: Vec<_> = r
        .stability_criteria
        .iter()
        .filter(|c| c.criterion != Criterion::Floquet)
        .collect();
    let (y0, y1) = log_range(rows.iter().filter_map(|c| c.error), 3.0);
    let (root, left, right) = page(
        path,
        "Stability criteria against Floquet (undamped)",
        "error = larger |window end − Floquet's end| in m = A/ℓ; k < 0 inverted, k > 0 hanging",
    )?;
    let mut chart = builder(&left)
        .build_cartesian_2d(-1.0..1.0, (y0..y1).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("signed k = ±(ω0/ω)²")
        .y_desc("error of the window's ends (in m)")
        .axis_desc_style(("sans-serif", 18))
        .label_style(("sans-serif", 15))
        .y_label_formatter(&pow10)
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(e)?;
    let mut entries = Vec::new();
    for name in Criterion::CHEAPER {
        let c = criterion_colour(name);
        for inverted in [true, false] {
            let pts: Vec<_> = rows
                .iter()
                .filter(|r| r.criterion == name && (r.k < 0.0) == inverted)
                .filter_map(|r| {
                    r.error
                        .filter(|&x| x > 0.0)
                        .map(|x| (r.k, x, r.missing_end))
                })
                .collect();
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|&(k, x, _)| (k, x)),
                    c.stroke_width(2),
                ))
                .map_err(e)?;
            for &(k, x, missing) in &pts {
                if missing {
                    chart
                        .draw_series([Circle::new((k, x), 5, c.stroke_width(2))])
                        .map_err(e)?;
                } else {
                    chart
                        .draw_series([Circle::new((k, x), 4, c.filled())])
                        .map_err(e)?;
                }
            }
        }
        entries.push((name.label().to_string(), c, Mark::Solid));
    }
    legend(
        &right,
        &entries,
        &[
            "hollow: the criterion has no upper end;".into(),
            "the error is that of the lower end only.".into(),
            String::new(),
            "averaging about the hanging position:".into(),
            "lower end 0 (exact), no upper end.".into(),
            String::new(),
            "Floquet: 1000 RK4 steps per period; its".into(),
            "own error is ≈ 1e-11 (stability-cost.png).".into(),
        ],
    )?;
    root.present().map_err(e)?;
    Ok(())
}

/// Error against cost: each criterion's points (one per k) and Floquet's convergence curves.
pub fn stability_cost(path: &Path, r: &Results) -> Result<()> {
    register()?;
    let rows: Vec<_> = r
        .stability_criteria
        .iter()
        .filter(|c| c.criterion != Criterion::Floquet && c.error.is_some_and(|x| x > 0.0))
        .collect();
    let fl = &r.floquet_convergence;
    let (x0, x1) = log_range(
        rows.iter()
            .map(|c| c.seconds_per_eval)
            .chain(fl.iter().map(|f| f.seconds_per_eval)),
        2.0,
    );
    let (y0, y1) = log_range(
        rows.iter()
            .filter_map(|c| c.error)
            .chain(fl.iter().filter_map(|f| f.error.map(|x| x.max(FLOOR)))),
        3.0,
    );
    let (root, left, right) = page(
        path,
        "Stability criteria: error against cost",
        "one point per k for each criterion; Floquet's own error against a finer Floquet as its RK4 steps per period grow",
    )?;
    let mut chart = builder(&left)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("wall time per evaluation of the window (s), median")
        .y_desc("error of the window's ends (in m)")
        .axis_desc_style(("sans-serif", 18))
        .label_style(("sans-serif", 15))
        .x_label_formatter(&pow10)
        .y_label_formatter(&pow10)
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(e)?;
    let mut entries = Vec::new();
    for name in Criterion::CHEAPER {
        let c = criterion_colour(name);
        chart
            .draw_series(rows.iter().filter(|r| r.criterion == name).filter_map(|r| {
                r.error
                    .map(|x| Circle::new((r.seconds_per_eval, x), 5, c.filled()))
            }))
            .map_err(e)?;
        entries.push((name.label().to_string(), c, Mark::Dot));
    }
    let mut ks: Vec<f64> = fl.iter().map(|f| f.k).collect();
    ks.dedup();
    let shades = [
        RGBColor(0, 0, 0),
        RGBColor(200, 60, 160),
        RGBColor(90, 90, 90),
    ];
    for (i, k) in ks.iter().enumerate() {
        let c = shades[i % shades.len()];
        let pts: Vec<(f64, f64)> = fl
            .iter()
            .filter(|f| f.k == *k)
            .filter_map(|f| f.error.map(|x| (f.seconds_per_eval, x.max(FLOOR))))
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(e)?;
        chart
            .draw_series(pts.iter().map(|&q| TriangleMarker::new(q, 6, c.filled())))
            .map_err(e)?;
        for f in fl.iter().filter(|f| f.k == *k) {
            if let Some(x) = f.error {
                // Beside the marker, not on it.
                let label = EmptyElement::at((f.seconds_per_eval, x.max(FLOOR)))
                    + Text::new(
                        format!("{}", f.steps_per_period),
                        (9, -4),
                        ("sans-serif", 13).into_font().color(&c),
                    );
                chart.draw_series([label]).map_err(e)?;
            }
        }
        let steps: Vec<u32> = fl
            .iter()
            .filter(|f| f.k == *k)
            .map(|f| f.steps_per_period)
            .collect();
        entries.push((
            format!(
                "Floquet, k = {k}: {}…{} steps",
                steps.first().copied().unwrap_or(0),
                steps.last().copied().unwrap_or(0)
            ),
            c,
            Mark::Triangle,
        ));
    }
    let reference = fl.first().map_or(0, |f| f.reference_steps);
    legend(
        &right,
        &entries,
        &[
            format!("Floquet error against {reference} steps per period;"),
            "labels: RK4 steps per period".into(),
        ],
    )?;
    root.present().map_err(e)?;
    Ok(())
}

/// Writes every plot into `dir`; returns the file names.
pub fn all(r: &Results, dir: &Path) -> Result<Vec<String>> {
    let mut files = Vec::new();
    for s in &r.scenes {
        for (axis, stem) in [(Axis::Time, "wp-time"), (Axis::Evals, "wp-evals")] {
            let name = format!("{stem}-{}.png", s.name);
            work_precision(&dir.join(&name), r, s.name, axis)?;
            files.push(name);
        }
    }
    stability_error(&dir.join("stability-error.png"), r)?;
    files.push("stability-error.png".into());
    stability_cost(&dir.join("stability-cost.png"), r)?;
    files.push("stability-cost.png".into());
    Ok(files)
}
