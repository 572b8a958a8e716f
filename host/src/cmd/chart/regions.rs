//! `kapitza chart regions`: the (θd, R) plane — how many equilibria, and where no reachable
//! stable one exists.

use anyhow::{bail, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;
use std::io::Write;

use super::options::{csv_num, drive_strengths, write_csv, Output, Range, Size};
use crate::chart::draw::{self, pe, tint, Figure, SERIES};
use crate::chart::map::samples;
use kapitza_core::model::equilibria::saddle_node_r;
use kapitza_core::model::{equilibria, DriveAngle};

/// The (θd, R) plane: the saddle-node curve R_sn(θd) with two equilibria below it and four
/// above, and the band of θd where no stable equilibrium lies within 90° of the drive
/// (unreachable on an apparatus whose actuator sits on one side of the pivot).
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// R values whose band of unreachable θd is reported (comma-separated); the band exists
    /// for 1 < R < 2.
    #[arg(
        long = "r",
        value_name = "R,…",
        value_delimiter = ',',
        default_value = "1.2,1.5,1.75,1.9",
        allow_hyphen_values = true
    )]
    pub r: Vec<f64>,
    /// Range of R drawn.
    #[arg(long, value_name = "FROM..TO", default_value = "0..3")]
    pub r_range: Range,
    /// Samples NxM of θd (0…180°) and R.
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "NxM",
        default_value = "361x301"
    )]
    pub size: Size,
    #[command(flatten)]
    pub output: Output,
}

/// The band of θd (degrees) with no reachable stable equilibrium at one R.
#[derive(Debug, Clone, Serialize)]
pub struct Band {
    pub r: f64,
    pub from_deg: Option<f64>,
    pub to_deg: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Cell {
    pub drive_angle_deg: f64,
    pub r: f64,
    pub equilibria: usize,
    pub reachable_stable: bool,
}

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct Report {
    pub bands: Vec<Band>,
    /// R_sn at each sampled θd.
    pub saddle_node: Vec<[f64; 2]>,
}

/// Whether some stable equilibrium lies within 90° of the drive at (R, θd).
pub fn reachable_stable(r: f64, theta_deg: f64) -> Result<bool> {
    Ok(equilibria(r, DriveAngle::from_deg(theta_deg)?)?
        .stable()
        .any(|e| e.within_90_of_drive))
}

/// The band at R by scanning θd ∈ [0°, 180°] in 0.25° steps and bisecting each end to 1e-10°.
/// None outside 1 < R < 2, where every θd has a reachable stable equilibrium (R ≥ 2, physics §4)
/// or the unreachable set runs up to 180° (R ≤ 1) and is not a band.
pub fn band(r: f64) -> Result<Band> {
    let none = Band {
        r,
        from_deg: None,
        to_deg: None,
    };
    if r <= 1.0 || r >= 2.0 {
        return Ok(none);
    }
    let refine = |mut reach: f64, mut not: f64| -> Result<f64> {
        while (reach - not).abs() > 1e-10 {
            let mid = 0.5 * (reach + not);
            if reachable_stable(r, mid)? {
                reach = mid;
            } else {
                not = mid;
            }
        }
        Ok(0.5 * (reach + not))
    };
    let mut from = None;
    let mut prev = (0.0, reachable_stable(r, 0.0)?);
    for i in 1..=720 {
        let th = 0.25 * f64::from(i);
        let now = reachable_stable(r, th)?;
        if prev.1 && !now && from.is_none() {
            from = Some(refine(prev.0, th)?);
        } else if !prev.1 && now {
            if let Some(f) = from {
                return Ok(Band {
                    r,
                    from_deg: Some(f),
                    to_deg: Some(refine(th, prev.0)?),
                });
            }
        }
        prev = (th, now);
    }
    Ok(none)
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let dir = args.output.prepare()?;
    let strengths = drive_strengths(&args.r)?;
    if args.r_range.from < 0.0 {
        bail!("--r-range must start at 0 or above");
    }
    let thetas = samples(0.0, 180.0, args.size.nx);
    let rs = samples(args.r_range.from, args.r_range.to, args.size.ny);
    let mut cells = Vec::new();
    for &th in &thetas {
        for &r in &rs {
            let eq = equilibria(r, DriveAngle::from_deg(th)?)?;
            cells.push(Cell {
                drive_angle_deg: th,
                r,
                equilibria: eq.len(),
                reachable_stable: eq.stable().any(|e| e.within_90_of_drive),
            });
        }
    }
    let bands = strengths
        .iter()
        .map(|&r| band(r))
        .collect::<Result<Vec<_>>>()?;
    let saddle_node = thetas
        .iter()
        .map(|&th| Ok([th, saddle_node_r(DriveAngle::from_deg(th)?)]))
        .collect::<Result<Vec<_>>>()?;
    let report = Report { bands, saddle_node };
    let fig = RegionsFigure {
        report: &report,
        cells: &cells,
        thetas: &thetas,
        rs: &rs,
    };
    let mut files = draw::save(dir, "regions", &fig)?;
    files.push(write_csv(
        &dir.join("regions.csv"),
        "drive_angle_deg,r,equilibria,reachable_stable",
        cells.iter().map(|c| {
            format!(
                "{},{},{},{}",
                c.drive_angle_deg, c.r, c.equilibria, c.reachable_stable
            )
        }),
    )?);
    files.push(write_csv(
        &dir.join("regions-bands.csv"),
        "r,from_deg,to_deg",
        report
            .bands
            .iter()
            .map(|b| format!("{},{},{}", b.r, csv_num(b.from_deg), csv_num(b.to_deg))),
    )?);
    args.output.finish(&report, &files, out)
}

/// The bands asked for: dark enough to read on the shading.
const BAND: RGBColor = RGBColor(130, 0, 0);

struct RegionsFigure<'a> {
    report: &'a Report,
    cells: &'a [Cell],
    thetas: &'a [f64],
    rs: &'a [f64],
}

