//! `kapitza chart stability`: the stability diagram of the linearised motion, in the (k, m)
//! plane or, for a given pendulum, in the (ω, A) plane.

use anyhow::{bail, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;
use std::io::Write;

use super::options::{csv_num, write_csv, Output, Point, Range, Size};
use crate::chart::draw::{self, pe, Figure, SERIES};
use crate::chart::map::{samples, stability_map, Damping, StabilityMap};
use crate::input::{self, GeometryArgs};
use kapitza_core::stability::{
    averaging, harmonic_balance, hill, mathieu, End, Window, K_MAX, M_MAX,
};

/// Subharmonic orders drawn (n = 2 is the flutter boundary).
const ORDERS: std::ops::RangeInclusive<u32> = 2..=8;
/// Tolerance on every boundary in m.
const TOL: f64 = 1e-9;

/// The stability diagram: where x'' + c x' + ω²(k − m cos ωt) x = 0 is stable.
///
/// Stable regions from the exact (Floquet) criterion, computed cell by cell from Hill's Sturm
/// counts, shaded; the averaging, Mathieu-series and harmonic-balance boundaries drawn over
/// them; the order-n subharmonic thresholds (n = 2…8); marked points. Signed k: < 0 about the
/// inverted position, > 0 about the hanging one. With a pendulum (--rod or --point) the plane
/// is drive frequency ω against amplitude A instead, with the operating point marked.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Range of signed k, FROM..TO (e.g. --k-range=-2.5..0.5).
    #[arg(
        long,
        value_name = "FROM..TO",
        default_value = "-1..1.5",
        allow_hyphen_values = true
    )]
    pub k_range: Range,
    /// Range of m = A/ℓ, FROM..TO (0 ≤ FROM).
    #[arg(
        long,
        value_name = "FROM..TO",
        default_value = "0..2.5",
        allow_hyphen_values = true
    )]
    pub m_range: Range,
    /// Samples NxM along x (k or ω) and y (m or A), both ends included.
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "NxM",
        default_value = "401x301"
    )]
    pub size: Size,
    /// Quality factor Q = ω0/c of the damping (δ = √|k|/Q); undamped without it.
    #[arg(long = "q", value_name = "Q", allow_hyphen_values = true)]
    pub quality: Option<f64>,
    /// Point(s) to mark, k,m (or ω,A in rad/s and metres with a pendulum). Repeatable.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true)]
    pub mark: Vec<Point>,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    /// With a pendulum: range of ω (rad/s).
    #[arg(long, value_name = "FROM..TO")]
    pub omega_range: Option<Range>,
    /// With a pendulum: range of A (m).
    #[arg(long, value_name = "FROM..TO")]
    pub amplitude_range: Option<Range>,
    /// With a pendulum: the operating point's ω (rad/s), marked.
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "W",
        requires = "amplitude"
    )]
    pub omega: Option<f64>,
    /// With a pendulum: the operating point's A (m), marked.
    #[arg(allow_hyphen_values = true, long, value_name = "A", requires = "omega")]
    pub amplitude: Option<f64>,
    /// Gravity g (m/s²).
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "G",
        default_value_t = 9.81
    )]
    pub gravity: f64,
    /// With a pendulum: the hanging position (k > 0) instead of the inverted one.
    #[arg(long)]
    pub hanging: bool,
    #[command(flatten)]
    pub output: Output,
}

/// One window's ends at one sampled k, from one criterion.
#[derive(Debug, Clone, Serialize)]
pub struct BoundaryRecord {
    pub k: f64,
    /// `averaging`, `mathieu`, `harmonic_balance` or `floquet`.
    pub criterion: &'static str,
    /// Stable windows at this k numbered from 0 upward in m.
    pub window: usize,
    pub lower_m: Option<f64>,
    pub upper_m: Option<f64>,
    pub lower_reason: Option<&'static str>,
    pub upper_reason: Option<&'static str>,
    /// With a pendulum: the drive frequency of this k (rad/s) and the ends as amplitudes (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lower_amplitude: Option<Option<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub upper_amplitude: Option<Option<f64>>,
}

/// One order-n threshold at one sampled k.
#[derive(Debug, Clone, Serialize)]
pub struct SubharmonicRecord {
    pub k: f64,
    /// `floquet` (undamped, Hill) or `harmonic_balance`.
    pub criterion: &'static str,
    pub order: u32,
    pub window: usize,
    pub m: Option<f64>,
    pub reason: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<Option<f64>>,
}

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct Report {
    pub plane: &'static str,
    pub quality: Option<f64>,
    pub k_samples: usize,
    pub m_samples: usize,
    /// With a pendulum: ℓ (m), g, and whether the inverted position is studied.
    pub equivalent_length: Option<f64>,
    pub boundaries: Vec<BoundaryRecord>,
    pub subharmonics: Vec<SubharmonicRecord>,
    pub stable_cells: usize,
    pub map_seconds: f64,
}

