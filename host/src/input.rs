//! Checks of command-line numbers, with messages that name the flag and the allowed range.
//!
//! The core checks its inputs too; checking here first lets the message speak in the user's
//! terms (`--rod`, degrees) rather than the core's.

use anyhow::{bail, Result};
use clap::Args;
use kapitza_core::error::{Compact, Range};
use kapitza_core::model::{Geometry, Groups};
use kapitza_core::stability::DELTA_MAX;

/// `v` if `range` admits it, else an error naming the flag.
fn in_range(flag: &str, v: f64, range: Range) -> Result<f64> {
    if range.admits(v) {
        Ok(v)
    } else {
        bail!("{flag} {v} is out of range: expected {}", range.allowed())
    }
}

pub fn positive(flag: &str, v: f64) -> Result<f64> {
    in_range(flag, v, Range::Positive)
}

pub fn non_negative(flag: &str, v: f64) -> Result<f64> {
    in_range(flag, v, Range::NonNegative)
}

pub fn finite(flag: &str, v: f64) -> Result<f64> {
    in_range(flag, v, Range::Finite)
}

/// `q` (given with `flag`) if the damping per radian of drive it gives at |k| = `k_abs`,
/// δ = √|k|/Q, stays within the criteria's range ([`DELTA_MAX`]): refused in terms of Q.
pub fn quality_for(flag: &str, q: f64, k_abs: f64) -> Result<f64> {
    let q = positive(flag, q)?;
    if k_abs.sqrt() / q > DELTA_MAX {
        // Rounded up to 3 significant digits, so the limit printed is itself accepted.
        let min = k_abs.sqrt() / DELTA_MAX;
        let scale = 10f64.powi(min.log10().floor() as i32 - 2);
        bail!(
            "{flag} {} is out of range: expected at least {} here (damping past δ = √|k|/Q = \
             {DELTA_MAX} per radian of drive is beyond what the criteria compute)",
            Compact(q),
            Compact((min / scale).ceil() * scale)
        );
    }
    Ok(q)
}

/// The pendulum, given as a uniform rod or a point mass on a light rod.
#[derive(Debug, Clone, Args)]
#[group(multiple = false)]
pub struct GeometryArgs {
    /// Uniform rod of length L (m), pivoted at one end: ℓ = 2L/3.
    #[arg(long, value_name = "L", allow_hyphen_values = true)]
    pub rod: Option<f64>,
    /// Point mass on a light rod of length l (m): ℓ = l.
    #[arg(long, value_name = "l", allow_hyphen_values = true)]
    pub point: Option<f64>,
}

impl GeometryArgs {
    pub fn is_given(&self) -> bool {
        self.rod.is_some() || self.point.is_some()
    }

    /// The geometry, if one was given, checked.
    pub fn geometry(&self) -> Result<Option<Geometry>> {
        Ok(match (self.rod, self.point) {
            (Some(l), _) => Some(Geometry::rod(positive("--rod", l)?)?),
            (_, Some(l)) => Some(Geometry::point_mass(positive("--point", l)?)?),
            _ => None,
        })
    }
}

/// The groups of the pendulum given by `geometry` under the drive (`--amplitude`, `--omega`),
/// undamped; `None` without a pendulum.
pub fn drive_groups(
    geometry: &GeometryArgs,
    amplitude: Option<f64>,
    omega: Option<f64>,
    gravity: f64,
) -> Result<Option<Groups>> {
    let Some(geometry) = geometry.geometry()? else {
        return Ok(None);
    };
    let (Some(a), Some(w)) = (amplitude, omega) else {
        bail!("--rod/--point need --amplitude A (m) and --omega W (rad/s)");
    };
    let g = Groups::new(
        geometry.equivalent_length(),
        positive("--gravity", gravity)?,
        positive("--amplitude", a)?,
        positive("--omega", w)?,
        0.0,
    )
    .map_err(|e| anyhow::anyhow!("pendulum and drive: {e}"))?;
    Ok(Some(g))
}
