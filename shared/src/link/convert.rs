//! Between the rig's types and their wire images: modes, faults, refusals, the configuration,
//! and the I16F16 / degree conversions at the boundary.

use super::message::{
    BridgeLine, Fault, Mode, RMethod, ResetCause, ResetInfo, SensorDiagnostics, StopReason,
    WireCalibration, WireClosedLoop, WireConfig, WireGeometry, Q16,
};
use super::reason::{ConfigField, Reason};
use crate::model::{self, Geometry};
use crate::rig::as5047::Diagnostics;
use crate::rig::calibration::Calibration;
use crate::rig::closed_loop::ClosedLoopR;
use crate::rig::config::{Limits, MotorConfig, RigConfig};
use crate::rig::estimator::Tuning;
use crate::rig::fixed::Angle;
use crate::rig::retained;
use crate::rig::safety;
use crate::rig::servo::ServoMap;
use crate::ParamError;

/// A number as I16F16 bits, saturating at the ends of the range; NaN gives 0.
pub fn to_q16(x: f64) -> Q16 {
    if x.is_nan() {
        0
    } else {
        libm::round(x * 65_536.0).clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
    }
}

/// I16F16 bits as a number (exact).
pub fn from_q16(bits: Q16) -> f64 {
    f64::from(bits) / 65_536.0
}

/// θd in degrees along the mount's travel: the wrapping angle unwrapped upwards from the
/// travel's lower end `min_deg` (so a θd inside the travel comes out as the number it was set
/// as, 190° as 190°, not −170°).
pub fn deg_along_travel(theta: Angle, min_deg: f64) -> f64 {
    let off = (theta - Angle::from_deg(min_deg)).to_turns_u32();
    min_deg + f64::from(off) * (360.0 / 4_294_967_296.0)
}

impl From<safety::Fault> for Fault {
    fn from(f: safety::Fault) -> Self {
        match f {
            safety::Fault::EStop => Self::EStop,
            safety::Fault::OverCurrent => Self::OverCurrent,
            safety::Fault::Stall => Self::Stall,
            safety::Fault::Sensor => Self::Sensor,
            safety::Fault::WrongDirection => Self::WrongDirection,
            safety::Fault::PhaseLockLost => Self::PhaseLockLost,
            safety::Fault::OverCurrentRms => Self::OverCurrentRms,
            safety::Fault::DutyCeiling => Self::DutyCeiling,
            safety::Fault::Bridge(l) => Self::Bridge(l.into()),
        }
    }
}

impl From<crate::rig::bridge::Line> for BridgeLine {
    fn from(l: crate::rig::bridge::Line) -> Self {
        match l {
            crate::rig::bridge::Line::NFault => Self::NFault,
            crate::rig::bridge::Line::Break => Self::Break,
        }
    }
}

impl ResetInfo {
    /// The status's reset information from the reset's cause and the fault retained across it.
    pub fn new(cause: retained::Cause, last_fault: Option<safety::Fault>) -> Self {
        use retained::{Cause as C, CrashKind as K};
        let (cause, fault_pc) = match cause {
            C::PowerOn => (ResetCause::PowerOn, None),
            C::Pin => (ResetCause::Pin, None),
            C::Watchdog => (ResetCause::Watchdog, None),
            C::Software => (ResetCause::Software, None),
            C::Other => (ResetCause::Other, None),
            C::Crash(c) => (
                match c.kind {
                    K::Panic => ResetCause::Panic,
                    K::HardFault => ResetCause::HardFault,
                    K::StackOverflow => ResetCause::StackOverflow,
                },
                c.pc,
            ),
        };
        Self {
            cause,
            last_fault: last_fault.map(Into::into),
            fault_pc,
        }
    }
}

impl From<safety::StopReason> for StopReason {
    fn from(r: safety::StopReason) -> Self {
        match r {
            safety::StopReason::Requested => Self::Requested,
            safety::StopReason::LinkSilent => Self::LinkSilent,
            safety::StopReason::Fault(f) => Self::Fault(f.into()),
        }
    }
}

impl From<safety::Mode> for Mode {
    fn from(m: safety::Mode) -> Self {
        match m {
            safety::Mode::Idle => Self::Idle,
            safety::Mode::Running => Self::Running,
            safety::Mode::Stopping(r) => Self::Stopping(r.into()),
            safety::Mode::Faulted(f) => Self::Faulted(f.into()),
        }
    }
}

