//! Checks of command-line numbers, with messages that name the flag and the allowed range.
//!
//! The core checks its inputs too; checking here first lets the message speak in the user's
//! terms (`--rod`, degrees) rather than the core's.

use anyhow::{bail, Result};
use clap::Args;
use kapitza_core::model::Geometry;

pub fn positive(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        bail!("{flag} {v} is out of range: expected a finite number > 0")
    }
}

pub fn non_negative(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        bail!("{flag} {v} is out of range: expected a finite number >= 0")
    }
}

pub fn finite(flag: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        bail!("{flag} {v} is out of range: expected a finite number")
    }
}

/// The pendulum, given as a uniform rod or a point mass on a light rod.
#[derive(Debug, Clone, Args)]
#[group(multiple = false)]
pub struct GeometryArgs {
    /// Uniform rod of length L (m), pivoted at one end: ℓ = 2L/3.
    #[arg(long, value_name = "L", allow_negative_numbers = true)]
    pub rod: Option<f64>,
    /// Point mass on a light rod of length l (m): ℓ = l.
    #[arg(long, value_name = "l", allow_negative_numbers = true)]
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
