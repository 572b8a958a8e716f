//! The fixed-point estimator: from pendulum-angle samples and the drive phase, what the pendulum
//! is doing on the slow time scale.
//!
//! | module | concept |
//! |---|---|
//! | [`period`] | synchronous averaging over each drive period: the slow angle φ̄, and the wobble's I/Q |
//! | [`period_f32`] | the same in f32, only for the accuracy-and-cost comparison |
//! | [`swing`] | extrema of φ̄ → slow frequency ωd, decay σ, ωp = √(ωd² + σ²) |
//! | [`settle`] | settled flag, equilibrium angle, R in situ, the wobble's check of A |
//!
//! Per sample it costs one unwrap, one sin/cos and three multiply-accumulates; everything else
//! runs once per drive period. All state is integers; angles are [`Angle`]s and wrap by
//! construction; physical outputs saturate.

pub mod period;
pub mod period_f32;
pub mod settle;
pub mod swing;

use crate::model::RMethod;
use crate::rig::config::RigConfig;
use crate::rig::fixed::{approx, Angle, RadPerSec, Ratio, Unit};
use period::{PeriodAverager, PeriodMean};
use settle::Settle;
use swing::SwingTracker;

/// Thresholds, in physical units (converted once).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tuning {
    /// Hysteresis for declaring an extremum (rad); well above the per-period noise.
    pub hysteresis: f64,
    /// Smallest peak-to-peak swing used for timing (rad).
    pub min_swing: f64,
    /// Settled: per-period means within this band (rad) for `quiet_blocks` blocks of `block_s`.
    pub settle_band: f64,
    pub block_s: f64,
    pub quiet_blocks: u32,
}

impl Tuning {
    /// Defaults for a 12–14-bit angle encoder: noise per period mean ≲ 1e-4 rad, so h = 0.3°.
    pub const DEFAULT: Self = Self {
        hysteresis: 0.3 * crate::math::PI / 180.0,
        min_swing: 1.0 * crate::math::PI / 180.0,
        settle_band: 0.3 * crate::math::PI / 180.0,
        block_s: 1.0,
        quiet_blocks: 2,
    };

    /// Checks every threshold: angles in (0, 0.5] rad (far above a sensor count, far below a
    /// swing), the block in (0, 60] s, 1 to 100 quiet blocks.
    pub fn validate(&self) -> Result<(), crate::ParamError> {
        for (name, v) in [
            ("hysteresis", self.hysteresis),
            ("min_swing", self.min_swing),
            ("settle_band", self.settle_band),
        ] {
            if !(v.is_finite() && v > 0.0 && v <= 0.5) {
                return Err(crate::ParamError {
                    name,
                    value: v,
                    allowed: "an angle in (0, 0.5] rad",
                });
            }
        }
        if !(self.block_s.is_finite() && self.block_s > 0.0 && self.block_s <= 60.0) {
            return Err(crate::ParamError {
                name: "block_s",
                value: self.block_s,
                allowed: "in (0, 60] s",
            });
        }
        if !(1..=100).contains(&self.quiet_blocks) {
            return Err(crate::ParamError {
                name: "quiet_blocks",
                value: f64::from(self.quiet_blocks),
                allowed: "1 to 100 blocks",
            });
        }
        Ok(())
    }
}

/// Everything the estimator knows, after the latest drive period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Estimate {
    /// Drive periods averaged since the last reset.
    pub periods: u32,
    /// Slow angle φ̄ of the latest period.
    pub phi: Angle,
    /// Slow angular velocity (rad/s) from successive periods; saturates.
    pub phi_rate: RadPerSec,
    /// Slow-oscillation frequency ωd (damped) and ωp (undamped), rad/s.
    pub omega_d: Option<RadPerSec>,
    pub omega_p: Option<RadPerSec>,
    /// Decay rate σ (1/s) of the slow amplitude; the damping c = 2σ.
    pub sigma: Option<RadPerSec>,
    pub settled: bool,
    /// The equilibrium angle φ0, once settled.
    pub equilibrium: Option<Angle>,
    /// R in situ and the formula used, once settled.
    pub r: Option<(Ratio, RMethod)>,
    /// Fast-wobble amplitude (rad) over the last quiet block, and the A (m) it implies.
    pub wobble: Option<Unit>,
    pub amplitude: Option<RadPerSec>,
}

/// Radians → 2^-32 turn.
fn rad_to_bits(x: f64) -> i64 {
    libm::round(x / crate::math::TAU * 4_294_967_296.0) as i64
}

