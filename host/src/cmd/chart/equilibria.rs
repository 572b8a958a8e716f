//! `kapitza chart equilibria`: the equilibrium angle φ0 against the drive angle θd, for several R.

use anyhow::{bail, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;
use std::io::Write;

use super::options::{drive_strengths, write_csv, Output, Range};
use crate::chart::draw::{self, pe, tint, Figure, SERIES};
use crate::chart::map::samples;
use crate::input::{self, GeometryArgs};
use kapitza_core::model::{equilibria, DriveAngle, Stability};

/// φ0 against θd for the R values given: every equilibrium of the averaged motion, stable
/// branches solid, unstable dashed, and the reachable side (within 90° of the drive) shaded.
///
/// Give R values (--r 1.2,1.75,2.5), or a pendulum and drive (--rod/--point with --amplitude
/// and --omega), which gives one R = A²ω²/(2gℓ).
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Drive strengths R, comma-separated.
    #[arg(
        long = "r",
        value_name = "R,…",
        value_delimiter = ',',
        default_value = "0.8,1.2,1.75,2.5",
        allow_hyphen_values = true
    )]
    pub r: Vec<f64>,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    /// Drive amplitude A (m). With --rod or --point.
    #[arg(allow_hyphen_values = true, long, value_name = "A", requires = "omega")]
    pub amplitude: Option<f64>,
    /// Drive angular frequency ω (rad/s). With --rod or --point.
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "W",
        requires = "amplitude"
    )]
    pub omega: Option<f64>,
    /// Gravity g (m/s²).
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "G",
        default_value_t = 9.81
    )]
    pub gravity: f64,
    /// Range of θd in degrees.
    #[arg(
        long,
        value_name = "FROM..TO",
        default_value = "0..180",
        allow_hyphen_values = true
    )]
    pub angle_range: Range,
    /// Samples of θd (both ends included).
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "N",
        default_value_t = 721
    )]
    pub samples: usize,
    #[command(flatten)]
    pub output: Output,
}

/// One equilibrium at one (R, θd).
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    pub r: f64,
    pub drive_angle_deg: f64,
    /// φ0 in (−180°, 180°].
    pub angle_deg: f64,
    pub stability: &'static str,
    pub within_90_of_drive: bool,
}

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct Report {
    pub r: Vec<f64>,
    pub equilibria: Vec<Point>,
}

fn label(s: Stability) -> &'static str {
    match s {
        Stability::Stable => "stable",
        Stability::Unstable => "unstable",
        Stability::Marginal => "marginal",
    }
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let dir = args.output.prepare()?;
    let rs = match input::drive_groups(&args.geometry, args.amplitude, args.omega, args.gravity)? {
        Some(g) => vec![g.r],
        None => drive_strengths(&args.r)?,
    };
    if !(2..=20_000).contains(&args.samples) {
        bail!(
            "--samples {} is out of range: expected 2..=20000",
            args.samples
        );
    }
    let thetas = samples(args.angle_range.from, args.angle_range.to, args.samples);
    let mut points = Vec::new();
    for &r in &rs {
        for &th in &thetas {
            for e in equilibria(r, DriveAngle::from_deg(th)?)?.as_slice() {
                points.push(Point {
                    r,
                    drive_angle_deg: th,
                    angle_deg: e.angle.to_degrees(),
                    stability: label(e.stability),
                    within_90_of_drive: e.within_90_of_drive,
                });
            }
        }
    }
    let report = Report {
        r: rs,
        equilibria: points,
    };
    let fig = EquilibriaFigure {
        report: &report,
        range: args.angle_range,
    };
    let mut files = draw::save(dir, "equilibria", &fig)?;
    files.push(write_csv(
        &dir.join("equilibria.csv"),
        "r,drive_angle_deg,angle_deg,stability,within_90_of_drive",
        report.equilibria.iter().map(|p| {
            format!(
                "{},{},{},{},{}",
                p.r, p.drive_angle_deg, p.angle_deg, p.stability, p.within_90_of_drive
            )
        }),
    )?);
    args.output.finish(&report, &files, out)
}

struct EquilibriaFigure<'a> {
    report: &'a Report,
    range: Range,
}