/// The axes: x samples and their k; y samples and their m.
struct Plane {
    xs: Vec<f64>,
    ks: Vec<f64>,
    ys: Vec<f64>,
    ms: Vec<f64>,
    /// A = m·ℓ with a pendulum.
    ell: Option<f64>,
    inverted: bool,
    omega0: f64,
}

fn plane(args: &Args) -> Result<Plane> {
    let Size { nx, ny } = args.size;
    if let Some(geometry) = args.geometry.geometry()? {
        let ell = geometry.equivalent_length();
        let g = input::positive("--gravity", args.gravity)?;
        let omega0 = (g / ell).sqrt();
        let w = args.omega_range.unwrap_or(Range {
            from: 3.0 * omega0,
            to: 30.0 * omega0,
        });
        let a = args.amplitude_range.unwrap_or(Range {
            from: 0.0,
            to: 0.1 * ell,
        });
        input::positive("--omega-range FROM", w.from)?;
        input::non_negative("--amplitude-range FROM", a.from)?;
        let xs = samples(w.from, w.to, nx);
        let sign = if args.hanging { 1.0 } else { -1.0 };
        let ks: Vec<f64> = xs.iter().map(|w| sign * (omega0 / w).powi(2)).collect();
        if ks.iter().any(|k| k.abs() > K_MAX) {
            bail!("--omega-range starts too low: (ω0/ω)² must stay <= {K_MAX} (ω0 = {omega0:.3} rad/s)");
        }
        let ys = samples(a.from, a.to, ny);
        let ms: Vec<f64> = ys.iter().map(|a| a / ell).collect();
        if ms.iter().any(|m| *m > M_MAX) {
            bail!("--amplitude-range reaches A/ℓ > {M_MAX}");
        }
        return Ok(Plane {
            xs,
            ks,
            ys,
            ms,
            ell: Some(ell),
            inverted: !args.hanging,
            omega0,
        });
    }
    let (k, m) = (args.k_range, args.m_range);
    if k.from < -K_MAX || k.to > K_MAX {
        bail!(
            "--k-range {}..{} is out of range: expected within -{K_MAX}..{K_MAX}",
            k.from,
            k.to
        );
    }
    if m.from < 0.0 || m.to > M_MAX {
        bail!(
            "--m-range {}..{} is out of range: expected within 0..{M_MAX}",
            m.from,
            m.to
        );
    }
    let xs = samples(k.from, k.to, nx);
    let ys = samples(m.from, m.to, ny);
    Ok(Plane {
        ks: xs.clone(),
        xs,
        ms: ys.clone(),
        ys,
        ell: None,
        inverted: true,
        omega0: 0.0,
    })
}

fn reason(e: End) -> Option<&'static str> {
    match e {
        End::Value(_) => None,
        End::Missing(w) => Some(w),
    }
}

/// The boundary records of every criterion at every sampled k.
fn boundaries(p: &Plane, damping: Damping) -> Result<Vec<BoundaryRecord>> {
    let m_top = p.ms.last().copied().unwrap_or(1.0).max(1e-6);
    let mut out = Vec::new();
    for (i, &k) in p.ks.iter().enumerate() {
        let omega = p.ell.map(|_| p.xs[i]);
        let mut push = |criterion, window, w: Window| {
            out.push(BoundaryRecord {
                k,
                criterion,
                window,
                lower_m: w.lower.value(),
                upper_m: w.upper.value(),
                lower_reason: reason(w.lower),
                upper_reason: reason(w.upper),
                omega,
                lower_amplitude: p.ell.map(|l| w.lower.value().map(|m| m * l)),
                upper_amplitude: p.ell.map(|l| w.upper.value().map(|m| m * l)),
            });
        };
        push("averaging", 0, averaging::window(k)?);
        push("mathieu", 0, mathieu::window(k)?);
        push("harmonic_balance", 0, harmonic_balance::window(k)?);
        let delta = damping.delta(k);
        if delta > 0.0 {
            let d = hill::damped_window(k, delta, TOL, hill::DEFAULT_HALF_STEPS)?;
            push("floquet", 0, d.window);
            continue;
        }
        for (j, w) in floquet_windows(k, m_top)?.into_iter().enumerate() {
            push("floquet", j, w);
        }
    }
    Ok(out)
}

