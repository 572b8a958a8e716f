//! `phase.png`: two phase portraits (rate against angle). Left, the whole run: the slow motion
//! (each drive period's mean angle and mean rate) and the strobes. Right, the end window's
//! trajectory at full resolution with its strobes. Angles are unwrapped and shifted as in
//! `angle.png`; a panel whose angles span more than a turn (a rotation, tumbling) wraps them
//! into the turn centred on where the run ends.

use anyhow::Result;
use plotters::prelude::*;
use std::path::Path;

use super::ticked::Ticked;

use super::{
    axis, err, header, segments, Area, PlotInput, Sample, AXIS_FONT, CAPTION_FONT, GRID, HEADER,
    SIZE, SLOW, STROBE, TICK_FONT, TRAJECTORY,
};

/// Narrowest rate range drawn (rad/s): a rest's rounding noise is not blown up to fill a panel.
const MIN_RATE_SPAN: f64 = 0.05;

/// One panel's points, in degrees (shifted) and rad/s.
struct Portrait {
    /// Drawn as a line (broken where it wraps) in this colour.
    line: (Vec<(f64, f64)>, RGBColor),
    /// Drawn as dots of this radius.
    dots: (Vec<(f64, f64)>, u32),
}

pub fn phase_png(path: &Path, p: &PlotInput) -> Result<()> {
    super::register()?;
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err(path))?;
    let (top, body) = root.split_vertically(HEADER);
    let (angle, rate) = p.names();
    header(
        &top,
        p.title,
        &p.subtitle,
        &[
            (Sample::Line(SLOW), "slow motion: period means".into()),
            (Sample::Dot(STROBE), "strobes (drive phase 2πk)".into()),
            (
                Sample::Line(TRAJECTORY),
                format!("trajectory ({angle}, {rate})"),
            ),
        ],
    )?;
    let shift = p.shift();
    let deg = |rad: f64| rad.to_degrees() + shift;
    let centre = {
        let n = p.window.len().max(1) as f64;
        p.window.iter().map(|s| deg(s[1])).sum::<f64>() / n
    };
    let (left, right) = body.split_horizontally(SIZE.0 / 2);

    let slow = p.slow();
    let strobes = p.last_strobes();
    let whole = Portrait {
        line: (slow.iter().map(|b| (deg(b.mean), b.rate)).collect(), SLOW),
        dots: (strobes.iter().map(|s| (deg(s.1), s.2)).collect(), 3),
    };
    let periods = slow.iter().map(|b| b.periods).sum::<u64>();
    let caption = format!("the whole run ({periods} drive periods)");
    draw(&left, path, &caption, whole, centre, (angle, rate))?;

    let (t0, t1) = match (p.window.first(), p.window.last()) {
        (Some(a), Some(b)) => (a[0], b[0]),
        _ => (0.0, 0.0),
    };
    let end = Portrait {
        line: (
            p.window.iter().map(|s| (deg(s[1]), s[2])).collect(),
            TRAJECTORY,
        ),
        dots: (
            strobes
                .iter()
                .filter(|s| s.0 >= t0 && s.0 <= t1)
                .map(|s| (deg(s.1), s.2))
                .collect(),
            6,
        ),
    };
    let caption = format!(
        "the last {} drive periods at full resolution",
        p.window_periods()
    );
    draw(&right, path, &caption, end, centre, (angle, rate))?;
    root.present().map_err(err(path))?;
    Ok(())
}

fn draw(
    area: &Area,
    path: &Path,
    caption: &str,
    mut portrait: Portrait,
    centre: f64,
    (angle, rate): (&str, &str),
) -> Result<()> {
    let xs: Vec<f64> = portrait
        .line
        .0
        .iter()
        .chain(&portrait.dots.0)
        .map(|q| q.0)
        .collect();
    let cut = axis::phase_cut(xs.iter().copied(), centre);
    if let Some(cut) = cut {
        for q in portrait.line.0.iter_mut().chain(&mut portrait.dots.0) {
            q.0 = axis::wrap_from(q.0, cut);
        }
    }
    let (x0, x1) = match cut {
        Some(c) => (c, c + 360.0),
        None => axis::padded(xs.into_iter(), 4.0),
    };
    let ys = portrait.line.0.iter().chain(&portrait.dots.0).map(|q| q.1);
    let (y0, y1) = axis::padded(ys, MIN_RATE_SPAN);
    let ticks = axis::degree_ticks(x0, x1);
    let digits = axis::decimals(&ticks);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", CAPTION_FONT))
        .margin(10)
        .margin_left(18)
        .margin_right(28)
        .x_label_area_size(56)
        .y_label_area_size(96)
        .build_cartesian_2d(Ticked::new(x0..x1, ticks), y0..y1)
        .map_err(err(path))?;
    chart
        .configure_mesh()
        .x_desc(format!("{angle} (degrees)"))
        .y_desc(format!("{rate} (rad/s)"))
        .axis_desc_style(("sans-serif", AXIS_FONT))
        .label_style(("sans-serif", TICK_FONT))
        .x_label_formatter(&|v| format!("{v:.digits$}°"))
        .light_line_style(WHITE)
        .bold_line_style(GRID)
        .draw()
        .map_err(err(path))?;
    let (line, colour) = portrait.line;
    if cut.is_some() && colour == SLOW {
        // Period means a turn or more apart: dots, as a line between them would cross the panel.
        chart
            .draw_series(line.into_iter().map(|q| Circle::new(q, 2, SLOW.filled())))
            .map_err(err(path))?;
    } else {
        for run in axis::unbroken(line.into_iter()) {
            chart
                .draw_series(segments(&run, colour.stroke_width(2)))
                .map_err(err(path))?;
        }
    }
    let (dots, r) = portrait.dots;
    chart
        .draw_series(dots.into_iter().map(|q| Circle::new(q, r, STROBE.filled())))
        .map_err(err(path))?;
    Ok(())
}
