//! The tilt servo: points the line of shaking at θd.
//!
//! The supervisor limits θd to the mount's travel and slews it; the control loop turns it into
//! a pulse width with the configuration's calibrated map (`kapitza_core::rig::calibration`), and
//! the power-up θd is `kapitza_core::rig::servo`'s. This task only sends the pulse, and none
//! before the first one arrives (so the mount does not swing at boot).

use crate::board::Tilt;
use crate::channels::SERVO_US;

#[embassy_executor::task]
pub async fn run(mut servo: Tilt) {
    loop {
        let us = SERVO_US.wait().await;
        servo.set_pulse_us(us);
    }
}
