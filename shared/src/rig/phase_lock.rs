//! Locking the crank motor's phase to the drive reference.
//!
//! The motor is reached through the three-method [`Motor`] trait — the firmware implements it on
//! the encoder timer, the current ADC and the H-bridge PWM; the closed-loop tests implement it on
//! a simulated motor — and the controller itself is a pure function of the numbers it is given.
//!
//! ```text
//! e      = wrap(φ_ref − φ_crank)                       phase error, rad, in (−π, π]
//! ∫e    += e / fc                                       clamped so |ki·∫e| ≤ c_max (anti-windup)
//! ω_cmd  = ω_ref + τ·α_ref  +  clamp(kp·e + ki·∫e, ±c_max)
//! duty   = clamp(ω_cmd / ω_full, ±duty_max)              (duty_max ≤ 1: the configured ceiling)
//! ```
//! Feed-forward ω_ref + τ·α_ref does nearly all the work (τ: the motor's speed lag, so a ramp is
//! led by τ·dω/dt); the PI on the phase error removes what it misses (gain error, load, friction).
//! Loop: motor ω/ω_cmd = 1/(1 + τs), phase = ω/s, so the open loop is (kp + ki/s)/(s(1 + τs)).
//! With kp = 8/s, ki = 16/s², τ = 50 ms it crosses over near 8 rad/s with ≈ 60° of phase margin
//! (the PI zero at ki/kp = 2 rad/s sits well below, the lag pole at 20 rad/s above), and a
//! constant gain error leaves no steady phase error (the integrator holds it).
//!
//! The crank speed (for the stall guard) is the wrapped encoder difference per control tick, so
//! it is unambiguous below half a turn per tick: |ω| < π·fc = 3142 rad/s at 1 kHz, 7× ω_max
//! (checked by [`RigConfig::validate`]).

use super::config::RigConfig;
use super::fixed::{Amps, Angle, Duty, RadPerSec};

/// The crank motor seen by the phase lock: read the crank angle, read the current, command duty.
pub trait Motor {
    /// Crank angle from the encoder, wrapping (one turn = 2^32); the pivot is at A·cos of it.
    fn crank_angle(&mut self) -> Angle;
    /// Motor current (A), for the over-current guard.
    fn current(&mut self) -> Amps;
    /// H-bridge command in [−1, 1); 0 stops driving.
    fn set_duty(&mut self, duty: Duty);
}

/// Phase-lock controller state, all fixed-point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PhaseLock {
    kp: RadPerSec,
    ki: RadPerSec,
    lag: RadPerSec,
    max_corr: RadPerSec,
    /// 1/ω_full in Q30 (s/rad).
    inv_full_q30: i64,
    fc: u32,
    /// The duty ceiling in I1F15 bits.
    duty_max: i64,
    /// ∫e dt in rad·s, I16F16.
    integral: RadPerSec,
    last_crank: Option<Angle>,
    crank_speed: RadPerSec,
    error: RadPerSec,
}

/// What one control tick decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LockOutput {
    pub duty: Duty,
    /// Phase error φ_ref − φ_crank (rad, I16F16).
    pub error: RadPerSec,
    /// Crank speed from successive encoder angles (rad/s).
    pub crank_speed: RadPerSec,
    /// The commanded speed before the duty conversion (rad/s).
    pub omega_cmd: RadPerSec,
    /// The duty is clamped at the ceiling.
    pub saturated: bool,
}

impl PhaseLock {
    pub fn new(cfg: &RigConfig) -> Self {
        let m = &cfg.motor;
        Self {
            kp: RadPerSec::saturating_from_num(m.kp),
            ki: RadPerSec::saturating_from_num(m.ki),
            lag: RadPerSec::saturating_from_num(m.lag),
            max_corr: RadPerSec::saturating_from_num(m.max_correction),
            inv_full_q30: libm::round((1u64 << 30) as f64 / m.omega_per_duty) as i64,
            fc: cfg.control_hz.max(1),
            duty_max: (libm::round(cfg.limits.duty_max * 32_768.0) as i64).clamp(1, 32_767),
            integral: RadPerSec::ZERO,
            last_crank: None,
            crank_speed: RadPerSec::ZERO,
            error: RadPerSec::ZERO,
        }
    }

    /// Forget the integrator (after a stop or a fault).
    pub fn reset(&mut self) {
        self.integral = RadPerSec::ZERO;
        self.error = RadPerSec::ZERO;
    }

    pub fn crank_speed(&self) -> RadPerSec {
        self.crank_speed
    }

    /// Measures the crank speed from the new encoder angle: wrap(Δφ)·fc. Call once per tick.
    fn measure(&mut self, crank: Angle) {
        if let Some(prev) = self.last_crank {
            let d = i64::from((crank - prev).to_rad_q().to_bits()); // Q28 rad
            let v = (d * i64::from(self.fc)) >> 12; // Q16 rad/s
            self.crank_speed = RadPerSec::from_bits(super::fixed::approx::sat_i32(v));
        }
        self.last_crank = Some(crank);
    }

