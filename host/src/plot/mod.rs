//! PNG plots of a run, sized for a lecture slide: `angle.png` (the transient as period means
//! and ranges, then the end window at full resolution, with the predicted equilibria) and
//! `phase.png` (the slow motion and the strobes over the whole run, then the end window's
//! trajectory).
//!
//! Text is drawn with DejaVu Sans, bundled in the binary (`host/assets/`, its licence beside it)
//! and registered with plotters' `ab_glyph` backend, so a machine without system fonts renders
//! the same. Legends sit in a header strip above the charts and the equilibrium labels in a
//! strip to their right, so neither covers the data.

mod angle;
pub mod axis;
mod phase;
mod ticked;
pub mod transient;

pub use angle::angle_png;
pub use phase::phase_png;

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::Path;
use std::sync::OnceLock;

use crate::record::Bucket;
use kapitza_core::model::Stability;

/// Text sizes are even: plotters' `ab_glyph` backend places each glyph at size/2 plus its top,
/// truncated to a pixel, so at odd sizes small glyphs (the decimal point) sit a pixel too high.
const FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
const SIZE: (u32, u32) = (1600, 1000);
const HEADER: u32 = 124;
const TITLE_FONT: u32 = 32;
const TEXT_FONT: u32 = 22;
const CAPTION_FONT: u32 = 24;
const AXIS_FONT: u32 = 24;
const TICK_FONT: u32 = 20;
/// Most strobes drawn (the CSV file keeps them all).
const MAX_STROBES: usize = 20_000;

/// Okabe & Ito colours, distinguishable in print and for common colour blindness.
const TRAJECTORY: RGBColor = RGBColor(0, 114, 178);
const BAND: RGBColor = RGBColor(178, 211, 234);
const SLOW: RGBColor = RGBColor(0, 0, 0);
const STROBE: RGBColor = RGBColor(213, 94, 0);
const STABLE: RGBColor = RGBColor(0, 158, 115);
const UNSTABLE: RGBColor = RGBColor(204, 60, 40);
const MARGINAL: RGBColor = RGBColor(230, 159, 0);
const GRID: RGBColor = RGBColor(225, 225, 225);

/// What both plots show. Angles are unwrapped, in rad, as the simulator integrated them.
pub struct PlotInput<'a> {
    pub title: &'a str,
    /// One line under the title: the parameters and the outcome.
    pub subtitle: String,
    /// The run's beginning, one bucket a drive period.
    pub first: &'a [Bucket],
    /// Whether `first` holds the whole run.
    pub first_is_whole: bool,
    /// The whole run in buckets of one or more periods.
    pub whole: &'a [Bucket],
    /// The end window at full resolution: (t, θ, θ').
    pub window: Vec<[f64; 3]>,
    /// Stroboscopic samples (t, θ, θ'), oldest first.
    pub strobes: Vec<(f64, f64, f64)>,
    /// Predicted equilibria (degrees, in (−180°, 180°]) with their stability.
    pub equilibria: Vec<(f64, Stability)>,
    /// Whether the angle is the averaged model's slow angle.
    pub averaged: bool,
}

impl PlotInput<'_> {
    /// Degrees to add to every angle: whole turns that put the end window's mean in
    /// (−90°, 270°] (see [`axis::turn_shift`]).
    fn shift(&self) -> f64 {
        let n = self.window.len().max(1) as f64;
        let mean = self.window.iter().map(|s| s[1]).sum::<f64>() / n;
        axis::turn_shift(mean.to_degrees())
    }

    /// The buckets the transient panel draws: the run's beginning, one period a bucket where
    /// kept, else the whole run's buckets.
    fn transient(&self) -> &[Bucket] {
        if self.first_is_whole {
            let n = transient::shown_periods(self.first);
            return &self.first[..n];
        }
        let n = transient::shown_periods(self.whole);
        let end = self.whole.get(n.saturating_sub(1)).map_or(0.0, |b| b.t1);
        if self.first.last().is_some_and(|b| b.t1 >= end) {
            let k = self.first.partition_point(|b| b.t1 <= end);
            &self.first[..k]
        } else {
            &self.whole[..n]
        }
    }

    /// The slow motion over the whole run.
    fn slow(&self) -> &[Bucket] {
        if self.first_is_whole {
            self.first
        } else {
            self.whole
        }
    }

    fn last_strobes(&self) -> &[(f64, f64, f64)] {
        &self.strobes[self.strobes.len().saturating_sub(MAX_STROBES)..]
    }

    fn names(&self) -> (&'static str, &'static str) {
        if self.averaged {
            ("φ", "φ'")
        } else {
            ("θ", "θ'")
        }
    }
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

