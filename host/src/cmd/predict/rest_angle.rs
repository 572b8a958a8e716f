//! `kapitza predict --rest-angle DEG`: which drive angles put a stable, reachable equilibrium
//! at a wanted angle φ0, and for which R.
//!
//! The equilibrium condition solved for the drive angle (physics §3), with x = φ0 − θd:
//!
//! ```text
//! sin φ0 + (R/2) sin 2x = 0      ⇒  sin 2x = −2 sin φ0 / R      (|·| ≤ 1: R ≥ 2|sin φ0|)
//! stable     cos φ0 + R cos 2x > 0
//! reachable  |x| ≤ 90°
//! ```
//!
//! At a given R there are up to four x (two values of 2x, each with x and x + 180°); without R,
//! R = −2 sin φ0 / sin 2x over the reachable x ∈ [−90°, 90°] gives the range of R.

use anyhow::{bail, Result};
use serde::Serialize;
use std::io::Write;

use kapitza_core::math;
use kapitza_core::model::{equilibria, DriveAngle};

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct RestAngle {
    pub rest_angle_deg: f64,
    /// R as given (or from the pendulum), else null.
    pub r: Option<f64>,
    /// At that R: every θd in (−180°, 180°] with a stable equilibrium at φ0 within 90° of it.
    pub drive_angles_deg: Vec<f64>,
    /// The R for which some θd works: from `r_min` up to `r_max` (null: no upper limit).
    pub r_min: Option<f64>,
    pub r_max: Option<f64>,
    /// Why there is no answer, if there is none.
    pub reason: Option<String>,
}

/// Whether (R, θd) has a stable equilibrium at φ0 (degrees) within 90° of the drive, checked by
/// the model's own root finder (independent of the inversion above).
fn confirmed(r: f64, theta_deg: f64, phi_deg: f64) -> Result<bool> {
    Ok(equilibria(r, DriveAngle::from_deg(theta_deg)?)?
        .stable()
        .any(|e| {
            e.within_90_of_drive && math::wrap_deg(e.angle.to_degrees() - phi_deg).abs() < 1e-6
        }))
}

pub fn compute(phi_deg: f64, r: Option<f64>) -> Result<RestAngle> {
    let phi = math::to_rad(phi_deg);
    let (s, c) = (phi.sin(), phi.cos());
    // Over the reachable x, R(x) = −2 sin φ0 / sin 2x where positive and stable.
    if s.abs() < 1e-12 {
        bail!(
            "--rest-angle {phi_deg}: rests on the vertical need no search: hanging (0°) at θd = 0 \
             for any R, inverted (180°) at θd = 180° for R > 1 (`predict --angle`)"
        );
    }
    let mut r_min = f64::INFINITY;
    let mut r_hi: f64 = 0.0;
    let mut unbounded = false;
    let n = 200_000;
    for i in 1..n {
        let x = -0.5 * math::PI + math::PI * f64::from(i) / f64::from(n);
        let r_x = -2.0 * s / (2.0 * x).sin();
        if r_x > 0.0 && r_x.is_finite() && c + r_x * (2.0 * x).cos() > 0.0 {
            r_min = r_min.min(r_x);
            r_hi = r_hi.max(r_x);
            unbounded |= x.abs() < 1e-4;
        }
    }
    let (r_min, r_max) = if r_min.is_finite() {
        (Some(r_min), if unbounded { None } else { Some(r_hi) })
    } else {
        (None, None)
    };
    let mut drive_angles_deg = Vec::new();
    if let Some(r) = r {
        let sin2x = -2.0 * s / r;
        if sin2x.abs() <= 1.0 {
            let a = sin2x.asin();
            for two_x in [a, math::PI - a] {
                for x in [0.5 * two_x, 0.5 * two_x + math::PI] {
                    let theta = math::wrap_deg(phi_deg - x.to_degrees());
                    if confirmed(r, theta, phi_deg)?
                        && !drive_angles_deg
                            .iter()
                            .any(|t: &f64| (t - theta).abs() < 1e-9)
                    {
                        drive_angles_deg.push(theta);
                    }
                }
            }
        }
        drive_angles_deg.sort_by(f64::total_cmp);
    }
    let reason = match (r, drive_angles_deg.is_empty(), r_min) {
        (_, _, None) => Some(format!(
            "no R and θd give a stable, reachable rest at {phi_deg}°"
        )),
        (Some(r), true, Some(lo)) => Some(format!(
            "at R = {r} no drive angle does; R must be at least {lo:.4}"
        )),
        _ => None,
    };
    Ok(RestAngle {
        rest_angle_deg: phi_deg,
        r,
        drive_angles_deg,
        r_min,
        r_max,
        reason,
    })
}

pub fn print(a: &RestAngle, out: &mut dyn Write) -> Result<()> {
    match (a.r_min, a.r_max) {
        (Some(lo), None) => writeln!(
            out,
            "a stable, reachable rest at {}° needs R ≥ {lo:.4}",
            a.rest_angle_deg
        )?,
        (Some(lo), Some(hi)) => writeln!(
            out,
            "a stable, reachable rest at {}° needs {lo:.4} ≤ R ≤ {hi:.4}",
            a.rest_angle_deg
        )?,
        _ => {}
    }
    if let Some(r) = a.r {
        for t in &a.drive_angles_deg {
            writeln!(out, "at R = {r}: drive angle θd = {t:.3}°")?;
        }
    }
    if let Some(why) = &a.reason {
        writeln!(out, "{why}")?;
    }
    Ok(())
}

/// Checks the wanted angle.
pub fn check(phi_deg: f64) -> Result<f64> {
    if !phi_deg.is_finite() {
        bail!("--rest-angle {phi_deg} is out of range: expected a finite angle in degrees");
    }
    Ok(math::wrap_deg(phi_deg))
}