/// Branches: consecutive samples of one R joined where the angle moves by less than 8° and the
/// stability is the same.
fn branches(points: &[&Point]) -> Vec<(&'static str, Vec<(f64, f64)>)> {
    let mut open: Vec<(&'static str, Vec<(f64, f64)>)> = Vec::new();
    let mut done = Vec::new();
    let mut last_theta = f64::NAN;
    for p in points {
        if p.drive_angle_deg != last_theta {
            // Branches not continued at the previous sample are finished.
            let (keep, finished): (Vec<_>, Vec<_>) = open
                .into_iter()
                .partition(|(_, b)| b.last().is_some_and(|l| l.0 == last_theta));
            done.extend(finished);
            open = keep;
            last_theta = p.drive_angle_deg;
        }
        let next = (p.drive_angle_deg, p.angle_deg);
        let continued = open.iter_mut().find(|(s, b)| {
            *s == p.stability
                && b.last()
                    .is_some_and(|l| l.0 < p.drive_angle_deg && (l.1 - p.angle_deg).abs() < 8.0)
        });
        match continued {
            Some((_, b)) => b.push(next),
            None => open.push((p.stability, vec![next])),
        }
    }
    done.extend(open);
    done
}

impl Figure for EquilibriaFigure<'_> {
    fn title(&self) -> String {
        "Where the shaken pendulum comes to rest: φ0 against the drive angle θd".into()
    }
    fn subtitle(&self) -> String {
        "averaged motion: sin φ0 + (R/2) sin 2(φ0 − θd) = 0, stable where cos φ0 + R cos 2(φ0 − θd) > 0; angles from the downward vertical".into()
    }
    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let (x0, x1) = (self.range.from, self.range.to);
        let mut chart = ChartBuilder::on(area)
            .margin(20)
            .margin_right(40)
            .x_label_area_size(80)
            .y_label_area_size(110)
            .build_cartesian_2d(x0..x1, -180.0..180.0)
            .map_err(pe)?;
        chart
            .configure_mesh()
            .x_desc("drive angle θd (degrees)")
            .y_desc("equilibrium angle φ0 (degrees)")
            .axis_desc_style(("sans-serif", draw::AXIS_FONT))
            .label_style(("sans-serif", draw::TICK_FONT))
            .x_labels(13)
            .y_labels(9)
            .x_label_formatter(&|v| format!("{v:.0}°"))
            .y_label_formatter(&|v| format!("{v:.0}°"))
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(RGBColor(200, 200, 200).mix(0.6))
            .draw()
            .map_err(pe)?;
        // Reachable: |φ0 − θd| ≤ 90° (wrapped), a band along the diagonal.
        let reach = tint(SERIES[2], 0.18);
        let steps = 360;
        let mut cells = Vec::new();
        for i in 0..steps {
            let a = x0 + (x1 - x0) * i as f64 / steps as f64;
            let b = x0 + (x1 - x0) * (i + 1) as f64 / steps as f64;
            let mid = 0.5 * (a + b);
            for shift in [-360.0, 0.0, 360.0] {
                let lo = (mid - 90.0 + shift).max(-180.0);
                let hi = (mid + 90.0 + shift).min(180.0);
                if lo < hi {
                    cells.push(Rectangle::new([(a, lo), (b, hi)], reach.filled()));
                }
            }
        }
        chart
            .draw_series(cells)
            .map_err(pe)?
            .label("reachable: within 90° of the drive")
            .legend(move |(x, y)| Rectangle::new([(x, y - 8), (x + 24, y + 8)], reach.filled()));
        for (ri, &r) in self.report.r.iter().enumerate() {
            let colour = SERIES[ri % SERIES.len()];
            let pts: Vec<&Point> = self.report.equilibria.iter().filter(|p| p.r == r).collect();
            let mut labelled = false;
            for (stability, b) in branches(&pts) {
                if stability == "stable" {
                    let s = chart
                        .draw_series(LineSeries::new(b, colour.stroke_width(4)))
                        .map_err(pe)?;
                    if !labelled {
                        s.label(format!("R = {r}")).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(4))
                        });
                        labelled = true;
                    }
                } else {
                    chart
                        .draw_series(DashedLineSeries::new(b, 10, 7, colour.stroke_width(2)))
                        .map_err(pe)?;
                }
            }
        }
        let grey = RGBColor(90, 90, 90);
        chart
            .draw_series(DashedLineSeries::new(
                [(x0, x0.max(-180.0)), (x0, x0.max(-180.0))],
                10,
                7,
                grey.stroke_width(2),
            ))
            .map_err(pe)?
            .label("unstable (dashed)")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 10, y)], grey.stroke_width(2))
            });
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(120, 120, 120))
            .label_font(("sans-serif", draw::LEGEND_FONT))
            .draw()
            .map_err(pe)?;
        Ok(())
    }
}