fn style_of(s: Stability) -> (RGBColor, &'static str) {
    match s {
        Stability::Stable => (STABLE, "stable"),
        Stability::Unstable => (UNSTABLE, "unstable"),
        Stability::Marginal => (MARGINAL, "marginal"),
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

#[derive(Clone, Copy)]
enum Sample {
    Line(RGBColor),
    Band(RGBColor),
    Dashed(RGBColor),
    Dot(RGBColor),
}

/// Title, subtitle and a legend line of (sample, text) entries.
fn header(area: &Area, title: &str, subtitle: &str, legend: &[(Sample, String)]) -> Result<()> {
    let e = |e| anyhow!("{e}");
    area.draw(&Text::new(
        title.to_string(),
        (18, 8),
        ("sans-serif", TITLE_FONT).into_font(),
    ))
    .map_err(e)?;
    area.draw(&Text::new(
        subtitle.to_string(),
        (18, 48),
        ("sans-serif", TEXT_FONT)
            .into_font()
            .color(&RGBColor(60, 60, 60)),
    ))
    .map_err(e)?;
    let (mut x, y) = (20, 100);
    for (sample, text) in legend {
        match *sample {
            Sample::Line(c) => {
                area.draw(&PathElement::new(
                    vec![(x, y), (x + 32, y)],
                    c.stroke_width(3),
                ))
                .map_err(e)?;
            }
            Sample::Band(c) => {
                area.draw(&Rectangle::new([(x, y - 8), (x + 32, y + 8)], c.filled()))
                    .map_err(e)?;
            }
            Sample::Dashed(c) => {
                for dx in [0, 13, 26] {
                    area.draw(&PathElement::new(
                        vec![(x + dx, y), (x + dx + 7, y)],
                        c.stroke_width(3),
                    ))
                    .map_err(e)?;
                }
            }
            Sample::Dot(c) => {
                area.draw(&Circle::new((x + 16, y), 5, c.filled()))
                    .map_err(e)?;
            }
        }
        let style: TextStyle = ("sans-serif", TEXT_FONT).into();
        area.draw(&Text::new(text.clone(), (x + 42, y - 12), style.clone()))
            .map_err(e)?;
        let width = area
            .estimate_text_size(text, &style)
            .map_or(11 * text.len() as u32, |(w, _)| w);
        x += 42 + width as i32 + 32;
    }
    Ok(())
}

impl PlotInput<'_> {
    /// Whole drive periods in the end window.
    fn window_periods(&self) -> u64 {
        let span = match (self.window.first(), self.window.last()) {
            (Some(a), Some(b)) => b[0] - a[0],
            _ => 0.0,
        };
        let period = self
            .whole
            .first()
            .map_or(0.0, |b| (b.t1 - b.t0) / b.periods as f64);
        if period > 0.0 {
            (span / period).round() as u64
        } else {
            0
        }
    }
}

/// A line through `points`, one path element a segment: plotters joins the segments of a wide
/// path with mitres, which at the sharp turns of a zigzag shoot far out of the chart.
fn segments(
    points: &[(f64, f64)],
    style: ShapeStyle,
) -> impl Iterator<Item = PathElement<(f64, f64)>> + '_ {
    points
        .windows(2)
        .map(move |w| PathElement::new(vec![w[0], w[1]], style))
}
