//! Why something was refused: one [`Reason`] for every way a request can fail, each with a
//! stable numeric code and a sentence the host can show.
//!
//! Two kinds, kept apart by [`Reason::is_link`]:
//!
//! ```text
//! code     kind      meaning                                               the host should
//! 1..=15   link      the frame did not arrive as sent, or speaks another    resend / check versions
//!                    protocol version; the rig did not look at the command
//! 16..     command   the rig understood and refused (limits, mode, fault)   show it to the user
//! ```
//! Codes never change meaning within a protocol version; a new reason gets a new code.

use core::fmt;

use postcard::experimental::max_size::MaxSize;
use serde::{Deserialize, Serialize};

use super::message::{Fault, Mode, Q15, Q16};

/// A refusal: the frame was bad or the command was not allowed. Nothing changed on the rig.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reason {
    // --- link level: the line failed ---
    /// The CRC did not match: noise or a lost byte.
    BadCrc,
    /// The frame ended before its header, CRC or message was complete.
    Truncated,
    /// Not a valid encoding (bad COBS, varint, bool or option tag, or bytes left over).
    Malformed,
    /// A message kind this rig does not know (a newer host?).
    UnknownMessage,
    /// The frame's protocol version is not the rig's; only `GetVersion` is answered.
    VersionMismatch { rig: u8, frame: u8 },
    /// Longer than the largest frame of this protocol version.
    TooLong,

    // --- command level: the rig refused ---
    /// R is negative or not a number.
    RInvalid { requested: Q16 },
    /// ω is not a finite number ≥ 0.
    OmegaInvalid,
    /// ω = ωc √R (rad/s, I16F16) is above the limit ω_max.
    OmegaAboveLimit { requested: Q16, limit: Q16 },
    /// θd (degrees, I16F16) is outside the mount's travel [min, max].
    DriveAngleOutOfRange { requested: Q16, min: Q16, max: Q16 },
    /// A fault is latched: clear it first.
    Faulted(Fault),
    /// Not allowed in the current mode (start needs idle, a new ω needs running, a new
    /// configuration needs idle).
    WrongMode(Mode),
    /// `ClearFault` while the e-stop is still pressed.
    EStopStillActive,
    /// A configuration value is out of range.
    ConfigInvalid { field: ConfigField },
    /// A pre-run check is running: wait for its verdict (in the status).
    CheckRunning,
    /// A bring-up duty (I1F15) above the bring-up cap.
    DutyAboveCap { requested: Q15, cap: Q15 },
    /// `ClearFault` while the H-bridge's nFAULT still reads low.
    BridgeFaultActive,
}

/// The configuration field a [`Reason::ConfigInvalid`] names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigField {
    Amplitude,
    Geometry,
    Gravity,
    OmegaMax,
    OmegaRateMax,
    DriveAngleRateMax,
    CurrentMax,
    StallMinOmega,
    StallFraction,
    OmegaPerDuty,
    Lag,
    Kp,
    Ki,
    MaxCorrection,
    SampleHz,
    DutyMax,
    PendulumZero,
    PendulumSign,
    CrankSign,
    ServoPulse,
    ServoRange,
    ServoCentre,
    CurrentOffset,
    CurrentScale,
    Hysteresis,
    MinSwing,
    SettleBand,
    BlockS,
    QuietBlocks,
    ClosedLoopBand,
    ClosedLoopRateMax,
    ConnectingRod,
    ControlHz,
    OvercurrentMs,
    StallMs,
    LinkTimeoutMs,
    DriveAngleMin,
    DriveAngleMax,
    Other,
}

impl ConfigField {
    /// Every field, in declaration order: `ALL[i] as usize == i`.
    pub const ALL: [Self; 39] = [
        Self::Amplitude,
        Self::Geometry,
        Self::Gravity,
        Self::OmegaMax,
        Self::OmegaRateMax,
        Self::DriveAngleRateMax,
        Self::CurrentMax,
        Self::StallMinOmega,
        Self::StallFraction,
        Self::OmegaPerDuty,
        Self::Lag,
        Self::Kp,
        Self::Ki,
        Self::MaxCorrection,
        Self::SampleHz,
        Self::DutyMax,
        Self::PendulumZero,
        Self::PendulumSign,
        Self::CrankSign,
        Self::ServoPulse,
        Self::ServoRange,
        Self::ServoCentre,
        Self::CurrentOffset,
        Self::CurrentScale,
        Self::Hysteresis,
        Self::MinSwing,
        Self::SettleBand,
        Self::BlockS,
        Self::QuietBlocks,
        Self::ClosedLoopBand,
        Self::ClosedLoopRateMax,
        Self::ConnectingRod,
        Self::ControlHz,
        Self::OvercurrentMs,
        Self::StallMs,
        Self::LinkTimeoutMs,
        Self::DriveAngleMin,
        Self::DriveAngleMax,
        Self::Other,
    ];

