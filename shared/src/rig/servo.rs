//! The tilt servo: θd → pulse width, and the θd the rig starts from after a reset.
//!
//! ```text
//! pulse = (min + max)/2 + (θd − centre) · (max − min)/range      µs, clamped to [min, max]
//! ```
//! A hobby servo is open loop: nobody measures where it is. Commanding any fixed angle at boot
//! swings the mount there, mid-demo after a watchdog reset. So the rig starts from the θd it
//! last commanded when that survived the reset ([`super::retained`]), and from the park angle
//! (0°, vertical shaking, or the nearest end of the travel) only after a power cycle, when the
//! servo's position is unknown anyway. Until then no pulse is sent at all.

use super::config::RigConfig;

/// A linear servo's pulse map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoMap {
    /// Pulse widths at the two ends of the servo's range (µs).
    pub min_us: u32,
    pub max_us: u32,
    /// The range those pulses span (degrees).
    pub range_deg: f64,
    /// The θd (degrees along the mount's travel) at the middle of the range.
    pub centre_deg: f64,
}

impl ServoMap {
    /// The reference board's servo: 500–2500 µs over 270°, centred at θd = 90°.
    pub const REFERENCE: Self = Self {
        min_us: 500,
        max_us: 2500,
        range_deg: 270.0,
        centre_deg: 90.0,
    };

    /// The pulse width (µs, unrounded) that points the mount at `deg`, clamped to the servo's
    /// range.
    pub fn pulse(&self, deg: f64) -> f64 {
        let (lo, hi) = (f64::from(self.min_us), f64::from(self.max_us));
        let us = (lo + hi) / 2.0 + (deg - self.centre_deg) * (hi - lo) / self.range_deg;
        // NaN clamps to nothing: send the centre instead.
        let us = if us.is_nan() { (lo + hi) / 2.0 } else { us };
        us.clamp(lo, hi)
    }

    /// [`ServoMap::pulse`] rounded to whole µs.
    pub fn pulse_us(&self, deg: f64) -> u32 {
        libm::round(self.pulse(deg)) as u32
    }

    /// The angle (deg) a pulse points the mount at: the inverse of [`ServoMap::pulse`] inside
    /// the range (a simulated servo's).
    pub fn deg_of_pulse(&self, us: f64) -> f64 {
        let (lo, hi) = (f64::from(self.min_us), f64::from(self.max_us));
        self.centre_deg + (us.clamp(lo, hi) - (lo + hi) / 2.0) * self.range_deg / (hi - lo)
    }
}

/// θd (degrees) at power-up: the retained one if it is inside the travel, else the park angle.
pub fn power_up_deg(retained: Option<f64>, cfg: &RigConfig) -> f64 {
    let (lo, hi) = (
        cfg.limits.drive_angle_min_deg,
        cfg.limits.drive_angle_max_deg,
    );
    match retained {
        Some(d) if d.is_finite() && (lo..=hi).contains(&d) => d,
        _ => 0f64.clamp(lo, hi),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 500–2500 µs over 270°, centred at 90°: 2000 µs / 270° = 7.407 µs per degree.
    const MAP: ServoMap = ServoMap::REFERENCE;

    #[test]
    fn pulse_is_linear_and_clamped() {
        assert_eq!(MAP.pulse_us(90.0), 1500);
        // 90° off the centre: 1500 ± 90 · 2000/270 = 1500 ± 666.7 → 2167 / 833 (rounded).
        assert_eq!(MAP.pulse_us(180.0), 2167);
        assert_eq!(MAP.pulse_us(0.0), 833);
        // The ends of the range: 90 ± 135°.
        assert_eq!(MAP.pulse_us(225.0), 2500);
        assert_eq!(MAP.pulse_us(-45.0), 500);
        assert_eq!(MAP.pulse_us(400.0), 2500);
        assert_eq!(MAP.pulse_us(f64::NAN), 1500);
        // The inverse, inside the range.
        for deg in [-45.0, 0.0, 37.5, 180.0, 225.0] {
            assert!(
                (MAP.deg_of_pulse(MAP.pulse(deg)) - deg).abs() < 1e-12,
                "{deg}"
            );
        }
    }

    #[test]
    fn power_up_keeps_a_retained_angle_inside_the_travel() {
        let cfg = RigConfig::REFERENCE; // travel [−10°, 190°]
        assert_eq!(power_up_deg(Some(120.0), &cfg), 120.0);
        assert_eq!(power_up_deg(None, &cfg), 0.0);
        assert_eq!(power_up_deg(Some(250.0), &cfg), 0.0);
        assert_eq!(power_up_deg(Some(f64::NAN), &cfg), 0.0);
        let mut c = cfg;
        c.limits.drive_angle_min_deg = 20.0;
        assert_eq!(power_up_deg(None, &c), 20.0);
    }
}
