//! What a bench must be measured for once, kept in the configuration instead of the build:
//! the pendulum sensor's zero and direction, the crank encoder's direction, the servo's pulse
//! map, the current sense's offset and scale, and the estimator's thresholds.
//!
//! ```text
//! pendulum  θ = sign · (count − zero)            2^-14 turn a count (AS5047P, rig::as5047::angle)
//! crank     φ = sign · encoder                   the encoder as wired, one turn = 2^32
//! current   I = (counts − offset) · scale        A; counts from the 12-bit ADC
//! servo     pulse = (min + max)/2 + (θd − centre)·(max − min)/range     µs (rig::servo)
//! ```
//! [`Calibration::DEFAULT`] is the reference board as wired: a stored configuration of the first
//! record format, which has no calibration, loads with it ([`crate::persist`]).

use super::config::too_big as bad;
use super::estimator::Tuning;
use super::fixed::{Amps, Angle};
use super::servo::ServoMap;
use crate::error::ParamError;

/// A bench's calibration: see the [module doc](self).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calibration {
    /// The pendulum sensor's count with the pendulum hanging at rest (0..2^14).
    pub pendulum_zero: u16,
    /// +1 if the pendulum sensor's count grows counter-clockwise seen from the front
    /// (physics §2), −1 if clockwise.
    pub pendulum_sign: i8,
    /// +1 if the crank encoder counts up when positive duty turns the crank, −1 if its
    /// channels are swapped.
    pub crank_sign: i8,
    /// The tilt servo's pulse map.
    pub servo: ServoMap,
    /// The current sense's ADC reading at zero current (counts) and its gain (A per count).
    pub current_offset: f64,
    pub current_scale: f64,
    /// The estimator's thresholds.
    pub estimator: Tuning,
}

/// The largest current-sense gain accepted (A per count): 1 A a count is already a sensor that
/// cannot see the 3 A trip.
const SCALE_MAX: f64 = 1.0;
/// The ADC's full scale (12 bits).
pub const ADC_COUNTS: f64 = 4096.0;

impl Calibration {
    /// The reference board as built: sensor zero 0 and sign +1, the crank counting with the
    /// drive, a 500–2500 µs servo over 270° centred at θd = 90°, the DRV8874's current mirror
    /// into 1.5 kΩ read by a 3.3 V 12-bit ADC (3.3/4096/0.6825 A a count, held as the firmware
    /// always held it, 77/65536), and the estimator's thresholds for a 14-bit sensor.
    pub const DEFAULT: Self = Self {
        pendulum_zero: 0,
        pendulum_sign: 1,
        crank_sign: 1,
        servo: ServoMap::REFERENCE,
        current_offset: 0.0,
        current_scale: 77.0 / 65_536.0,
        estimator: Tuning::DEFAULT,
    };

    /// Checks every field; the error names it (`ConfigField` per field on the wire).
    pub fn validate(&self) -> Result<(), ParamError> {
        if self.pendulum_zero >= 1 << 14 {
            return Err(bad(
                "pendulum_zero",
                f64::from(self.pendulum_zero),
                "a sensor count in [0, 16383]",
            ));
        }
        for (name, s) in [
            ("pendulum_sign", self.pendulum_sign),
            ("crank_sign", self.crank_sign),
        ] {
            if s != 1 && s != -1 {
                return Err(bad(name, f64::from(s), "+1 or -1"));
            }
        }
        let sv = &self.servo;
        if !(SERVO_MIN_US..=SERVO_MAX_US).contains(&sv.min_us)
            || !(SERVO_MIN_US..=SERVO_MAX_US).contains(&sv.max_us)
            || sv.min_us >= sv.max_us
        {
            return Err(bad(
                "servo_pulse_us",
                f64::from(sv.max_us),
                "min_us < max_us, both in [400, 2600] us",
            ));
        }
        if !(sv.range_deg.is_finite() && sv.range_deg > 0.0 && sv.range_deg <= 360.0) {
            return Err(bad("servo_range_deg", sv.range_deg, "in (0, 360] degrees"));
        }
        if !(sv.centre_deg.is_finite() && sv.centre_deg.abs() <= 360.0) {
            return Err(bad(
                "servo_centre_deg",
                sv.centre_deg,
                "in [-360, 360] degrees",
            ));
        }
        if !(self.current_offset.is_finite() && (0.0..ADC_COUNTS).contains(&self.current_offset)) {
            return Err(bad(
                "current_offset",
                self.current_offset,
                "ADC counts in [0, 4096)",
            ));
        }
        // The conversion holds the scale in Q24: below one LSB it would be 0.
        if !(self.current_scale.is_finite()
            && self.current_scale >= 1.0 / 16_777_216.0
            && self.current_scale <= SCALE_MAX)
        {
            return Err(bad(
                "current_scale",
                self.current_scale,
                "A per count in [2^-24, 1]",
            ));
        }
        self.estimator.validate()
    }