    /// The field a [`crate::ParamError`] from `RigConfig::validate` names.
    pub fn from_param_name(name: &str) -> Self {
        match name {
            "amplitude" => Self::Amplitude,
            "gravity" => Self::Gravity,
            "equivalent length" | "length" | "inertia" | "mass" | "com" => Self::Geometry,
            "omega_max" => Self::OmegaMax,
            "omega_rate_max" => Self::OmegaRateMax,
            "drive_angle_min_deg" => Self::DriveAngleMin,
            "drive_angle_max_deg" => Self::DriveAngleMax,
            "drive_angle_rate_max_deg" => Self::DriveAngleRateMax,
            "current_max" => Self::CurrentMax,
            "stall_min_omega" => Self::StallMinOmega,
            "stall_fraction" => Self::StallFraction,
            "omega_per_duty" => Self::OmegaPerDuty,
            "lag" => Self::Lag,
            "kp" => Self::Kp,
            "ki" => Self::Ki,
            "max_correction" => Self::MaxCorrection,
            "sample_hz" => Self::SampleHz,
            "control_hz" => Self::ControlHz,
            "overcurrent_ms" => Self::OvercurrentMs,
            "stall_ms" => Self::StallMs,
            "link_timeout_ms" => Self::LinkTimeoutMs,
            "duty_max" => Self::DutyMax,
            "pendulum_zero" => Self::PendulumZero,
            "pendulum_sign" => Self::PendulumSign,
            "crank_sign" => Self::CrankSign,
            "servo_pulse_us" => Self::ServoPulse,
            "servo_range_deg" => Self::ServoRange,
            "servo_centre_deg" => Self::ServoCentre,
            "current_offset" => Self::CurrentOffset,
            "current_scale" => Self::CurrentScale,
            "hysteresis" => Self::Hysteresis,
            "min_swing" => Self::MinSwing,
            "settle_band" => Self::SettleBand,
            "block_s" => Self::BlockS,
            "quiet_blocks" => Self::QuietBlocks,
            "closed_loop_band" => Self::ClosedLoopBand,
            "closed_loop_rate_max" => Self::ClosedLoopRateMax,
            "connecting_rod" => Self::ConnectingRod,
            _ => Self::Other,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Amplitude => "amplitude",
            Self::Geometry => "geometry",
            Self::Gravity => "gravity",
            Self::OmegaMax => "omega_max",
            Self::OmegaRateMax => "omega_rate_max",
            Self::DriveAngleRateMax => "drive_angle_rate_max_deg",
            Self::CurrentMax => "current_max",
            Self::StallMinOmega => "stall_min_omega",
            Self::StallFraction => "stall_fraction",
            Self::OmegaPerDuty => "omega_per_duty",
            Self::Lag => "lag",
            Self::Kp => "kp",
            Self::Ki => "ki",
            Self::MaxCorrection => "max_correction",
            Self::SampleHz => "sample_hz",
            Self::DutyMax => "duty_max",
            Self::PendulumZero => "calibration.pendulum_zero",
            Self::PendulumSign => "calibration.pendulum_sign",
            Self::CrankSign => "calibration.crank_sign",
            Self::ServoPulse => "calibration.servo_min_us/servo_max_us",
            Self::ServoRange => "calibration.servo_range_deg",
            Self::ServoCentre => "calibration.servo_centre_deg",
            Self::CurrentOffset => "calibration.current_offset",
            Self::CurrentScale => "calibration.current_scale",
            Self::Hysteresis => "calibration.hysteresis",
            Self::MinSwing => "calibration.min_swing",
            Self::SettleBand => "calibration.settle_band",
            Self::BlockS => "calibration.block_s",
            Self::QuietBlocks => "calibration.quiet_blocks",
            Self::ClosedLoopBand => "closed_loop.band",
            Self::ClosedLoopRateMax => "closed_loop.rate_max",
            Self::ConnectingRod => "connecting_rod",
            Self::ControlHz => "control_hz",
            Self::OvercurrentMs => "overcurrent_ms",
            Self::StallMs => "stall_ms",
            Self::LinkTimeoutMs => "link_timeout_ms",
            Self::DriveAngleMin => "drive_angle_min_deg",
            Self::DriveAngleMax => "drive_angle_max_deg",
            Self::Other => "a configuration value",
        }
    }
}