/// Every undamped window at k for m in [0, m_top]; the first from `hill::first_window` (the
/// same ends `kapitza boundary` reports), the others from the walk.
fn floquet_windows(k: f64, m_top: f64) -> Result<Vec<Window>> {
    let (first, _, _) = hill::first_window(k, M_MAX, TOL)?;
    let mut out = vec![first];
    let Some(u0) = first.upper.value() else {
        return Ok(out);
    };
    let mut lower = None;
    for t in hill::Windows::new(k, m_top, TOL)? {
        if t.m <= u0 + 1e-6 {
            continue;
        }
        if !t.stable_before() && t.stable_after() {
            lower = Some(t.m);
        } else if let (Some(l), true) = (lower, t.stable_before() && !t.stable_after()) {
            out.push(Window {
                lower: End::Value(l),
                upper: End::Value(t.m),
                note: None,
            });
            lower = None;
        }
    }
    if let Some(l) = lower {
        out.push(Window {
            lower: End::Value(l),
            upper: End::Missing(hill::windows::STABLE_TO_LIMIT),
            note: None,
        });
    }
    Ok(out)
}

fn subharmonics(p: &Plane) -> Result<Vec<SubharmonicRecord>> {
    let mut out = Vec::new();
    for (i, &k) in p.ks.iter().enumerate() {
        for n in ORDERS {
            for (criterion, e) in [
                ("floquet", hill::subharmonic_m(k, n, TOL)?),
                ("harmonic_balance", harmonic_balance::subharmonic_m(k, n)?),
            ] {
                out.push(SubharmonicRecord {
                    k,
                    criterion,
                    order: n,
                    window: 0,
                    m: e.value(),
                    reason: reason(e),
                    omega: p.ell.map(|_| p.xs[i]),
                    amplitude: p.ell.map(|l| e.value().map(|m| m * l)),
                });
            }
        }
    }
    Ok(out)
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let dir = args.output.prepare()?;
    let damping = match args.quality {
        Some(q) => Damping::Quality(input::positive("--q", q)?),
        None => Damping::None,
    };
    let p = plane(args)?;
    if let (Damping::Quality(q), Some(k_max)) =
        (damping, p.ks.iter().map(|k| k.abs()).reduce(f64::max))
    {
        crate::input::quality_for("--q", q, k_max)?;
    }
    if let (Some(w), Some(a)) = (args.omega, args.amplitude) {
        input::positive("--omega", w)?;
        input::non_negative("--amplitude", a)?;
    }
    let t = std::time::Instant::now();
    let map = stability_map(&p.ks, &p.ms, damping)?;
    let map_seconds = t.elapsed().as_secs_f64();
    let report = Report {
        plane: if p.ell.is_some() {
            "omega_amplitude"
        } else {
            "k_m"
        },
        quality: args.quality,
        k_samples: p.ks.len(),
        m_samples: p.ms.len(),
        equivalent_length: p.ell,
        boundaries: boundaries(&p, damping)?,
        subharmonics: subharmonics(&p)?,
        stable_cells: map.stable.iter().flatten().filter(|&&s| s).count(),
        map_seconds,
    };
    let mut marks: Vec<(f64, f64, String)> = args
        .mark
        .iter()
        .map(|q| (q.x, scale_y(&p, q.y), format!("({}, {})", q.x, q.y)))
        .collect();
    if let (Some(w), Some(a)) = (args.omega, args.amplitude) {
        marks.push((
            w,
            scale_y(&p, a / p.ell.unwrap_or(1.0)),
            "operating point".into(),
        ));
    }
    let fig = StabilityFigure {
        p: &p,
        map: &map,
        report: &report,
        quality: args.quality,
        marks,
    };
    let mut files = draw::save(dir, "stability", &fig)?;
    files.push(write_csv(
        &dir.join("stability-map.csv"),
        "k,m,stable",
        map.ks.iter().enumerate().flat_map(|(i, k)| {
            let (ms, stable) = (&map.ms, &map.stable);
            ms.iter()
                .enumerate()
                .map(move |(j, m)| format!("{k},{m},{}", stable[i][j]))
        }),
    )?);
    files.push(write_csv(
        &dir.join("stability-boundaries.csv"),
        "k,criterion,window,lower_m,upper_m",
        report.boundaries.iter().map(|b| {
            format!(
                "{},{},{},{},{}",
                b.k,
                b.criterion,
                b.window,
                csv_num(b.lower_m),
                csv_num(b.upper_m)
            )
        }),
    )?);
    files.push(write_csv(
        &dir.join("stability-subharmonics.csv"),
        "k,criterion,order,m",
        report
            .subharmonics
            .iter()
            .map(|s| format!("{},{},{},{}", s.k, s.criterion, s.order, csv_num(s.m))),
    )?);
    if !args.output.json {
        writeln!(
            out,
            "{}×{} map in {:.3} s ({} stable cells)",
            p.ks.len(),
            p.ms.len(),
            map_seconds,
            report.stable_cells
        )?;
    }
    args.output.finish(&report, &files, out)
}

