//! The tilt servo: points the line of shaking at θd.
//!
//! The supervisor limits θd to the mount's travel and slews it; the pulse map and the power-up
//! θd are `kapitza_core::rig::servo`. This task only sends the pulse, and none before the first
//! θd arrives (so the mount does not swing at boot).

use kapitza_core::rig::servo::ServoMap;

use crate::board::{Tilt, SERVO_MAP};
use crate::channels::THETA_D;

#[embassy_executor::task]
pub async fn run(mut servo: Tilt) {
    let map: ServoMap = SERVO_MAP;
    loop {
        let deg = THETA_D.wait().await;
        servo.set_pulse_us(map.pulse_us(deg));
    }
}
