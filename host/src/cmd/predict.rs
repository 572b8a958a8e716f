//! `kapitza predict`: every equilibrium of the averaged motion, with its stability.

mod rest_angle;

use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::io::Write;

use crate::input::{self, GeometryArgs};
use kapitza_core::error::Compact;
use kapitza_core::math;
use kapitza_core::model::drive::{ANGLE_RANGE, MAX_ANGLE_DEG};
use kapitza_core::model::equilibria::saddle_node_r;
use kapitza_core::model::{equilibria, DriveAngle, Equilibrium, Groups, Stability};

/// Predict every equilibrium of the shaken pendulum (averaged motion) and its stability.
///
/// Give the drive strength R directly, or a pendulum and drive (--rod/--point with --amplitude and
/// --omega) from which R follows.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Drive strength R = A²ω²/(2gℓ) (>= 0).
    #[arg(long = "r", value_name = "R", allow_hyphen_values = true, required_unless_present_any = ["rod", "point", "rest_angle"], conflicts_with_all = ["rod", "point", "amplitude", "omega"])]
    pub r: Option<f64>,
    /// Drive angle θd in degrees from the downward vertical (0 shakes vertically, 90
    /// horizontally, 180 vertically along the upward direction).
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        required_unless_present = "rest_angle",
        conflicts_with = "rest_angle"
    )]
    pub angle: Option<f64>,
    /// Instead of --angle: the wanted rest angle φ0 (degrees). Prints every drive angle that
    /// puts a stable equilibrium within 90° of the drive there (at the R given, if any), and the
    /// range of R for which one exists — or says that none does.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub rest_angle: Option<f64>,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    /// Drive amplitude A (m): half the peak-to-peak stroke. With --rod or --point.
    #[arg(long, value_name = "A", requires = "omega", allow_hyphen_values = true)]
    pub amplitude: Option<f64>,
    /// Drive angular frequency ω (rad/s). With --rod or --point.
    #[arg(
        long,
        value_name = "W",
        requires = "amplitude",
        allow_hyphen_values = true
    )]
    pub omega: Option<f64>,
    /// Gravity g (m/s²).
    #[arg(
        long,
        value_name = "G",
        default_value_t = 9.81,
        allow_hyphen_values = true
    )]
    pub gravity: f64,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct Report {
    pub r: f64,
    pub drive_angle_deg: f64,
    /// R on the saddle-node curve at this θd: two equilibria below it, four above.
    pub saddle_node_r: f64,
    /// Present when a pendulum and drive were given.
    pub physical: Option<Physical>,
    pub equilibria: Vec<EquilibriumOut>,
}

#[derive(Debug, Serialize)]
pub struct Physical {
    pub equivalent_length: f64,
    pub omega0: f64,
    pub omega_c: f64,
    pub m: f64,
    pub k_abs: f64,
}

#[derive(Debug, Serialize)]
pub struct EquilibriumOut {
    /// In (−180°, 180°].
    pub angle_deg: f64,
    pub stability: &'static str,
    pub stable: bool,
    pub marginal: bool,
    /// cos φ0 + R cos 2(φ0 − θd): the curvature of the effective potential per m g z.
    pub margin: f64,
    pub omega_p_over_omega0: Option<f64>,
    /// ωp in rad/s when a pendulum was given.
    pub omega_p: Option<f64>,
    pub within_90_of_drive: bool,
}

impl EquilibriumOut {
    /// One equilibrium as reported; `omega0` (rad/s), when known, gives ωp in rad/s.
    pub fn new(e: &Equilibrium, omega0: Option<f64>) -> Self {
        Self {
            angle_deg: math::wrap_deg(math::to_deg(e.angle)),
            stability: match e.stability {
                Stability::Stable => "stable",
                Stability::Unstable => "unstable",
                Stability::Marginal => "marginal",
            },
            stable: e.stability == Stability::Stable,
            marginal: e.stability == Stability::Marginal,
            margin: e.margin,
            omega_p_over_omega0: e.omega_p_over_omega0,
            omega_p: e.omega_p_over_omega0.zip(omega0).map(|(x, w0)| x * w0),
            within_90_of_drive: e.within_90_of_drive,
        }
    }
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    if let Some(phi) = args.rest_angle {
        let phi = rest_angle::check(phi)?;
        let r = match args.r {
            Some(r) => Some(input::non_negative("--r", r)?),
            None => input::drive_groups(&args.geometry, args.amplitude, args.omega, args.gravity)?
                .map(|g| g.r),
        };
        let a = rest_angle::compute(phi, r)?;
        if args.json {
            serde_json::to_writer_pretty(&mut *out, &a)?;
            writeln!(out)?;
        } else {
            rest_angle::print(&a, out)?;
        }
        return Ok(());
    }
    let report = compute(args)?;
    if args.json {
        serde_json::to_writer_pretty(&mut *out, &report)?;
        writeln!(out)?;
    } else {
        print_table(&report, out)?;
    }
    Ok(())
}