/// Angular velocity (rad/s, I16F16) of an angle change `du` (2^-32 turn) over `dt_us`;
/// saturates at ±32768 rad/s, never wraps.
///
/// ```text
/// Q16 rad/s = Δu·(2π/2^32)·(10⁶/Δt)·2^16 = Δu·2π·10⁶/(2^16·Δt)     (2π·10⁶ carried as 6 283 185 307/10³)
/// ```
/// In i128: Δu may be many turns for a rotating pendulum.
pub fn slow_rate(du: i64, dt_us: u32) -> RadPerSec {
    const TWO_PI_E9: i128 = 6_283_185_307;
    let dt = i128::from(dt_us.max(1));
    let v = i128::from(du) * TWO_PI_E9 / (dt * 65_536 * 1000);
    RadPerSec::from_bits(v.clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i32)
}

/// The estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Estimator {
    period: PeriodAverager,
    swing: SwingTracker,
    settle: Settle,
    theta_d: Angle,
    omega0_sq: RadPerSec,
    ell: RadPerSec,
    last: Option<PeriodMean>,
    est: Estimate,
}

impl Estimator {
    pub fn new(cfg: &RigConfig, tuning: &Tuning, theta_d: Angle) -> Self {
        let d = cfg.derived();
        Self {
            period: PeriodAverager::new(),
            swing: SwingTracker::new(
                rad_to_bits(tuning.hysteresis),
                rad_to_bits(tuning.min_swing),
            ),
            settle: Settle::new(
                libm::round(tuning.block_s * 1e6) as u32,
                rad_to_bits(tuning.settle_band).unsigned_abs(),
                tuning.quiet_blocks,
            ),
            theta_d,
            omega0_sq: d.omega0_sq,
            ell: RadPerSec::saturating_from_num(cfg.ell()),
            last: None,
            est: Estimate::default(),
        }
    }

    /// Forget the slow history (the drive changed: ω ramping, θd slewing); averaging goes on.
    pub fn reset_slow(&mut self, theta_d: Angle) {
        self.theta_d = theta_d;
        self.swing.reset();
        self.settle.reset();
        self.est = Estimate {
            phi: self.est.phi,
            ..Estimate::default()
        };
    }

    pub fn estimate(&self) -> &Estimate {
        &self.est
    }

    /// The fast wobble's amplitude (rad, Q30) as the latest drive period's I/Q demodulation
    /// measures it; 0 before a period has completed.
    pub fn wobble_now(&self) -> Unit {
        self.last.map_or(Unit::ZERO, |pm| {
            settle::wobble(pm.i, pm.q, pm.mean, self.theta_d, self.ell).0
        })
    }

    /// One sample: stamp (µs, wrapping), pendulum angle, drive phase. Returns the estimate when
    /// a drive period completes.
    #[inline]
    pub fn push(&mut self, t_us: u32, theta: Angle, drive_phase: Angle) -> Option<&Estimate> {
        let pm = self.period.push(t_us, theta, drive_phase)?;
        self.on_period(&pm);
        Some(&self.est)
    }

    fn on_period(&mut self, pm: &PeriodMean) {
        let e = &mut self.est;
        e.periods = e.periods.saturating_add(1);
        e.phi = pm.mean;
        if let Some(prev) = self.last {
            e.phi_rate = slow_rate(pm.unwrapped.wrapping_sub(prev.unwrapped), pm.dt_us);
        }
        self.last = Some(*pm);
        self.swing.push(pm.unwrapped, pm.t_us);
        self.settle.push(pm);
        e.omega_d = self.swing.omega_d();
        e.sigma = self.swing.sigma();
        let wp2 = self.swing.omega_p_sq();
        e.omega_p = wp2.map(approx::sqrt);
        e.settled = self.settle.settled();
        if let Some(b) = self.settle.block() {
            let phi0 = Angle::from_bits(b.mean as i32); // low 32 bits: the wrapped angle
            e.equilibrium = Some(phi0);
            e.r = settle::r_in_situ(phi0, self.theta_d, wp2, self.omega0_sq);
            let (amp, a) = settle::wobble(b.i, b.q, phi0, self.theta_d, self.ell);
            e.wobble = Some(amp);
            e.amplitude = a;
        } else {
            e.equilibrium = None;
            e.r = None;
            e.wobble = None;
            e.amplitude = None;
        }
    }
}