    /// The pendulum angle of a sensor count.
    pub fn pendulum_angle(&self, count: u16) -> Angle {
        super::as5047::angle(count, self.pendulum_zero, self.pendulum_sign)
    }

    /// The crank angle of the encoder's reading as wired.
    pub fn crank_angle(&self, raw: Angle) -> Angle {
        if self.crank_sign < 0 {
            Angle::ZERO - raw
        } else {
            raw
        }
    }

    /// The current-sense conversion, fixed for the control tick.
    pub fn current_sense(&self) -> CurrentSense {
        CurrentSense {
            offset_q8: libm::round(self.current_offset * 256.0) as i64,
            scale_q24: libm::round(self.current_scale * 16_777_216.0) as i64,
        }
    }
}

/// The servo pulse range accepted (µs): hobby servos take 500–2500 µs, a little beyond for
/// trimming.
const SERVO_MIN_US: u32 = 400;
const SERVO_MAX_US: u32 = 2600;

/// ADC counts → amperes in integers: `(counts − offset)·scale`, offset in Q8 counts and the
/// scale in Q24 A a count, so the reference board's 77/65536 A a count is exact and a record of
/// the first format, which fixed that scale, reads the same currents to the bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurrentSense {
    offset_q8: i64,
    scale_q24: i64,
}

impl CurrentSense {
    /// The current (A, I16F16, saturating) of an ADC reading.
    pub fn amps(&self, counts: u16) -> Amps {
        // (Q8 counts · Q24 A/count) >> 16 = Q16 A
        let q16 = (((i64::from(counts) << 8) - self.offset_q8) * self.scale_q24) >> 16;
        Amps::from_bits(super::fixed::approx::sat_i32(q16))
    }

    /// The ADC reading (counts, rounded, clamped to the 12 bits) of a current: the inverse,
    /// for a simulated sensor.
    pub fn counts(&self, amps: f64) -> u16 {
        let c = amps * 16_777_216.0 / self.scale_q24 as f64 + self.offset_q8 as f64 / 256.0;
        libm::round(c).clamp(0.0, ADC_COUNTS - 1.0) as u16
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_current_sense_is_the_former_board_constant() {
        // The firmware multiplied counts by 77 (I16F16 bits of A per count): the same bits.
        let s = Calibration::DEFAULT.current_sense();
        for c in [0u16, 1, 847, 2541, 4095] {
            assert_eq!(s.amps(c).to_bits(), i32::from(c) * 77, "{c}");
        }
        // An offset of 100.5 counts and 1e-3 A a count: 1100.5 counts is 1.000 A (Q16 floor).
        let mut cal = Calibration::DEFAULT;
        cal.current_offset = 100.5;
        cal.current_scale = 1e-3;
        let a = cal.current_sense().amps(1100).to_num::<f64>() + 0.5e-3;
        assert!((a - 1.0).abs() < 2e-5, "{a}");
        assert_eq!(cal.current_sense().counts(1.0), 1101);
    }

    #[test]
    fn signs_turn_angles_round() {
        let mut cal = Calibration::DEFAULT;
        let q = Angle::QUARTER_TURN;
        assert_eq!(cal.crank_angle(q), q);
        cal.crank_sign = -1;
        assert_eq!(cal.crank_angle(q), Angle::ZERO - q);
        // Zero at count 4096 (a quarter turn), reversed: count 0 is +90°.
        cal.pendulum_zero = 4096;
        cal.pendulum_sign = -1;
        assert_eq!(cal.pendulum_angle(0), q);
    }

    #[test]
    fn refuses_each_field_by_name() {
        type Spoil = fn(&mut Calibration);
        let cases: [(&str, Spoil); 9] = [
            ("pendulum_zero", |c| c.pendulum_zero = 16_384),
            ("pendulum_sign", |c| c.pendulum_sign = 0),
            ("crank_sign", |c| c.crank_sign = 2),
            ("servo_pulse_us", |c| c.servo.min_us = c.servo.max_us),
            ("servo_range_deg", |c| c.servo.range_deg = 0.0),
            ("servo_centre_deg", |c| c.servo.centre_deg = f64::NAN),
            ("current_offset", |c| c.current_offset = -1.0),
            ("current_scale", |c| c.current_scale = 0.0),
            ("hysteresis", |c| c.estimator.hysteresis = 0.0),
        ];
        assert!(Calibration::DEFAULT.validate().is_ok());
        for (name, spoil) in cases {
            let mut c = Calibration::DEFAULT;
            spoil(&mut c);
            assert_eq!(c.validate().unwrap_err().name, name);
        }
    }
}
