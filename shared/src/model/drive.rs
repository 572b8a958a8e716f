//! The drive: the pivot moves as `r_p(t) = A cos(ωt) · (sin θd, −cos θd)` (physics §2).

use crate::error::{finite, non_negative, positive, ParamError};
use crate::math;

/// The drive angle θd with its sine and cosine, exact at multiples of 90° when built from degrees.
///
/// The special cases of physics §3 (θd = 0°, 90°, 180°) are exact symmetries; computing sin(π) in
/// floating point gives 1.2e-16 instead of 0 and breaks them, so the pair is kept alongside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveAngle {
    rad: f64,
    sin: f64,
    cos: f64,
}

/// Largest angle accepted in degrees, either way. An angle is meant modulo a turn; one given as
/// 1e17° has an f64 spacing of 16°, so whatever it was meant to be is already lost. At 1e6° the
/// spacing is 1.2e-10°, far below any resolution the project uses.
pub const MAX_ANGLE_DEG: f64 = 1e6;
/// [`MAX_ANGLE_DEG`] as the allowed range of an error message.
pub const ANGLE_RANGE: &str = "a number in [-1e6, 1e6] degrees";

impl DriveAngle {
    /// θd from degrees in [−[`MAX_ANGLE_DEG`], [`MAX_ANGLE_DEG`]].
    pub fn from_deg(deg: f64) -> Result<Self, ParamError> {
        let deg = finite("drive angle", deg)?;
        if deg.abs() > MAX_ANGLE_DEG {
            return Err(ParamError {
                name: "drive angle",
                value: deg,
                allowed: ANGLE_RANGE,
            });
        }
        let (sin, cos) = math::sin_cos_deg(deg);
        Ok(Self {
            rad: math::wrap_pi(math::to_rad(deg)),
            sin,
            cos,
        })
    }

    pub fn from_rad(rad: f64) -> Result<Self, ParamError> {
        let rad = finite("drive angle", rad)?;
        let (sin, cos) = math::sin_cos(rad);
        Ok(Self {
            rad: math::wrap_pi(rad),
            sin,
            cos,
        })
    }

    /// θd in radians, wrapped to (−π, π].
    pub fn rad(&self) -> f64 {
        self.rad
    }
    pub fn deg(&self) -> f64 {
        math::to_deg(self.rad)
    }
    pub fn sin(&self) -> f64 {
        self.sin
    }
    pub fn cos(&self) -> f64 {
        self.cos
    }
    /// (sin 2θd, cos 2θd), exact whenever sin θd and cos θd are.
    pub fn sin_cos_2(&self) -> (f64, f64) {
        (
            2.0 * self.sin * self.cos,
            self.cos * self.cos - self.sin * self.sin,
        )
    }
}

/// The shaking of the pivot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drive {
    /// A: half the peak-to-peak stroke (m).
    pub amplitude: f64,
    /// ω (rad/s).
    pub omega: f64,
    pub angle: DriveAngle,
}

impl Drive {
    pub fn new(amplitude: f64, omega: f64, angle: DriveAngle) -> Result<Self, ParamError> {
        Ok(Self {
            amplitude: non_negative("amplitude", amplitude)?,
            omega: positive("omega", omega)?,
            angle,
        })
    }
}