pub fn compute(args: &Args) -> Result<Report> {
    let Some(angle) = args.angle else {
        bail!("give --angle DEG (or --rest-angle DEG)");
    };
    let angle_deg = input::finite("--angle", angle)?;
    if angle_deg.abs() > MAX_ANGLE_DEG {
        bail!(
            "--angle {} is out of range: expected {ANGLE_RANGE}",
            Compact(angle_deg)
        );
    }
    let theta_d = DriveAngle::from_deg(angle_deg)?;
    let gravity = input::positive("--gravity", args.gravity)?;
    let (r, physical) = match (args.r, args.geometry.geometry()?) {
        (Some(r), None) => (input::non_negative("--r", r)?, None),
        (None, Some(geometry)) => {
            let (Some(a), Some(w)) = (args.amplitude, args.omega) else {
                bail!("--rod/--point need --amplitude A (m) and --omega W (rad/s)");
            };
            let a = input::positive("--amplitude", a)?;
            let w = input::positive("--omega", w)?;
            let ell = geometry.equivalent_length();
            let g = Groups::new(ell, gravity, a, w, 0.0).context("pendulum and drive")?;
            let phys = Physical {
                equivalent_length: ell,
                omega0: g.omega0,
                omega_c: g.omega_c,
                m: g.m,
                k_abs: g.k_abs,
            };
            (g.r, Some(phys))
        }
        _ => bail!(
            "give either --r R or a pendulum (--rod L or --point l) with --amplitude and --omega"
        ),
    };
    let eqs = equilibria(r, theta_d)?;
    let omega0 = physical.as_ref().map(|p| p.omega0);
    let equilibria = eqs
        .as_slice()
        .map(|e| EquilibriumOut::new(e, omega0))
        .collect();
    Ok(Report {
        r,
        drive_angle_deg: angle_deg,
        saddle_node_r: saddle_node_r(theta_d),
        physical,
        equilibria,
    })
}

fn print_table(r: &Report, out: &mut dyn Write) -> Result<()> {
    if let Some(p) = &r.physical {
        writeln!(
            out,
            "pendulum: ℓ = {:.4} m, ω0 = {:.3} rad/s, ωc = {:.2} rad/s, m = A/ℓ = {:.4}",
            p.equivalent_length, p.omega0, p.omega_c, p.m
        )?;
    }
    let regime = if (r.r - r.saddle_node_r).abs() <= 1e-9 * (1.0 + r.r) {
        "on the curve, equilibria merge"
    } else if r.r > r.saddle_node_r {
        "four equilibria"
    } else {
        "two equilibria"
    };
    writeln!(
        out,
        "R = {:.4} at θd = {}°  (saddle-node R_sn = {:.4}: {regime})",
        r.r, r.drive_angle_deg, r.saddle_node_r
    )?;
    writeln!(
        out,
        "{:>10}  {:<9}  {:>7}  {:>10}  within 90° of drive",
        "angle", "stability", "ωp/ω0", "ωp (rad/s)"
    )?;
    for e in &r.equilibria {
        let wp = e
            .omega_p_over_omega0
            .map_or("—".into(), |x| format!("{x:.4}"));
        let wpa = e.omega_p.map_or("—".into(), |x| format!("{x:.3}"));
        let within = if e.within_90_of_drive { "yes" } else { "no" };
        writeln!(
            out,
            "{:>9.2}°  {:<9}  {wp:>7}  {wpa:>10}  {within}",
            e.angle_deg, e.stability
        )?;
    }
    Ok(())
}
