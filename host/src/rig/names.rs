//! The names the rig's modes, faults and stop reasons have in every output (JSON keys' values,
//! CSV, the dashboard), and wire angles in degrees.

use kapitza_core::link::message::{Fault, Mode, ResetCause, StopReason, Turns};
use kapitza_core::math;

pub fn mode_name(m: &Mode) -> &'static str {
    match m {
        Mode::Idle => "idle",
        Mode::Running => "running",
        Mode::Stopping(_) => "stopping",
        Mode::Faulted(_) => "faulted",
        Mode::Checking => "checking",
    }
}

pub fn fault_name(f: &Fault) -> &'static str {
    match f {
        Fault::EStop => "estop",
        Fault::OverCurrent => "over_current",
        Fault::Stall => "stall",
        Fault::Sensor => "sensor",
        Fault::WrongDirection => "wrong_direction",
        Fault::PhaseLockLost => "phase_lock_lost",
        Fault::OverCurrentRms => "over_current_rms",
        Fault::DutyCeiling => "duty_ceiling",
    }
}

pub fn stop_name(s: &StopReason) -> &'static str {
    match s {
        StopReason::Requested => "requested",
        StopReason::LinkSilent => "link_silent",
        StopReason::Fault(f) => fault_name(f),
    }
}

/// A wire angle (2^32 per turn) in degrees, in (−180, 180].
pub fn turns_deg(t: Turns) -> f64 {
    math::wrap_deg(f64::from(t) * (360.0 / 4_294_967_296.0))
}

pub fn reset_name(c: &ResetCause) -> &'static str {
    match c {
        ResetCause::PowerOn => "power_on",
        ResetCause::Pin => "pin",
        ResetCause::Watchdog => "watchdog",
        ResetCause::Software => "software",
        ResetCause::Other => "other",
        ResetCause::Panic => "panic",
        ResetCause::HardFault => "hard_fault",
        ResetCause::StackOverflow => "stack_overflow",
    }
}