impl Reason {
    /// The stable numeric code (1–15 link level, 16 and up command level).
    pub fn code(&self) -> u8 {
        match self {
            Self::BadCrc => 1,
            Self::Truncated => 2,
            Self::Malformed => 3,
            Self::UnknownMessage => 4,
            Self::VersionMismatch { .. } => 5,
            Self::TooLong => 6,
            Self::RInvalid { .. } => 16,
            Self::OmegaInvalid => 17,
            Self::OmegaAboveLimit { .. } => 18,
            Self::DriveAngleOutOfRange { .. } => 19,
            Self::Faulted(_) => 20,
            Self::WrongMode(_) => 21,
            Self::EStopStillActive => 22,
            Self::ConfigInvalid { .. } => 23,
            Self::CheckRunning => 24,
            Self::DutyAboveCap { .. } => 25,
            Self::BridgeFaultActive => 26,
        }
    }

    /// The line failed (resend, or check versions), as opposed to the rig refusing a command.
    pub fn is_link(&self) -> bool {
        self.code() < 16
    }
}

/// I16F16 bits as a number, for messages.
fn q16(bits: Q16) -> f64 {
    f64::from(bits) / 65_536.0
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}] ", self.code())?;
        match *self {
            Self::BadCrc => f.write_str("frame damaged on the line (CRC mismatch)"),
            Self::Truncated => f.write_str("frame cut short"),
            Self::Malformed => f.write_str("frame not validly encoded"),
            Self::UnknownMessage => f.write_str("message kind unknown to this rig"),
            Self::VersionMismatch { rig, frame } => write!(
                f,
                "protocol version {frame} in the frame, but the rig speaks version {rig}"
            ),
            Self::TooLong => f.write_str("frame longer than any message of this protocol"),
            Self::RInvalid { requested } => {
                write!(f, "R = {} is not a number >= 0", q16(requested))
            }
            Self::OmegaInvalid => f.write_str("the drive frequency is not a number >= 0"),
            Self::OmegaAboveLimit { requested, limit } => write!(
                f,
                "omega = {} rad/s is above the limit {} rad/s",
                q16(requested),
                q16(limit)
            ),
            Self::DriveAngleOutOfRange {
                requested,
                min,
                max,
            } => write!(
                f,
                "drive angle {} deg is outside the mount's travel [{}, {}] deg",
                q16(requested),
                q16(min),
                q16(max)
            ),
            Self::Faulted(x) => write!(f, "fault latched ({x:?}): clear it first"),
            Self::WrongMode(m) => write!(f, "not allowed in mode {m:?}"),
            Self::EStopStillActive => f.write_str("the emergency stop is still pressed"),
            Self::ConfigInvalid { field } => {
                write!(f, "configuration value {} out of range", field.name())
            }
            Self::CheckRunning => f.write_str("the pre-run check is running: wait for its verdict"),
            Self::DutyAboveCap { requested, cap } => write!(
                f,
                "bring-up duty {} is above the bring-up cap {}",
                f64::from(requested) / 32_768.0,
                f64::from(cap) / 32_768.0
            ),
            Self::BridgeFaultActive => {
                f.write_str("the H-bridge still signals a fault (nFAULT low): check its supply")
            }
        }
    }
}

impl fmt::Display for super::message::Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use super::message::Verdict as V;
        match *self {
            V::SensorSilent => f.write_str("the pendulum sensor gave no angle during the check"),
            V::SensorNotReady => f.write_str(
                "the pendulum sensor is not ready (no diagnostics, or its magnet out of range)",
            ),
            V::CurrentOffset { amps } => write!(
                f,
                "the current sense reads {:.3} A at rest (calibrate its offset)",
                q16(amps)
            ),
            V::CrankReversed { speed } => write!(
                f,
                "the test pulse turned the crank backwards ({:.1} rad/s): encoder channels or motor leads swapped (calibration.crank_sign)",
                q16(speed)
            ),
            V::CrankStalled { speed } => write!(
                f,
                "the test pulse did not turn the crank ({:.1} rad/s): motor stalled or unpowered",
                q16(speed)
            ),
            V::CrankTooFast { speed } => write!(
                f,
                "the test pulse turned the crank too fast ({:.1} rad/s) for the motor's configured gain",
                q16(speed)
            ),
            V::Aborted => f.write_str("the check was stopped before its verdict"),
        }
    }
}
