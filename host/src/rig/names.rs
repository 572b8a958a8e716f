//! The names the rig's modes, faults and stop reasons have in every output (JSON keys' values,
//! CSV, the dashboard), and wire angles in degrees.

use kapitza_core::link::message::{BridgeLine, Fault, Mode, ResetCause, StopReason, Turns};
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
        Fault::Bridge(_) => "bridge",
    }
}

/// The line a fault was seen on, where the rig says: a bridge fault's `"nfault"` (the DRV8874
/// pulled nFAULT low) or `"break"` (TIM1's break flag, nFAULT high again).
pub fn fault_reason(f: &Fault) -> Option<&'static str> {
    match f {
        Fault::Bridge(BridgeLine::NFault) => Some("nfault"),
        Fault::Bridge(BridgeLine::Break) => Some("break"),
        _ => None,
    }
}

/// What to do about a fault, in a sentence.
pub fn fault_hint(f: &Fault) -> &'static str {
    match f {
        Fault::EStop => "release the emergency stop, then `kapitza clear`",
        Fault::OverCurrent | Fault::OverCurrentRms => {
            "the motor drew too much current: check the crank turns freely, then `kapitza clear`"
        }
        Fault::Stall => "the crank did not follow the drive: free it, then `kapitza clear`",
        Fault::Sensor => {
            "the pendulum sensor failed: check its cable and magnet, then `kapitza clear`"
        }
        Fault::WrongDirection => {
            "the crank turned backwards: swap the encoder channels or the motor leads \
             (calibration.crank_sign), then `kapitza clear`"
        }
        Fault::PhaseLockLost => {
            "the crank slipped behind the drive: a lower R, or check the belt, then `kapitza clear`"
        }
        Fault::DutyCeiling => {
            "the motor needed more duty than limits.duty_max allows: a lower R, then `kapitza clear`"
        }
        Fault::Bridge(BridgeLine::NFault) => {
            "the H-bridge signals a fault (nFAULT low): its 12 V supply is missing or sagging \
             (the e-stop's relay, the bench supply), or it overheated or saw a short; \
             `kapitza clear` once the supply is back (refused while nFAULT stays low)"
        }
        Fault::Bridge(BridgeLine::Break) => {
            "the H-bridge faulted and recovered between two control ticks (a supply dip or an \
             over-current retry): check the supply and the motor leads, then `kapitza clear`"
        }
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
