//! The rig configuration, defined once: stroke, pendulum, gravity, limits, motor and loop rates.
//!
//! It is plain `Copy` data so the firmware can persist it as is and the simulated rig can share
//! it. Checked once by [`RigConfig::validate`]; everything derived from it for the fixed-point
//! code comes from [`RigConfig::derived`].
//!
//! ```text
//! R = A²ω²/(2gℓ) · G  ⇔  ω = ωc √(R/G),  ωc = √(2gℓ)/A     (physics §3, §5.1)
//! A: amplitude of the pivot's motion, half its peak-to-peak stroke (the crank radius)
//! G = 1 + (A/2b)² with a connecting rod b (model::slider_crank), else 1
//! ```
//! R is the drive strength the averaged theory sees: the one a demo asks for and the rig
//! measures in situ.

use super::calibration::Calibration;
use super::closed_loop::ClosedLoopR;
use super::fixed::{Angle, RadPerSec};
use crate::error::{positive, ParamError};
use crate::model::groups::omega_for_r;
use crate::model::slider_crank::SliderCrank;
use crate::model::Geometry;

/// Limits that no command may push the rig past (physics §7, "Safety").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Highest drive angular frequency (rad/s).
    pub omega_max: f64,
    /// Highest |dω/dt| of the drive reference (rad/s²); also the soft start/stop ramp.
    pub omega_rate_max: f64,
    /// Allowed drive angles θd, in degrees, as a closed interval (the actuator mount's travel).
    pub drive_angle_min_deg: f64,
    pub drive_angle_max_deg: f64,
    /// Highest |dθd/dt| (deg/s) of the tilt servo.
    pub drive_angle_rate_max_deg: f64,
    /// Motor over-current threshold (A) and how long it may be exceeded (ms) before a stop.
    pub current_max: f64,
    pub overcurrent_ms: u32,
    /// Stall: commanded speed ≥ `stall_min_omega` while the crank turns slower than
    /// `stall_fraction` of it for `stall_ms`.
    pub stall_min_omega: f64,
    pub stall_fraction: f64,
    pub stall_ms: u32,
    /// The laptop link is silent after this long without a valid message (ms).
    pub link_timeout_ms: u32,
    /// The largest |duty| the drive may command, in (0, 1]: the phase lock is clamped to it,
    /// and a drive that needs it for `stall_ms` is stopped (`Fault::DutyCeiling`).
    pub duty_max: f64,
}

/// The crank motor as the phase lock sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorConfig {
    /// Steady crank speed at full duty (rad/s): the feed-forward's gain.
    pub omega_per_duty: f64,
    /// Speed-loop lag (s): the feed-forward adds τ·dω/dt.
    pub lag: f64,
    /// Phase-lock proportional gain (1/s) and integral gain (1/s²) on the phase error.
    pub kp: f64,
    pub ki: f64,
    /// Largest speed correction (rad/s) the phase loop may add to the feed-forward.
    pub max_correction: f64,
}

/// The rig: everything the logic needs to know about the hardware, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigConfig {
    /// Drive amplitude A (m): half the peak-to-peak stroke.
    pub amplitude: f64,
    /// The connecting rod b (m) from the crank pin to the carriage, whose second harmonic
    /// (A²/4b) cos 2ψ raises R by (A/2b)² and pushes the slow angle ([`SliderCrank`]); 0 for a
    /// pure sine (a scotch yoke or a cam).
    pub connecting_rod: f64,
    pub geometry: Geometry,
    pub gravity: f64,
    pub limits: Limits,
    pub motor: MotorConfig,
    /// Pendulum sample and DDS tick rate (Hz); control and safety tick rate (Hz). The sample rate
    /// must be a multiple of the control rate.
    pub sample_hz: u32,
    pub control_hz: u32,
    /// The bench's measured constants (sensor zero and signs, servo map, current sense,
    /// estimator thresholds).
    pub calibration: Calibration,
    /// Closing the loop on R (off by default).
    pub closed_loop: ClosedLoopR,
}

/// Fixed-point constants derived from a validated configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Derived {
    /// ω0² = g/ℓ (1/s²), I16F16.
    pub omega0_sq: RadPerSec,
    /// A/ℓ in Q30 (I2F30): the fast wobble's scale.
    pub a_over_ell: super::fixed::Unit,
    /// Samples per control tick.
    pub samples_per_control: u32,
    /// The DDS rate limit in frequency words per sample tick.
    pub dds_step: u32,
    pub theta_d_min: Angle,
    pub theta_d_max: Angle,
}