impl From<model::RMethod> for RMethod {
    fn from(m: model::RMethod) -> Self {
        match m {
            model::RMethod::EquilibriumAngle => Self::EquilibriumAngle,
            model::RMethod::SlowFrequency => Self::SlowFrequency,
        }
    }
}

impl From<safety::Refusal> for Reason {
    fn from(r: safety::Refusal) -> Self {
        use safety::Refusal as R;
        match r {
            R::OmegaInvalid { .. } => Self::OmegaInvalid,
            R::OmegaAboveLimit { requested, limit } => Self::OmegaAboveLimit {
                requested: to_q16(requested),
                limit: to_q16(limit),
            },
            R::DriveAngleOutOfRange {
                requested,
                min,
                max,
            } => Self::DriveAngleOutOfRange {
                requested: to_q16(requested),
                min: to_q16(min),
                max: to_q16(max),
            },
            R::Faulted(f) => Self::Faulted(f.into()),
            R::WrongMode(m) => Self::WrongMode(m.into()),
            R::EStopStillActive => Self::EStopStillActive,
            R::BridgeFaultActive => Self::BridgeFaultActive,
        }
    }
}

impl From<crate::rig::fields::Field> for ConfigField {
    fn from(f: crate::rig::fields::Field) -> Self {
        Self::from_param_name(f.name())
    }
}

impl From<ParamError> for Reason {
    fn from(e: ParamError) -> Self {
        Self::ConfigInvalid {
            field: ConfigField::from_param_name(e.name),
        }
    }
}

impl From<Geometry> for WireGeometry {
    fn from(g: Geometry) -> Self {
        match g {
            Geometry::Rod { length } => Self::Rod { length },
            Geometry::PointMass { length } => Self::PointMass { length },
            Geometry::General { inertia, mass, com } => Self::General { inertia, mass, com },
        }
    }
}

impl From<WireGeometry> for Geometry {
    fn from(g: WireGeometry) -> Self {
        match g {
            WireGeometry::Rod { length } => Self::Rod { length },
            WireGeometry::PointMass { length } => Self::PointMass { length },
            WireGeometry::General { inertia, mass, com } => Self::General { inertia, mass, com },
        }
    }
}

impl From<RigConfig> for WireConfig {
    fn from(c: RigConfig) -> Self {
        let RigConfig {
            amplitude,
            connecting_rod,
            geometry,
            gravity,
            limits:
                Limits {
                    omega_max,
                    omega_rate_max,
                    drive_angle_min_deg,
                    drive_angle_max_deg,
                    drive_angle_rate_max_deg,
                    current_max,
                    overcurrent_ms,
                    stall_min_omega,
                    stall_fraction,
                    stall_ms,
                    link_timeout_ms,
                    duty_max,
                },
            motor:
                MotorConfig {
                    omega_per_duty,
                    lag,
                    kp,
                    ki,
                    max_correction,
                },
            sample_hz,
            control_hz,
            calibration,
            closed_loop,
        } = c;
        Self {
            amplitude,
            connecting_rod,
            geometry: geometry.into(),
            gravity,
            omega_max,
            omega_rate_max,
            drive_angle_min_deg,
            drive_angle_max_deg,
            drive_angle_rate_max_deg,
            current_max,
            overcurrent_ms,
            stall_min_omega,
            stall_fraction,
            stall_ms,
            link_timeout_ms,
            omega_per_duty,
            lag,
            kp,
            ki,
            max_correction,
            sample_hz,
            control_hz,
            duty_max,
            calibration: calibration.into(),
            closed_loop: closed_loop.into(),
        }
    }
}

impl From<WireConfig> for RigConfig {
    fn from(w: WireConfig) -> Self {
        let WireConfig {
            amplitude,
            connecting_rod,
            geometry,
            gravity,
            omega_max,
            omega_rate_max,
            drive_angle_min_deg,
            drive_angle_max_deg,
            drive_angle_rate_max_deg,
            current_max,
            overcurrent_ms,
            stall_min_omega,
            stall_fraction,
            stall_ms,
            link_timeout_ms,
            omega_per_duty,
            lag,
            kp,
            ki,
            max_correction,
            sample_hz,
            control_hz,
            duty_max,
            calibration,
            closed_loop,
        } = w;
        Self {
            amplitude,
            connecting_rod,
            geometry: geometry.into(),
            gravity,
            limits: Limits {
                omega_max,
                omega_rate_max,
                drive_angle_min_deg,
                drive_angle_max_deg,
                drive_angle_rate_max_deg,
                current_max,
                overcurrent_ms,
                stall_min_omega,
                stall_fraction,
                stall_ms,
                link_timeout_ms,
                duty_max,
            },
            motor: MotorConfig {
                omega_per_duty,
                lag,
                kp,
                ki,
                max_correction,
            },
            sample_hz,
            control_hz,
            calibration: calibration.into(),
            closed_loop: closed_loop.into(),
        }
    }
}

