//! PNG plots of a run: the angle against time with the predicted equilibria, and the phase
//! portrait with the stroboscopic samples.
//!
//! Text is drawn with DejaVu Sans, bundled in the binary (`host/assets/`, its licence beside it)
//! and registered with plotters' `ab_glyph` backend, so a machine without system fonts renders
//! the same. Legends sit in a header strip above the chart and the equilibrium labels in a strip
//! to its right, so neither covers the data.

use anyhow::{anyhow, Result};
use plotters::coord::combinators::IntoLinspace;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::Path;
use std::sync::OnceLock;

use kapitza_core::model::Stability;

/// Text sizes are even: plotters' `ab_glyph` backend places each glyph at size/2 plus its top,
/// truncated to a pixel, so at odd sizes small glyphs (the decimal point) sit a pixel too high.
const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
const SIZE: (u32, u32) = (1200, 720);
const HEADER: u32 = 78;
const LABELS: u32 = 170;
/// Most trajectory points and strobes drawn (the CSV files keep them all).
const MAX_POINTS: usize = 20_000;

const TRAJECTORY: RGBColor = RGBColor(31, 90, 180);
const LIGHT_TRAJECTORY: RGBColor = RGBColor(150, 180, 225);
const STROBE: RGBColor = RGBColor(200, 40, 30);
const STABLE: RGBColor = RGBColor(20, 140, 60);
const UNSTABLE: RGBColor = RGBColor(210, 60, 40);
const MARGINAL: RGBColor = RGBColor(220, 140, 0);

/// What both plots show.
pub struct PlotInput<'a> {
    pub title: &'a str,
    /// One line under the title: the parameters and the outcome.
    pub subtitle: String,
    /// (t, θ unwrapped in rad, θ' in rad/s).
    pub series: &'a [[f64; 3]],
    /// Stroboscopic (θ rad, θ' rad/s), oldest first.
    pub strobes: Vec<(f64, f64)>,
    /// Predicted equilibria (degrees) with their stability.
    pub equilibria: Vec<(f64, Stability)>,
    /// Angles are drawn in [lo, lo + 360°): see [`window_lo`].
    pub window_lo: f64,
    /// Run length (s).
    pub t_end: f64,
    /// Whether the angle is the averaged model's slow angle.
    pub averaged: bool,
}

/// The angle window to draw in: (−180°, 180°] unless the motion lives near ±180°, then [0°, 360°).
pub fn window_lo(centre_deg: f64) -> f64 {
    if centre_deg.abs() > 90.0 {
        0.0
    } else {
        -180.0
    }
}

fn wrap_into(deg: f64, lo: f64) -> f64 {
    lo + (deg - lo).rem_euclid(360.0)
}

pub(crate) fn register() -> Result<()> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| register_font("sans-serif", FontStyle::Normal, FONT).is_ok());
    if ok {
        Ok(())
    } else {
        Err(anyhow!("the bundled font could not be loaded"))
    }
}

fn err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> anyhow::Error + '_ {
    move |e| anyhow!("cannot draw {}: {e}", path.display())
}

/// Splits points (x in degrees) into runs that do not jump across the window's cut.
fn unbroken(points: impl Iterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut prev: Option<f64> = None;
    for (a, b) in points {
        match prev {
            Some(p) if (a - p).abs() <= 180.0 => runs.last_mut().expect("a run").push((a, b)),
            _ => runs.push(vec![(a, b)]),
        }
        prev = Some(a);
    }
    runs
}

fn stride(n: usize) -> usize {
    n.div_ceil(MAX_POINTS).max(1)
}

