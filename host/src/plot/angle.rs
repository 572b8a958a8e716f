//! `angle.png`: two panels over time. Above, the transient: each drive period's range of the
//! angle as a band and its mean (the slow motion) as a line, from t = 0 until well after the
//! motion settles. Below, the last drive periods at full resolution with the strobes. Both on
//! the unwrapped angle, so neither is cut at ±180°, with the predicted equilibria at every turn
//! in view.

use anyhow::Result;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

use super::ticked::Ticked;

use super::{
    axis, err, header, segments, style_of, Area, PlotInput, Sample, AXIS_FONT, BAND, CAPTION_FONT,
    GRID, HEADER, SIZE, SLOW, STABLE, STROBE, TEXT_FONT, TICK_FONT, TRAJECTORY, UNSTABLE,
};
use kapitza_core::model::Stability;

const LABELS: u32 = 200;
/// Narrowest angle range drawn (degrees): a rest's tiny wiggle is not blown up to fill a panel.
const MIN_SPAN: f64 = 4.0;

type Chart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, Ticked>>;

pub fn angle_png(path: &Path, p: &PlotInput) -> Result<()> {
    super::register()?;
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let (top, body) = root.split_vertically(HEADER);
    let (angle, _) = p.names();
    let slow = if p.averaged {
        "period mean of the slow angle"
    } else {
        "period mean (slow motion)"
    };
    header(
        &top,
        p.title,
        &p.subtitle,
        &[
            (Sample::Band(BAND), "range over each drive period".into()),
            (Sample::Line(SLOW), slow.into()),
            (Sample::Line(TRAJECTORY), format!("{angle}(t)")),
            (Sample::Dot(STROBE), "strobes".into()),
            (Sample::Line(STABLE), "stable (averaged theory)".into()),
            (Sample::Dashed(UNSTABLE), "unstable".into()),
        ],
    )?;
    let shift = p.shift();
    let (upper, lower) = body.split_vertically((SIZE.1 - HEADER) / 2);
    let deg = |rad: f64| rad.to_degrees() + shift;

    // The transient.
    let buckets = p.transient();
    let t0 = buckets.first().map_or(0.0, |b| b.t0);
    let t1 = buckets.last().map_or(1.0, |b| b.t1);
    let span = axis::padded(
        buckets.iter().flat_map(|b| [deg(b.min), deg(b.max)]),
        MIN_SPAN,
    );
    let unit = Unit::for_span(span);
    let deg = |rad: f64| unit.of(rad, shift);
    let span = unit.range(span, shift);
    let periods: u64 = buckets.iter().map(|b| b.periods).sum();
    let caption = if periods as usize == buckets.len() {
        format!("the first {periods} drive periods: each period's range and mean")
    } else {
        format!(
            "the first {periods} drive periods: range and mean over every {}",
            buckets.first().map_or(1, |b| b.periods)
        )
    };
    let mut chart = panel(&upper, path, &caption, (t0, t1), span, angle, unit)?;
    if unit == Unit::Degrees {
        equilibria(&mut chart, &upper, path, p, span)?;
    }
    let mut band: Vec<(f64, f64)> = buckets
        .iter()
        .flat_map(|b| [(b.t0, deg(b.max)), (b.t1, deg(b.max))])
        .collect();
    band.extend(
        buckets
            .iter()
            .rev()
            .flat_map(|b| [(b.t1, deg(b.min)), (b.t0, deg(b.min))]),
    );
    chart
        .draw_series(std::iter::once(Polygon::new(band, BAND.filled())))
        .map_err(err(path))?;
    let means: Vec<(f64, f64)> = buckets.iter().map(|b| (b.t_mid(), deg(b.mean))).collect();
    chart
        .draw_series(segments(&means, SLOW.stroke_width(2)))
        .map_err(err(path))?;

    // The end window.
    let w = &p.window;
    let t0 = w.first().map_or(0.0, |s| s[0]);
    let t1 = w.last().map_or(1.0, |s| s[0]).max(t0 + 1e-9);
    let deg = |rad: f64| rad.to_degrees() + shift;
    let span = axis::padded(w.iter().map(|s| deg(s[1])), MIN_SPAN);
    let unit = Unit::for_span(span);
    let deg = |rad: f64| unit.of(rad, shift);
    let span = unit.range(span, shift);
    let periods = p.window_periods();
    let caption = format!("the last {periods} drive periods at full resolution");
    let mut chart = panel(&lower, path, &caption, (t0, t1), span, angle, unit)?;
    if unit == Unit::Degrees {
        equilibria(&mut chart, &lower, path, p, span)?;
    }
    let line: Vec<(f64, f64)> = w.iter().map(|s| (s[0], deg(s[1]))).collect();
    chart
        .draw_series(segments(&line, TRAJECTORY.stroke_width(2)))
        .map_err(err(path))?;
    chart
        .draw_series(
            p.strobes
                .iter()
                .filter(|s| s.0 >= t0 && s.0 <= t1)
                .map(|s| Circle::new((s.0, deg(s.1)), 5, STROBE.filled())),
        )
        .map_err(err(path))?;
    root.present().map_err(err(path))?;
    Ok(())
}

