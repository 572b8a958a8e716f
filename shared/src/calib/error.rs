//! Why a calibration measurement was refused: each names what was measured and what a
//! plausible measurement needs, so the operator knows what to do again.

use crate::error::Compact;
use core::fmt;

/// A measurement the samples cannot support.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CalibError {
    /// Fewer half-swings than the fit needs.
    TooFewSwings { found: usize, needed: usize },
    /// The swing (rad) is too small to measure against the sensor's noise.
    AmplitudeTooSmall { amplitude: f64, needed: f64 },
    /// ω0 (rad/s) outside what the configured pendulum makes plausible.
    FrequencyImplausible { omega0: f64, min: f64, max: f64 },
    /// The swing grows instead of decaying: something drives it.
    NotDecaying { ratio: f64 },
    /// The nudge moved the reading less than needed (rad) to tell its direction.
    NudgeTooSmall { moved: f64, needed: f64 },
    /// The crank moved fewer counts than needed to tell its direction.
    CrankDidNotTurn { counts: i64, needed: i64 },
    /// Fewer jog-to-mark pairs than the fit needs, or two at the same pulse.
    TooFewMarks { found: usize, needed: usize },
    /// The pulse → angle line misses a mark by more than allowed (degrees).
    ServoFitPoor { residual_deg: f64, max_deg: f64 },
    /// The servo's travel (degrees) does not cover the configured drive angles.
    ServoTravelShort { min_deg: f64, max_deg: f64 },
    /// The current readings at rest scatter more than allowed (counts, standard deviation).
    CurrentNoisy { spread: f64, max: f64 },
    /// The current offset (counts) is outside the sensor's plausible zero.
    CurrentOffsetImplausible { offset: f64, min: f64, max: f64 },
    /// The pendulum is not hanging across the drive line: |sin(φ0 − θd)| below what the wobble
    /// needs.
    NotAcrossDrive { sin: f64, needed: f64 },
    /// The drive is too slow beside ω0 for the wobble's first-order formula (ω/ω0).
    DriveTooSlow { ratio: f64, needed: f64 },
    /// The wobble (rad) is too small to read a stroke from.
    WobbleTooSmall { wobble: f64, needed: f64 },
    /// A number that must be finite and positive was not.
    Invalid { what: &'static str, value: f64 },
}

impl fmt::Display for CalibError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use CalibError::*;
        let c = Compact;
        match *self {
            TooFewSwings { found, needed } => write!(
                f,
                "too few swings: {found} half-swings measured, {needed} needed (start from a larger angle, or record longer)"
            ),
            AmplitudeTooSmall { amplitude, needed } => write!(
                f,
                "swing too small: {:.2}° measured, at least {:.2}° needed",
                crate::math::to_deg(amplitude),
                crate::math::to_deg(needed)
            ),
            FrequencyImplausible { omega0, min, max } => write!(
                f,
                "natural frequency {} rad/s is outside the plausible {}..{} rad/s for the configured pendulum",
                c(omega0), c(min), c(max)
            ),
            NotDecaying { ratio } => write!(
                f,
                "the swing does not decay (amplitude ratio per half-swing {}): is the drive off?",
                c(ratio)
            ),
            NudgeTooSmall { moved, needed } => write!(
                f,
                "the nudge moved the reading {:.2}°, at least {:.2}° needed to tell its direction",
                crate::math::to_deg(moved),
                crate::math::to_deg(needed)
            ),
            CrankDidNotTurn { counts, needed } => write!(
                f,
                "the crank moved {counts} counts, at least {needed} needed to tell its direction"
            ),
            TooFewMarks { found, needed } => write!(
                f,
                "{found} distinct jog-to-mark pairs, at least {needed} needed"
            ),
            ServoFitPoor { residual_deg, max_deg } => write!(
                f,
                "the servo's pulse-to-angle line misses a mark by {:.2}°, at most {:.2}° allowed",
                residual_deg, max_deg
            ),
            ServoTravelShort { min_deg, max_deg } => write!(
                f,
                "the servo reaches only {:.1}°..{:.1}°, short of the configured drive angles",
                min_deg, max_deg
            ),
            CurrentNoisy { spread, max } => write!(
                f,
                "current readings at rest scatter by {} counts, at most {} allowed: is the bridge off?",
                c(spread), c(max)
            ),
            CurrentOffsetImplausible { offset, min, max } => write!(
                f,
                "current offset {} counts outside the plausible {}..{}",
                c(offset), c(min), c(max)
            ),
            NotAcrossDrive { sin, needed } => write!(
                f,
                "the pendulum is not across the drive line (|sin(phi0 - theta_d)| = {}, {} needed)",
                c(sin), c(needed)
            ),
            DriveTooSlow { ratio, needed } => write!(
                f,
                "the drive is only {} times omega0, at least {} needed",
                c(ratio), c(needed)
            ),
            WobbleTooSmall { wobble, needed } => write!(
                f,
                "the wobble is {} rad, at least {} rad needed",
                c(wobble), c(needed)
            ),
            Invalid { what, value } => write!(f, "{what} = {} is not a finite positive number", c(value)),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for CalibError {}

/// Accepts a finite number > 0.
pub(crate) fn positive(what: &'static str, value: f64) -> Result<f64, CalibError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(CalibError::Invalid { what, value })
    }
}