fn style_of(s: Stability) -> (RGBColor, &'static str) {
    match s {
        Stability::Stable => (STABLE, "stable"),
        Stability::Unstable => (UNSTABLE, "unstable"),
        Stability::Marginal => (MARGINAL, "marginal"),
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// Title, subtitle and a legend line of (sample, text) entries.
fn header(area: &Area, title: &str, subtitle: &str, legend: &[(Sample, String)]) -> Result<()> {
    let e = |e| anyhow!("{e}");
    area.draw(&Text::new(
        title.to_string(),
        (14, 6),
        ("sans-serif", 24).into_font(),
    ))
    .map_err(e)?;
    area.draw(&Text::new(
        subtitle.to_string(),
        (14, 34),
        ("sans-serif", 16).into_font().color(&RGBColor(60, 60, 60)),
    ))
    .map_err(e)?;
    let (mut x, y) = (16, 64);
    for (sample, text) in legend {
        match *sample {
            Sample::Line(c) => {
                area.draw(&PathElement::new(
                    vec![(x, y), (x + 28, y)],
                    c.stroke_width(3),
                ))
                .map_err(e)?;
            }
            Sample::Dashed(c) => {
                for dx in [0, 12, 24] {
                    area.draw(&PathElement::new(
                        vec![(x + dx, y), (x + dx + 6, y)],
                        c.stroke_width(2),
                    ))
                    .map_err(e)?;
                }
            }
            Sample::Dot(c) => {
                area.draw(&Circle::new((x + 14, y), 4, c.filled()))
                    .map_err(e)?;
            }
        }
        let style: TextStyle = ("sans-serif", 16).into();
        area.draw(&Text::new(text.clone(), (x + 36, y - 9), style.clone()))
            .map_err(e)?;
        let width = area
            .estimate_text_size(text, &style)
            .map_or(8 * text.len() as u32, |(w, _)| w);
        x += 36 + width as i32 + 28;
    }
    Ok(())
}

#[derive(Clone, Copy)]
enum Sample {
    Line(RGBColor),
    Dashed(RGBColor),
    Dot(RGBColor),
}

/// `angle.png`: θ (degrees, in the window) against t, with the predicted equilibria as
/// horizontal lines (stable solid, unstable dashed, marginal dashed orange), labelled at the
/// right.
pub fn angle_png(path: &Path, p: &PlotInput) -> Result<()> {
    register()?;
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let (top, body) = root.split_vertically(HEADER);
    let (left, right) = body.split_horizontally(SIZE.0 - LABELS);
    let what = if p.averaged {
        "slow angle φ(t) (averaged model)"
    } else {
        "angle θ(t)"
    };
    header(
        &top,
        p.title,
        &p.subtitle,
        &[
            (Sample::Line(TRAJECTORY), what.to_string()),
            (
                Sample::Line(STABLE),
                "stable equilibrium (averaged theory)".into(),
            ),
            (Sample::Dashed(UNSTABLE), "unstable".into()),
        ],
    )?;
    let lo = p.window_lo;
    let t_end = if p.t_end > 0.0 { p.t_end } else { 1.0 };
    let mut chart = ChartBuilder::on(&left)
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(0.0..t_end, (lo..lo + 360.0 + 1e-9).step(45.0))
        .map_err(err(path))?;
    chart
        .configure_mesh()
        .x_desc("time t (s)")
        .y_desc(if p.averaged {
            "slow angle φ (degrees)"
        } else {
            "angle θ (degrees)"
        })
        .axis_desc_style(("sans-serif", 18))
        .label_style(("sans-serif", 16))
        .y_label_formatter(&|v| format!("{v:.0}°"))
        .x_label_formatter(&|v| format!("{v}"))
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()
        .map_err(err(path))?;
    // Equilibria under the trajectory, so a pendulum at rest on its line stays visible.
    let mut labels = Vec::new();
    for &(a, s) in &p.equilibria {
        let y = wrap_into(a, lo);
        let (colour, name) = style_of(s);
        let ends = [(0.0, y), (t_end, y)];
        if s == Stability::Stable {
            chart
                .draw_series(LineSeries::new(ends, colour.stroke_width(2)))
                .map_err(err(path))?;
        } else {
            chart
                .draw_series(DashedLineSeries::new(ends, 10, 7, colour.stroke_width(2)))
                .map_err(err(path))?;
        }
        let py = chart.backend_coord(&(t_end, y)).1;
        labels.push((py, format!("{name} {a:.1}°"), colour));
    }
    let k = stride(p.series.len());
    let points = p
        .series
        .iter()
        .step_by(k)
        .map(|s| (wrap_into(s[1].to_degrees(), lo), s[0]));
    for run in unbroken(points) {
        chart
            .draw_series(LineSeries::new(
                run.into_iter().map(|(a, t)| (t, a)),
                TRAJECTORY.stroke_width(1),
            ))
            .map_err(err(path))?;
    }
    // Labels at their lines' heights, pushed apart where lines are close.
    labels.sort_by_key(|l| l.0);
    let top_px = right.get_pixel_range().1.start;
    let mut last = i32::MIN;
    for (py, text, colour) in labels {
        let y = (py - top_px - 8).max(last + 18);
        last = y;
        right
            .draw(&Text::new(
                text,
                (6, y),
                ("sans-serif", 16).into_font().color(&colour),
            ))
            .map_err(err(path))?;
    }
    root.present().map_err(err(path))?;
    Ok(())
}

/// Range of `xs`, padded by 5 % (at least `min_span` wide).
fn padded(xs: impl Iterator<Item = f64>, min_span: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in xs.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if lo > hi {
        return (-1.0, 1.0);
    }
    let pad = (0.05 * (hi - lo)).max(0.5 * (min_span - (hi - lo)).max(0.0));
    (lo - pad, hi + pad)
}

/// `phase.png`: θ' against θ, the trajectory as a light line and the strobes as dots on top.
pub fn phase_png(path: &Path, p: &PlotInput) -> Result<()> {
    register()?;
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let (top, body) = root.split_vertically(HEADER);
    let lo = p.window_lo;
    let k = stride(p.series.len());
    let traj: Vec<(f64, f64)> = p
        .series
        .iter()
        .step_by(k)
        .map(|s| (wrap_into(s[1].to_degrees(), lo), s[2]))
        .collect();
    let skip = p.strobes.len().saturating_sub(MAX_POINTS);
    let strobes: Vec<(f64, f64)> = p.strobes[skip..]
        .iter()
        .map(|&(th, v)| (wrap_into(th.to_degrees(), lo), v))
        .collect();
    let all = || traj.iter().chain(&strobes);
    let (x0, x1) = padded(all().map(|q| q.0), 1.0);
    let (x0, x1) = (x0.max(lo), x1.min(lo + 360.0));
    let (y0, y1) = padded(all().map(|q| q.1), 1e-3);
    let (what, rate) = if p.averaged {
        ("slow trajectory (averaged model)", "φ'")
    } else {
        ("trajectory", "θ'")
    };
    header(
        &top,
        p.title,
        &p.subtitle,
        &[
            (Sample::Line(LIGHT_TRAJECTORY), what.to_string()),
            (
                Sample::Dot(STROBE),
                "stroboscopic samples (drive phase 2πk)".into(),
            ),
        ],
    )?;
    let mut chart = ChartBuilder::on(&body)
        .margin(12)
        .margin_right(30)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err(path))?;
    let angle = if p.averaged { "φ" } else { "θ" };
    chart
        .configure_mesh()
        .x_desc(format!("angle {angle} (degrees)"))
        .y_desc(format!("angular velocity {rate} (rad/s)"))
        .axis_desc_style(("sans-serif", 18))
        .label_style(("sans-serif", 16))
        .x_label_formatter(&|v| format!("{v}°"))
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()
        .map_err(err(path))?;
    for run in unbroken(traj.into_iter()) {
        chart
            .draw_series(LineSeries::new(run, LIGHT_TRAJECTORY.stroke_width(1)))
            .map_err(err(path))?;
    }
    chart
        .draw_series(strobes.iter().map(|&q| Circle::new(q, 3, STROBE.filled())))
        .map_err(err(path))?;
    root.present().map_err(err(path))?;
    Ok(())
}