/// m → the y axis' unit (m, or A in mm with a pendulum).
fn scale_y(p: &Plane, m: f64) -> f64 {
    p.ell.map_or(m, |l| m * l * 1e3)
}

struct StabilityFigure<'a> {
    p: &'a Plane,
    map: &'a StabilityMap,
    report: &'a Report,
    quality: Option<f64>,
    marks: Vec<(f64, f64, String)>,
}

const STABLE_FILL: RGBColor = RGBColor(190, 220, 245);

impl Figure for StabilityFigure<'_> {
    fn title(&self) -> String {
        match self.p.ell {
            None => "Where the shaken pendulum is stable: the (k, m) plane".into(),
            Some(l) => {
                format!(
                "Where the {} position is stable: drive frequency against amplitude (ℓ = {:.3} m)",
                if self.p.inverted { "inverted" } else { "hanging" },
                l
            )
            }
        }
    }

    fn subtitle(&self) -> String {
        let damping = self
            .quality
            .map_or("undamped".to_string(), |q| format!("damped, Q = {q}"));
        match self.p.ell {
            None => format!(
                "x'' + c x' + ω²(k − m cos ωt) x = 0, {damping}; k < 0: inverted, k > 0: hanging; m = A/ℓ, |k| = (ω0/ω)²"
            ),
            Some(_) => format!(
                "linearised about the {} position, {damping}; ω0 = {:.2} rad/s",
                if self.p.inverted { "inverted" } else { "hanging" },
                self.p.omega0
            ),
        }
    }

    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let p = self.p;
        let (x0, x1) = (p.xs[0], *p.xs.last().unwrap_or(&1.0));
        let (y0, y1) = (
            scale_y(p, p.ms[0]),
            scale_y(p, *p.ms.last().unwrap_or(&1.0)),
        );
        let mut chart = ChartBuilder::on(area)
            .margin(20)
            .margin_right(40)
            .x_label_area_size(80)
            .y_label_area_size(110)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(pe)?;
        let (xd, yd) = match p.ell {
            None => ("signed k = ±(ω0/ω)²", "m = A/ℓ"),
            Some(_) => ("drive frequency ω (rad/s)", "amplitude A (mm)"),
        };
        chart
            .configure_mesh()
            .x_desc(xd)
            .y_desc(yd)
            .axis_desc_style(("sans-serif", draw::AXIS_FONT))
            .label_style(("sans-serif", draw::TICK_FONT))
            .x_label_formatter(&|v| {
                if p.ell.is_some() {
                    format!("{v:.0}")
                } else {
                    format!("{v:.1}")
                }
            })
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(RGBColor(200, 200, 200).mix(0.6))
            .draw()
            .map_err(pe)?;
        // Stable cells, merged into runs along y so the SVG stays small.
        let (nx, ny) = (p.xs.len(), p.ys.len());
        let half_x = 0.5 * (x1 - x0) / (nx - 1) as f64;
        let half_y = 0.5 * (y1 - y0) / (ny - 1) as f64;
        let mut rects = Vec::new();
        for i in 0..nx {
            let mut j = 0;
            while j < ny {
                if !self.map.stable[i][j] {
                    j += 1;
                    continue;
                }
                let start = j;
                while j < ny && self.map.stable[i][j] {
                    j += 1;
                }
                let xa = (p.xs[i] - half_x).max(x0);
                let xb = (p.xs[i] + half_x).min(x1);
                let ya = (scale_y(p, p.ms[start]) - half_y).max(y0);
                let yb = (scale_y(p, p.ms[j - 1]) + half_y).min(y1);
                rects.push(Rectangle::new([(xa, ya), (xb, yb)], STABLE_FILL.filled()));
            }
        }
        chart
            .draw_series(rects)
            .map_err(pe)?
            .label("stable (Floquet, exact)")
            .legend(|(x, y)| Rectangle::new([(x, y - 8), (x + 24, y + 8)], STABLE_FILL.filled()));
        // Criteria's ends as curves: consecutive samples joined unless an end is missing.
        let styles: [(&str, &str, RGBColor, u32); 4] = [
            ("floquet", "Floquet window ends", RGBColor(20, 20, 20), 2),
            ("averaging", "averaging: m = √(−2k)", SERIES[1], 3),
            ("mathieu", "Mathieu series", SERIES[2], 3),
            ("harmonic_balance", "harmonic balance", SERIES[3], 3),
        ];
        for (name, label, colour, width) in styles {
            let mut first = true;
            let max_window = self
                .report
                .boundaries
                .iter()
                .filter(|b| b.criterion == name)
                .map(|b| b.window)
                .max()
                .unwrap_or(0);
            for window in 0..=max_window {
                for upper in [false, true] {
                    let pts: Vec<(usize, Option<f64>)> = self
                        .report
                        .boundaries
                        .iter()
                        .filter(|b| b.criterion == name && b.window == window)
                        .map(|b| {
                            let i = p.ks.iter().position(|&k| k == b.k).unwrap_or(0);
                            let m = if upper { b.upper_m } else { b.lower_m };
                            // m = 0 ends of the hanging windows are the axis, not a boundary.
                            (i, m.filter(|&m| m > 0.0).map(|m| scale_y(p, m)))
                        })
                        .collect();
                    for run in runs(&pts, &p.xs, (y0, y1)) {
                        let s = chart
                            .draw_series(LineSeries::new(run, colour.stroke_width(width)))
                            .map_err(pe)?;
                        if first {
                            s.label(label).legend(move |(x, y)| {
                                PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
                            });
                            first = false;
                        }
                    }
                }
            }
        }
        // Subharmonic thresholds (Floquet, undamped), thin dashed.
        let grey = RGBColor(110, 110, 110);
        let mut first = true;
        for n in ORDERS {
            let pts: Vec<(usize, Option<f64>)> = self
                .report
                .subharmonics
                .iter()
                // Drawn below the first tongue (k < 1/4), where they fan out inside the first
                // window; the data has them at every k.
                .filter(|s| s.criterion == "floquet" && s.order == n && s.k < 0.25)
                .map(|s| {
                    let i = p.ks.iter().position(|&k| k == s.k).unwrap_or(0);
                    (i, s.m.map(|m| scale_y(p, m)))
                })
                .collect();
            for run in runs(&pts, &p.xs, (y0, y1)) {
                let s = chart
                    .draw_series(DashedLineSeries::new(run, 6, 5, grey.stroke_width(1)))
                    .map_err(pe)?;
                if first {
                    s.label("order-n subharmonic thresholds, n = 2…8")
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(1))
                        });
                    first = false;
                }
            }
        }
        for (x, y, text) in &self.marks {
            chart
                .draw_series([Cross::new((*x, *y), 10, RED.stroke_width(4))])
                .map_err(pe)?;
            chart
                .draw_series([Text::new(
                    format!("  {text}"),
                    (*x, *y),
                    ("sans-serif", draw::LEGEND_FONT).into_font().color(&RED),
                )])
                .map_err(pe)?;
        }
        // The legend sits in the middle at the top, above the inverted wedge and left of the
        // hanging tongues in the default ranges.
        // With a pendulum the unstable low-amplitude corner is free.
        let (left, _) = chart.plotting_area().get_pixel_range();
        let (px, _) = chart.backend_coord(&(x0 + 0.27 * (x1 - x0), y1));
        let position = match p.ell {
            None => SeriesLabelPosition::Coordinate(px - left.start, 10),
            Some(_) => SeriesLabelPosition::LowerLeft,
        };
        chart
            .configure_series_labels()
            .position(position)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(120, 120, 120))
            .label_font(("sans-serif", draw::LEGEND_FONT))
            .draw()
            .map_err(pe)?;
        Ok(())
    }
}

/// Splits samples (index into xs, y or none) into unbroken runs: a gap where y is missing, off
/// the axis, or jumps by more than a tenth of the axis.
fn runs(pts: &[(usize, Option<f64>)], xs: &[f64], axis: (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let span = axis.1 - axis.0;
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut last: Option<f64> = None;
    for &(i, y) in pts {
        let y = y.filter(|y| (axis.0..=axis.1).contains(y));
        match (y, last) {
            (Some(y), Some(l)) if (y - l).abs() < 0.1 * span => {
                out.last_mut().expect("a run").push((xs[i], y));
            }
            (Some(y), _) => out.push(vec![(xs[i], y)]),
            (None, _) => {}
        }
        last = y;
    }
    out
}