impl Figure for RegionsFigure<'_> {
    fn title(&self) -> String {
        "How many equilibria, and which drive angles cannot tilt the rod (θd, R)".into()
    }
    fn subtitle(&self) -> String {
        "averaged motion; R = A²ω²/(2gℓ); reachable = within 90° of the drive direction".into()
    }
    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let (r0, r1) = (self.rs[0], *self.rs.last().unwrap_or(&3.0));
        let mut chart = ChartBuilder::on(area)
            .margin(20)
            .margin_right(40)
            .x_label_area_size(80)
            .y_label_area_size(110)
            .build_cartesian_2d(0.0..180.0, r0..r1)
            .map_err(pe)?;
        chart
            .configure_mesh()
            .x_desc("drive angle θd (degrees)")
            .y_desc("drive strength R")
            .axis_desc_style(("sans-serif", draw::AXIS_FONT))
            .label_style(("sans-serif", draw::TICK_FONT))
            .x_labels(13)
            .x_label_formatter(&|v| format!("{v:.0}°"))
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(RGBColor(200, 200, 200).mix(0.6))
            .draw()
            .map_err(pe)?;
        let (nx, ny) = (self.thetas.len(), self.rs.len());
        let hx = 0.5 * 180.0 / (nx - 1) as f64;
        let hy = 0.5 * (r1 - r0) / (ny - 1) as f64;
        let four = tint(SERIES[0], 0.25);
        let none = tint(SERIES[1], 0.55);
        let mut rects_four = Vec::new();
        let mut rects_none = Vec::new();
        for (i, &th) in self.thetas.iter().enumerate() {
            for kind in [0, 1] {
                let mut j = 0;
                while j < ny {
                    let c = &self.cells[i * ny + j];
                    let on = if kind == 0 {
                        c.equilibria == 4
                    } else {
                        !c.reachable_stable
                    };
                    if !on {
                        j += 1;
                        continue;
                    }
                    let start = j;
                    while j < ny && {
                        let c = &self.cells[i * ny + j];
                        if kind == 0 {
                            c.equilibria == 4
                        } else {
                            !c.reachable_stable
                        }
                    } {
                        j += 1;
                    }
                    let rect = [
                        ((th - hx).max(0.0), (self.rs[start] - hy).max(r0)),
                        ((th + hx).min(180.0), (self.rs[j - 1] + hy).min(r1)),
                    ];
                    if kind == 0 {
                        rects_four.push(Rectangle::new(rect, four.filled()));
                    } else {
                        rects_none.push(Rectangle::new(rect, none.filled()));
                    }
                }
            }
        }
        chart
            .draw_series(rects_four)
            .map_err(pe)?
            .label("four equilibria")
            .legend(move |(x, y)| Rectangle::new([(x, y - 8), (x + 24, y + 8)], four.filled()));
        chart
            .draw_series(rects_none)
            .map_err(pe)?
            .label(
                "no stable equilibrium within 90° of the drive (lines: the band at each R asked)",
            )
            .legend(move |(x, y)| Rectangle::new([(x, y - 8), (x + 24, y + 8)], none.filled()));
        let black = RGBColor(20, 20, 20);
        chart
            .draw_series(LineSeries::new(
                self.report
                    .saddle_node
                    .iter()
                    .map(|p| (p[0], p[1]))
                    .filter(|p| p.1 <= r1),
                black.stroke_width(3),
            ))
            .map_err(pe)?
            .label("saddle-node curve R_sn(θd): two equilibria below, four above")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], black.stroke_width(3))
            });
        for b in &self.report.bands {
            if let (Some(f), Some(t)) = (b.from_deg, b.to_deg) {
                chart
                    .draw_series(LineSeries::new([(f, b.r), (t, b.r)], BAND.stroke_width(3)))
                    .map_err(pe)?;
                chart
                    .draw_series([Text::new(
                        format!("R = {}: {f:.1}° … {t:.1}°", b.r),
                        // Below its line, inside the arch: above it the top band's label
                        // would cross the saddle-node curve.
                        (0.5 * (f + t) - 18.0, b.r - 0.035),
                        ("sans-serif", draw::LEGEND_FONT).into_font().color(&BAND),
                    )])
                    .map_err(pe)?;
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(120, 120, 120))
            .label_font(("sans-serif", draw::LEGEND_FONT))
            .draw()
            .map_err(pe)?;
        Ok(())
    }
}
