//! The second record format (version 2), read only to migrate it: the configuration before
//! the connecting rod was part of it. A rig of that time drove its stroke as a pure sine as
//! far as its numbers knew, so the rod loads as 0.

use serde::Deserialize;

use crate::link::message::{WireCalibration, WireClosedLoop, WireGeometry};
use crate::link::WireConfig;
use crate::rig::config::RigConfig;

/// The payload of a version-2 record, field for field as it was written.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct ConfigV2 {
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
    duty_max: f64,
    calibration: WireCalibration,
    closed_loop: WireClosedLoop,
}

impl From<ConfigV2> for RigConfig {
    fn from(v: ConfigV2) -> Self {
        RigConfig::from(WireConfig {
            connecting_rod: 0.0,
            amplitude: v.amplitude,
            geometry: v.geometry,
            gravity: v.gravity,
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
            omega_per_duty: v.omega_per_duty,
            lag: v.lag,
            kp: v.kp,
            ki: v.ki,
            max_correction: v.max_correction,
            sample_hz: v.sample_hz,
            control_hz: v.control_hz,
            duty_max: v.duty_max,
            calibration: v.calibration,
            closed_loop: v.closed_loop,
        })
    }
}