impl RigConfig {
    /// The reference demo rig: a 25 cm uniform rod on a 10 mm crank (ωc = 180.8 rad/s, so
    /// R = 3 at ω = 313 rad/s, 50 Hz), a brushed motor reaching 500 rad/s at full duty.
    pub const REFERENCE: Self = Self {
        amplitude: 0.010,
        connecting_rod: 0.0,
        geometry: Geometry::Rod { length: 0.25 },
        gravity: 9.81,
        limits: Limits {
            omega_max: 420.0,
            omega_rate_max: 60.0,
            drive_angle_min_deg: -10.0,
            drive_angle_max_deg: 190.0,
            drive_angle_rate_max_deg: 30.0,
            current_max: 3.0,
            overcurrent_ms: 20,
            stall_min_omega: 20.0,
            stall_fraction: 0.3,
            stall_ms: 300,
            link_timeout_ms: 1000,
            duty_max: 1.0,
        },
        motor: MotorConfig {
            omega_per_duty: 500.0,
            lag: 0.05,
            kp: 8.0,
            ki: 16.0,
            max_correction: 40.0,
        },
        sample_hz: 10_000,
        control_hz: 1_000,
        calibration: Calibration::DEFAULT,
        closed_loop: ClosedLoopR::DEFAULT,
    };

    /// Checks every number once; the rest of the rig logic relies on it.
    pub fn validate(self) -> Result<Self, ParamError> {
        // The safety ranges first (rig::fields): a refusal names the field the table names.
        if let Err((field, value)) = super::fields::check(&self) {
            return Err(too_big(field.name(), value, SAFETY_RANGE));
        }
        positive("amplitude", self.amplitude)?;
        positive("gravity", self.gravity)?;
        // The expansion A cos ψ + (A²/4b) cos 2ψ needs b well past the crank radius; below 2A
        // the carriage could not follow the crank at all.
        if !(self.connecting_rod == 0.0
            || (self.connecting_rod.is_finite() && self.connecting_rod > 2.0 * self.amplitude))
        {
            return Err(too_big(
                "connecting_rod",
                self.connecting_rod,
                "0 (a pure sine) or longer than 2 amplitudes (m)",
            ));
        }
        // A decoded configuration builds the body as a literal: check it as its constructor would.
        self.geometry.validate()?;
        let ell = positive("equivalent length", self.geometry.equivalent_length())?;
        // The fixed-point constants of `derived` saturate or round to 0 rather than fail: keep
        // ℓ, A/ℓ and ω0² = g/ℓ inside their formats.
        if ell >= Q16_MAX {
            return Err(too_big("equivalent length", ell, "below 32768 m (I16F16)"));
        }
        if self.amplitude / ell >= 2.0 {
            return Err(too_big(
                "amplitude",
                self.amplitude,
                "below 2 equivalent lengths (A/l in I2F30)",
            ));
        }
        let omega0_sq = self.gravity / ell;
        if !(1.0 / 65_536.0..Q16_MAX).contains(&omega0_sq) {
            return Err(too_big(
                "gravity",
                self.gravity,
                "with g/l in [2^-16, 32768) 1/s^2 (omega0^2 in I16F16)",
            ));
        }
        let l = &self.limits;
        positive("omega_max", l.omega_max)?;
        if l.omega_max >= 30_000.0 {
            return Err(too_big(
                "omega_max",
                l.omega_max,
                "below 30000 rad/s (I16F16)",
            ));
        }
        if l.omega_max >= crate::math::PI * f64::from(self.control_hz) {
            return Err(too_big(
                "omega_max",
                l.omega_max,
                "below pi*control_hz, where the crank speed measurement aliases",
            ));
        }
        // A stall detector that arms only above the highest speed never arms.
        if l.stall_min_omega >= l.omega_max {
            return Err(too_big(
                "stall_min_omega",
                l.stall_min_omega,
                "below omega_max (else the stall detector never arms)",
            ));
        }
        positive("omega_rate_max", l.omega_rate_max)?;
        if super::dds::step_from_rate(l.omega_rate_max, self.sample_hz.max(1)) == 0 {
            return Err(too_big(
                "omega_rate_max",
                l.omega_rate_max,
                "at least one frequency word per tick, 2*pi*sample_hz/65536 rad/s^2",
            ));
        }
        positive("drive_angle_rate_max_deg", l.drive_angle_rate_max_deg)?;
        q16("current_max", l.current_max)?;
        q16("stall_min_omega", l.stall_min_omega)?;
        // The stall test multiplies the commanded speed by this fraction in i64 (Q16): above 1
        // it means nothing, and far above it the product overflows.
        if positive("stall_fraction", l.stall_fraction)? > 1.0 {
            return Err(too_big(
                "stall_fraction",
                l.stall_fraction,
                "a fraction in (0, 1]",
            ));
        }
        if !(l.drive_angle_min_deg.is_finite()
            && l.drive_angle_max_deg.is_finite()
            && l.drive_angle_min_deg < l.drive_angle_max_deg
            && l.drive_angle_max_deg - l.drive_angle_min_deg < 360.0)
        {
            return Err(too_big(
                "drive_angle_max_deg",
                l.drive_angle_max_deg,
                "finite, above drive_angle_min_deg, and less than a turn from it",
            ));
        }
        if !(l.duty_max.is_finite() && l.duty_max > 0.0 && l.duty_max <= 1.0) {
            return Err(too_big("duty_max", l.duty_max, "a fraction in (0, 1]"));
        }
        // The duty conversion multiplies by 2^30/omega_per_duty in i64: at least 1 rad/s keeps
        // the product below 2^61.
        if positive("omega_per_duty", self.motor.omega_per_duty)? < 1.0 {
            return Err(too_big(
                "omega_per_duty",
                self.motor.omega_per_duty,
                "at least 1 rad/s",
            ));
        }
        // The phase lock holds these in I16F16; a gain below one LSB would be 0 (and ki = 0
        // divides by zero in the anti-windup limit).
        q16("lag", self.motor.lag)?;
        q16("kp", self.motor.kp)?;
        q16("ki", self.motor.ki)?;
        q16("max_correction", self.motor.max_correction)?;
        if self.control_hz == 0
            || !self.sample_hz.is_multiple_of(self.control_hz)
            || !(MIN_SAMPLE_HZ..=MAX_SAMPLE_HZ).contains(&self.sample_hz)
        {
            return Err(too_big(
                "sample_hz",
                f64::from(self.sample_hz),
                "a multiple of control_hz, from 1 kHz to 12 kHz (the firmware's sample budget)",
            ));
        }
        self.calibration.validate()?;
        self.closed_loop.validate()?;
        Ok(self)
    }