    /// One control tick. `active` false (stopped or faulted) gives duty 0 and resets the loop.
    pub fn update(
        &mut self,
        active: bool,
        ref_phase: Angle,
        ref_omega: RadPerSec,
        ref_accel: RadPerSec,
        crank: Angle,
    ) -> LockOutput {
        self.measure(crank);
        if !active {
            self.reset();
            return LockOutput {
                duty: Duty::ZERO,
                error: RadPerSec::ZERO,
                crank_speed: self.crank_speed,
                omega_cmd: RadPerSec::ZERO,
                saturated: false,
            };
        }
        let e = RadPerSec::from_bits((ref_phase - crank).to_rad_q().to_bits() >> 12);
        self.error = e;
        // ∫e += e/fc, clamped so that ki·∫e stays within ±c_max.
        let step = RadPerSec::from_bits(e.to_bits() / self.fc as i32);
        let lim = self.max_corr.saturating_div(self.ki);
        self.integral = self.integral.saturating_add(step).clamp(-lim, lim);
        let corr = self
            .kp
            .saturating_mul(e)
            .saturating_add(self.ki.saturating_mul(self.integral))
            .clamp(-self.max_corr, self.max_corr);
        let ff = ref_omega.saturating_add(self.lag.saturating_mul(ref_accel));
        let omega_cmd = ff.saturating_add(corr);
        // duty (Q15) = ω_cmd (Q16) · 1/ω_full (Q30) >> 31
        let d = (i64::from(omega_cmd.to_bits()) * self.inv_full_q30) >> 31;
        let duty = Duty::from_bits(d.clamp(-self.duty_max, self.duty_max) as i16);
        LockOutput {
            duty,
            error: e,
            crank_speed: self.crank_speed,
            omega_cmd,
            saturated: d.abs() >= self.duty_max,
        }
    }

    /// [`PhaseLock::update`] against a [`Motor`]: read the crank, command the duty.
    pub fn drive<M: Motor>(
        &mut self,
        motor: &mut M,
        active: bool,
        ref_phase: Angle,
        ref_omega: RadPerSec,
        ref_accel: RadPerSec,
    ) -> LockOutput {
        let crank = motor.crank_angle();
        let out = self.update(active, ref_phase, ref_omega, ref_accel, crank);
        motor.set_duty(out.duty);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feed_forward_alone_at_zero_error() {
        // Zero phase error, steady: duty = ω_ref/ω_full = 314.16/500 = 0.6283 (±2 LSB of Q15).
        let mut pl = PhaseLock::new(&RigConfig::REFERENCE);
        let w = RadPerSec::from_num(314.159);
        let out = pl.update(true, Angle::ZERO, w, RadPerSec::ZERO, Angle::ZERO);
        assert!((out.duty.to_num::<f64>() - 314.159 / 500.0).abs() < 1e-4);
        // Inactive: zero duty, integrator reset.
        let out = pl.update(false, Angle::ZERO, w, RadPerSec::ZERO, Angle::ZERO);
        assert_eq!(out.duty, Duty::ZERO);
    }

    #[test]
    fn the_duty_is_clamped_at_the_configured_ceiling() {
        // Feed-forward alone at ω = 400 rad/s asks for 400/500 = 0.8 of full duty.
        let w = RadPerSec::from_num(400);
        let mut pl = PhaseLock::new(&RigConfig::REFERENCE);
        let out = pl.update(true, Angle::ZERO, w, RadPerSec::ZERO, Angle::ZERO);
        assert!((out.duty.to_num::<f64>() - 0.8).abs() < 1e-4);
        assert!(!out.saturated);
        // With a ceiling of 0.5: clamped to 0.5 (16384 in I1F15), and said so.
        let mut cfg = RigConfig::REFERENCE;
        cfg.limits.duty_max = 0.5;
        let mut pl = PhaseLock::new(&cfg);
        let out = pl.update(true, Angle::ZERO, w, RadPerSec::ZERO, Angle::ZERO);
        assert_eq!(out.duty.to_bits(), 16_384);
        assert!(out.saturated);
        // Backwards too.
        let out = pl.update(true, Angle::ZERO, -w, RadPerSec::ZERO, Angle::ZERO);
        assert_eq!(out.duty.to_bits(), -16_384);
    }

    #[test]
    fn correction_is_bounded_and_integrator_does_not_wind_up() {
        // A stuck crank at a 90° phase error for 100 s: the correction stays at ±c_max (40 rad/s)
        // and the integrator at c_max/ki, so on release it has no stored windup beyond that.
        let cfg = RigConfig::REFERENCE;
        let mut pl = PhaseLock::new(&cfg);
        let w = RadPerSec::from_num(100);
        let mut out = pl.update(true, Angle::ZERO, w, RadPerSec::ZERO, Angle::ZERO);
        for _ in 0..100_000 {
            out = pl.update(true, Angle::QUARTER_TURN, w, RadPerSec::ZERO, Angle::ZERO);
        }
        let cmd: f64 = out.omega_cmd.to_num();
        assert!((cmd - 140.0).abs() < 1e-3, "{cmd}");
        let i: f64 = pl.integral.to_num();
        assert!((i - 40.0 / 16.0).abs() < 1e-3, "{i}");
    }
}