impl From<Calibration> for WireCalibration {
    fn from(c: Calibration) -> Self {
        let Calibration {
            pendulum_zero,
            pendulum_sign,
            crank_sign,
            servo:
                ServoMap {
                    min_us,
                    max_us,
                    range_deg,
                    centre_deg,
                },
            current_offset,
            current_scale,
            estimator:
                Tuning {
                    hysteresis,
                    min_swing,
                    settle_band,
                    block_s,
                    quiet_blocks,
                },
        } = c;
        Self {
            pendulum_zero,
            pendulum_sign,
            crank_sign,
            servo_min_us: min_us,
            servo_max_us: max_us,
            servo_range_deg: range_deg,
            servo_centre_deg: centre_deg,
            current_offset,
            current_scale,
            hysteresis,
            min_swing,
            settle_band,
            block_s,
            quiet_blocks,
        }
    }
}

impl From<WireCalibration> for Calibration {
    fn from(w: WireCalibration) -> Self {
        let WireCalibration {
            pendulum_zero,
            pendulum_sign,
            crank_sign,
            servo_min_us,
            servo_max_us,
            servo_range_deg,
            servo_centre_deg,
            current_offset,
            current_scale,
            hysteresis,
            min_swing,
            settle_band,
            block_s,
            quiet_blocks,
        } = w;
        Self {
            pendulum_zero,
            pendulum_sign,
            crank_sign,
            servo: ServoMap {
                min_us: servo_min_us,
                max_us: servo_max_us,
                range_deg: servo_range_deg,
                centre_deg: servo_centre_deg,
            },
            current_offset,
            current_scale,
            estimator: Tuning {
                hysteresis,
                min_swing,
                settle_band,
                block_s,
                quiet_blocks,
            },
        }
    }
}

impl From<ClosedLoopR> for WireClosedLoop {
    fn from(c: ClosedLoopR) -> Self {
        let ClosedLoopR {
            enabled,
            band,
            rate_max,
        } = c;
        Self {
            enabled,
            band,
            rate_max,
        }
    }
}

impl From<WireClosedLoop> for ClosedLoopR {
    fn from(w: WireClosedLoop) -> Self {
        let WireClosedLoop {
            enabled,
            band,
            rate_max,
        } = w;
        Self {
            enabled,
            band,
            rate_max,
        }
    }
}

impl From<Diagnostics> for SensorDiagnostics {
    fn from(d: Diagnostics) -> Self {
        Self {
            agc: d.agc,
            magnet_low: d.magnet_low,
            magnet_high: d.magnet_high,
            cordic_overflow: d.cordic_overflow,
            ready: d.ready,
        }
    }
}

impl WireConfig {
    /// The configuration this describes, if [`RigConfig::validate`] accepts it.
    pub fn to_valid(self) -> Result<RigConfig, Reason> {
        RigConfig::from(self).validate().map_err(Reason::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::retained::{Cause, Crash, CrashKind};

    #[test]
    fn reset_info_carries_the_crash_and_its_pc() {
        let crash = |kind, pc| Cause::Crash(Crash { kind, pc });
        let cases = [
            (Cause::Watchdog, ResetCause::Watchdog, None),
            (Cause::Software, ResetCause::Software, None),
            (crash(CrashKind::Panic, None), ResetCause::Panic, None),
            (
                crash(CrashKind::HardFault, Some(0x0800_1234)),
                ResetCause::HardFault,
                Some(0x0800_1234),
            ),
            (
                crash(CrashKind::StackOverflow, None),
                ResetCause::StackOverflow,
                None,
            ),
        ];
        for (cause, want, pc) in cases {
            let r = ResetInfo::new(cause, Some(safety::Fault::Stall));
            assert_eq!((r.cause, r.fault_pc), (want, pc), "{cause:?}");
            assert_eq!(r.last_fault, Some(Fault::Stall));
        }
        assert_eq!(ResetInfo::new(Cause::PowerOn, None), ResetInfo::POWER_ON);
    }
}
