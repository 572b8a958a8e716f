//! The first record format (version 1), read only to migrate it: the configuration before
//! the duty ceiling, the calibration and the closed-loop settings were part of it. Those load
//! as the values the firmware of that time was built with ([`Calibration::DEFAULT`], a duty
//! ceiling of 1, closed loop off), so a rig keeps behaving as it did.

use serde::Deserialize;

use crate::link::message::WireGeometry;
use crate::rig::calibration::Calibration;
use crate::rig::closed_loop::ClosedLoopR;
use crate::rig::config::{Limits, MotorConfig, RigConfig};

/// The payload of a version-1 record, field for field as it was written.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct ConfigV1 {
    amplitude: f64,
    geometry: WireGeometry,
    gravity: f64,
    omega_max: f64,
    omega_rate_max: f64,
    drive_angle_min_deg: f64,
    drive_angle_max_deg: f64,
    drive_angle_rate_max_deg: f64,
    current_max: f64,
    overcurrent_ms: u32,
    stall_min_omega: f64,
    stall_fraction: f64,
    stall_ms: u32,
    link_timeout_ms: u32,
    omega_per_duty: f64,
    lag: f64,
    kp: f64,
    ki: f64,
    max_correction: f64,
    sample_hz: u32,
    control_hz: u32,
}

impl From<ConfigV1> for RigConfig {
    fn from(v: ConfigV1) -> Self {
        Self {
            amplitude: v.amplitude,
            connecting_rod: 0.0,
            geometry: v.geometry.into(),
            gravity: v.gravity,
            limits: Limits {
                omega_max: v.omega_max,
                omega_rate_max: v.omega_rate_max,
                drive_angle_min_deg: v.drive_angle_min_deg,
                drive_angle_max_deg: v.drive_angle_max_deg,
                drive_angle_rate_max_deg: v.drive_angle_rate_max_deg,
                current_max: v.current_max,
                overcurrent_ms: v.overcurrent_ms,
                stall_min_omega: v.stall_min_omega,
                stall_fraction: v.stall_fraction,
                stall_ms: v.stall_ms,
                link_timeout_ms: v.link_timeout_ms,
                duty_max: 1.0,
            },
            motor: MotorConfig {
                omega_per_duty: v.omega_per_duty,
                lag: v.lag,
                kp: v.kp,
                ki: v.ki,
                max_correction: v.max_correction,
            },
            sample_hz: v.sample_hz,
            control_hz: v.control_hz,
            calibration: Calibration::DEFAULT,
            closed_loop: ClosedLoopR::DEFAULT,
        }
    }
}