/// The unit of a panel's angle axis: degrees, or turns for a rotation's many turns.
#[derive(Clone, Copy, PartialEq)]
enum Unit {
    Degrees,
    Turns,
}

impl Unit {
    fn for_span((lo, hi): (f64, f64)) -> Self {
        if hi - lo > axis::TURNS_ABOVE {
            Self::Turns
        } else {
            Self::Degrees
        }
    }

    /// An unwrapped angle (rad) in this unit: degrees moved by `shift`, or turns from θ = 0.
    fn of(self, rad: f64, shift: f64) -> f64 {
        match self {
            Self::Degrees => rad.to_degrees() + shift,
            Self::Turns => rad.to_degrees() / 360.0,
        }
    }

    /// A range of shifted degrees in this unit.
    fn range(self, (lo, hi): (f64, f64), shift: f64) -> (f64, f64) {
        (
            self.of((lo - shift).to_radians(), shift),
            self.of((hi - shift).to_radians(), shift),
        )
    }
}

/// A chart of angle (degrees or turns) against time on the left of `area`, its right strip left for
/// labels.
fn panel<'a, 'b>(
    area: &'a Area<'b>,
    path: &Path,
    caption: &str,
    (t0, t1): (f64, f64),
    (lo, hi): (f64, f64),
    angle: &str,
    unit: Unit,
) -> Result<Chart<'a, 'b>> {
    let (left, _) = area.split_horizontally(SIZE.0 - LABELS);
    let (ticks, name, sign) = match unit {
        Unit::Degrees => (axis::degree_ticks(lo, hi), "degrees", "°"),
        Unit::Turns => (axis::decimal_ticks(lo, hi), "turns from 0°, unwrapped", ""),
    };
    let digits = axis::decimals(&ticks);
    let y = Ticked::new(lo..hi, ticks);
    let mut chart = ChartBuilder::on(&left)
        .caption(caption, ("sans-serif", CAPTION_FONT))
        .margin(10)
        .margin_left(18)
        .x_label_area_size(56)
        .y_label_area_size(104)
        .build_cartesian_2d(t0..t1, y)
        .map_err(err(path))?;
    chart
        .configure_mesh()
        .x_desc("time t (s)")
        .y_desc(format!("{angle} ({name})"))
        .axis_desc_style(("sans-serif", AXIS_FONT))
        .label_style(("sans-serif", TICK_FONT))
        .y_label_formatter(&|v| format!("{v:.digits$}{sign}"))
        .x_labels(8)
        .light_line_style(WHITE)
        .bold_line_style(GRID)
        .draw()
        .map_err(err(path))?;
    // The chart keeps a borrow of `left`'s backend, which lives as long as `area`.
    Ok(chart)
}

/// The predicted equilibria at every turn inside the panel's range, stable solid and the
/// others dashed, labelled in the strip to the right.
fn equilibria(
    chart: &mut Chart,
    area: &Area,
    path: &Path,
    p: &PlotInput,
    (lo, hi): (f64, f64),
) -> Result<()> {
    let (t0, t1) = {
        let r = chart.x_range();
        (r.start, r.end)
    };
    let mut labels = Vec::new();
    for &(a, s) in &p.equilibria {
        let first = ((lo - a) / 360.0).ceil() as i64;
        let last = ((hi - a) / 360.0).floor() as i64;
        for n in first..=last {
            let y = a + 360.0 * n as f64;
            let (colour, name) = style_of(s);
            let ends = [(t0, y), (t1, y)];
            if s == Stability::Stable {
                chart
                    .draw_series(LineSeries::new(ends, colour.stroke_width(2)))
                    .map_err(err(path))?;
            } else {
                chart
                    .draw_series(DashedLineSeries::new(ends, 12, 8, colour.stroke_width(2)))
                    .map_err(err(path))?;
            }
            let py = chart.backend_coord(&(t1, y)).1;
            labels.push((py, format!("{name} {y:.1}°"), colour));
        }
    }
    // Labels at their lines' heights, pushed apart where lines are close.
    labels.sort_by_key(|l| l.0);
    let (_, right) = area.split_horizontally(SIZE.0 - LABELS);
    let top_px = right.get_pixel_range().1.start;
    let mut last = i32::MIN;
    for (py, text, colour) in labels {
        let y = (py - top_px - 11).max(last + 24);
        last = y;
        right
            .draw(&Text::new(
                text,
                (8, y),
                ("sans-serif", TEXT_FONT).into_font().color(&colour),
            ))
            .map_err(err(path))?;
    }
    Ok(())
}
