//! The tilt servo: points the line of shaking at θd.
//!
//! ```text
//! pulse = centre + (θd − θd_centre) · (max − min)/range      (µs; a linear hobby servo)
//! ```
//! The supervisor already limits θd to the mount's travel and slews it at its rate limit; this
//! task only converts. The servo itself is open loop: its position is not measured.

use crate::board::{Tilt, SERVO_CENTRE_DEG, SERVO_MAX_US, SERVO_MIN_US, SERVO_RANGE_DEG};
use crate::channels::THETA_D;

fn pulse_us(theta_d_deg: f64) -> u32 {
    let centre = f64::from(SERVO_MIN_US + SERVO_MAX_US) / 2.0;
    let per_deg = f64::from(SERVO_MAX_US - SERVO_MIN_US) / SERVO_RANGE_DEG;
    let us = centre + (theta_d_deg - SERVO_CENTRE_DEG) * per_deg;
    us.clamp(f64::from(SERVO_MIN_US), f64::from(SERVO_MAX_US)) as u32
}

#[embassy_executor::task]
pub async fn run(mut servo: Tilt) {
    loop {
        let deg = THETA_D.wait().await;
        servo.set_pulse_us(pulse_us(deg));
    }
}
