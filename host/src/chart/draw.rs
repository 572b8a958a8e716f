//! One figure drawn twice, to PNG and to SVG, at a size readable on a lecture slide, with the
//! bundled font (see [`crate::plot`]): a title and subtitle strip, then the chart.

use anyhow::{anyhow, Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Pixels: 16:10, large type.
pub const SIZE: (u32, u32) = (1600, 1000);
pub const TITLE_FONT: u32 = 40;
pub const SUBTITLE_FONT: u32 = 24;
pub const AXIS_FONT: u32 = 28;
pub const TICK_FONT: u32 = 24;
pub const LEGEND_FONT: u32 = 22;
const HEADER: u32 = 100;

/// Colours for a few series, distinguishable in print and for common colour blindness
/// (Okabe & Ito).
pub const SERIES: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// What a chart draws onto any backend.
pub trait Figure {
    fn title(&self) -> String;
    fn subtitle(&self) -> String;
    /// Draws the chart body (below the title strip).
    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()>;
}

/// A plotters error as a sentence.
pub fn pe<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("{e}")
}

fn render<DB: DrawingBackend, F: Figure>(root: DrawingArea<DB, Shift>, fig: &F) -> Result<()> {
    root.fill(&WHITE).map_err(pe)?;
    let (top, body) = root.split_vertically(HEADER);
    top.draw(&Text::new(
        fig.title(),
        (24, 12),
        ("sans-serif", TITLE_FONT).into_font(),
    ))
    .map_err(pe)?;
    top.draw(&Text::new(
        fig.subtitle(),
        (24, 62),
        ("sans-serif", SUBTITLE_FONT)
            .into_font()
            .color(&RGBColor(70, 70, 70)),
    ))
    .map_err(pe)?;
    fig.body(&body)?;
    root.present().map_err(pe)?;
    Ok(())
}

/// Writes `DIR/STEM.png` and `DIR/STEM.svg`; returns their paths.
pub fn save<F: Figure>(dir: &Path, stem: &str, fig: &F) -> Result<Vec<PathBuf>> {
    crate::plot::register()?;
    let png = dir.join(format!("{stem}.png"));
    let svg = dir.join(format!("{stem}.svg"));
    render(BitMapBackend::new(&png, SIZE).into_drawing_area(), fig)
        .with_context(|| format!("cannot write {}", png.display()))?;
    render(SVGBackend::new(&svg, SIZE).into_drawing_area(), fig)
        .with_context(|| format!("cannot write {}", svg.display()))?;
    Ok(vec![png, svg])
}

/// Checks before any work that `dir` exists (creating it) and is writable.
pub fn prepare_dir(dir: &Path) -> Result<()> {
    crate::files::check_out_dir("--out", dir)
}

/// A light tint of a colour, for shaded regions.
pub fn tint(c: RGBColor, amount: f64) -> RGBColor {
    let mix = |x: u8| (255.0 - (255.0 - f64::from(x)) * amount).round() as u8;
    RGBColor(mix(c.0), mix(c.1), mix(c.2))
}