    /// Equivalent length ℓ (m).
    pub fn ell(&self) -> f64 {
        self.geometry.equivalent_length()
    }

    /// The slider-crank, if the drive has a connecting rod.
    pub fn slider_crank(&self) -> Option<SliderCrank> {
        (self.connecting_rod > 0.0).then(|| SliderCrank {
            amplitude: self.amplitude,
            rod: self.connecting_rod,
            ell: self.ell(),
        })
    }

    /// R_e / R of the first harmonic alone: 1 + (A/2b)², or 1 for a pure sine.
    pub fn strength_gain(&self) -> f64 {
        self.slider_crank().map_or(1.0, |c| c.strength_gain())
    }

    /// ω that gives drive strength R with this stroke and pendulum: ω = ωc √(R/G).
    pub fn omega_for_r(&self, r: f64) -> Result<f64, ParamError> {
        omega_for_r(r, self.ell(), self.gravity, self.amplitude)
            .map(|w| w / crate::math::sqrt(self.strength_gain()))
    }

    /// R = G A²ω²/(2gℓ) at drive ω.
    pub fn r_for_omega(&self, omega: f64) -> f64 {
        self.strength_gain() * self.amplitude * self.amplitude * omega * omega
            / (2.0 * self.gravity * self.ell())
    }

    /// ω0 = √(g/ℓ).
    pub fn omega0(&self) -> f64 {
        crate::math::sqrt(self.gravity / self.ell())
    }

    pub fn derived(&self) -> Derived {
        Derived {
            omega0_sq: RadPerSec::saturating_from_num(self.gravity / self.ell()),
            a_over_ell: super::fixed::Unit::saturating_from_num(self.amplitude / self.ell()),
            samples_per_control: self.sample_hz / self.control_hz.max(1),
            dds_step: super::dds::step_from_rate(self.limits.omega_rate_max, self.sample_hz),
            theta_d_min: Angle::from_deg(self.limits.drive_angle_min_deg),
            theta_d_max: Angle::from_deg(self.limits.drive_angle_max_deg),
        }
    }
}

/// What a refusal by the safety table allows; the host says the range itself.
const SAFETY_RANGE: &str = "the range in docs/rig.md, \"Safety limits\"";

/// The end of the I16F16 range (RadPerSec, Amps, Ratio).
const Q16_MAX: f64 = 32_768.0;

/// The fastest sample rate the firmware keeps up with. Its worst sample must end before the
/// next one starts (docs/accuracy-mcu.md, "The budget", at CPI 2.0): the estimator's slow
/// update at the end of a drive period (≈ 48 µs), up to three sensor frames with their
/// chip-select times (≈ 3 × 4 µs, `rig::as5047`), the control tick (≈ 5.4 µs) and the time
/// driver's interrupt (≈ 1 µs): ≈ 66 µs, so 1/fs ≥ 66 µs, fs ≤ 15 kHz; 12 kHz keeps a fifth
/// in reserve. A configuration above it would be stored and then overrun at every boot.
pub const MAX_SAMPLE_HZ: u32 = 12_000;
/// The slowest: at 1 kHz the sample is the control tick, and a 67 Hz drive period still has
/// 15 samples for the synchronous average.
pub const MIN_SAMPLE_HZ: u32 = 1_000;

/// A positive number that I16F16 holds without saturating to its end or rounding to 0.
fn q16(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() && (1.0 / 65_536.0..Q16_MAX).contains(&value) {
        Ok(value)
    } else {
        Err(too_big(name, value, "a number in [2^-16, 32768) (I16F16)"))
    }
}

/// A refusal of `name` = `value`, saying what is allowed.
pub(crate) fn too_big(name: &'static str, value: f64, allowed: &'static str) -> ParamError {
    ParamError {
        name,
        value,
        allowed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_rig_numbers() {
        // Closed forms, physics §3: ℓ = 2L/3 = 0.1667 m, ωc = √(2gℓ)/A = 180.83 rad/s,
        // so R = 3 at ω = ωc√3 = 313.2 rad/s; ω0 = √(g/ℓ) = 7.672 rad/s.
        let c = RigConfig::REFERENCE.validate().unwrap();
        let w = c.omega_for_r(3.0).unwrap();
        assert!((w - 180.83 * 3f64.sqrt()).abs() < 0.01, "{w}");
        assert!((c.r_for_omega(w) - 3.0).abs() < 1e-12);
        assert!((c.omega0() - 7.672).abs() < 1e-3);
        let d = c.derived();
        assert_eq!(d.samples_per_control, 10);
        assert!((d.omega0_sq.to_num::<f64>() - 58.86).abs() < 1e-4);
    }

    #[test]
    fn rejects_bad_configs() {
        let mut c = RigConfig::REFERENCE;
        c.amplitude = 0.0;
        assert_eq!(c.validate().unwrap_err().name, "amplitude");
        let mut c = RigConfig::REFERENCE;
        c.sample_hz = 10_001;
        assert_eq!(c.validate().unwrap_err().name, "sample_hz");
        // Multiples of control_hz (1 kHz) on either side of the range [1 kHz, 12 kHz].
        for (hz, ok) in [
            (100_000, false),
            (13_000, false),
            (12_000, true),
            (1_000, true),
        ] {
            let mut c = RigConfig::REFERENCE;
            c.sample_hz = hz;
            assert_eq!(c.validate().is_ok(), ok, "{hz}");
        }
        let mut c = RigConfig::REFERENCE;
        c.limits.drive_angle_min_deg = 170.0;
        c.limits.drive_angle_max_deg = 160.0;
        assert_eq!(c.validate().unwrap_err().name, "drive_angle_max_deg");
        for d in [0.0, -0.5, 1.01, f64::NAN] {
            let mut c = RigConfig::REFERENCE;
            c.limits.duty_max = d;
            assert_eq!(c.validate().unwrap_err().name, "duty_max", "{d}");
        }
        let mut c = RigConfig::REFERENCE;
        c.calibration.crank_sign = 0;
        assert_eq!(c.validate().unwrap_err().name, "crank_sign");
        let mut c = RigConfig::REFERENCE;
        c.closed_loop.rate_max = 0.0;
        assert_eq!(c.validate().unwrap_err().name, "closed_loop_rate_max");
        assert!(RigConfig::REFERENCE.omega_for_r(-1.0).is_err());
        for (rod, ok) in [(0.0, true), (0.05, true), (0.02, false), (-0.05, false)] {
            let mut c = RigConfig::REFERENCE;
            c.connecting_rod = rod;
            assert_eq!(c.validate().is_ok(), ok, "{rod}");
        }
        let mut c = RigConfig::REFERENCE;
        c.connecting_rod = f64::NAN;
        assert_eq!(c.validate().unwrap_err().name, "connecting_rod");
    }

    #[test]
    fn a_connecting_rod_raises_r_by_its_gain() {
        // physics §5.1: a 10 mm crank on a 50 mm rod, G = 1 + (10/100)² = 1.01; the ω for an R
        // falls by √G, and R at that ω is R again.
        let mut c = RigConfig::REFERENCE;
        c.connecting_rod = 0.05;
        let c = c.validate().unwrap();
        let w = c.omega_for_r(3.0).unwrap();
        let pure = RigConfig::REFERENCE.omega_for_r(3.0).unwrap();
        assert!((w - pure / 1.01f64.sqrt()).abs() < 1e-9, "{w} vs {pure}");
        assert!((c.r_for_omega(w) - 3.0).abs() < 1e-12);
    }
}
