//! The safety ranges of the configuration fields that guard the rig, declared once: numbers
//! only, so the firmware carries no names or reasons (the host pairs each row with its key,
//! unit and why). [`RigConfig::validate`] checks them first; [`repair`] gives a stored record's
//! out-of-range fields their defaults and keeps the rest.
//!
//! Every range is closed or half-open in the field's own unit (ms, Hz, rad/s, rad/s², deg,
//! deg/s, A, or 1); docs/rig.md shows the table with its reasons.

use super::config::RigConfig;
use crate::link::origin::FieldSet;
use crate::link::reason::ConfigField;

/// One end of a range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum End {
    /// The value itself is allowed.
    Closed(f64),
    /// Only values strictly beyond it are.
    Open(f64),
}

impl End {
    pub fn value(self) -> f64 {
        match self {
            End::Closed(x) | End::Open(x) => x,
        }
    }
}

/// A field and the range that keeps its function on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    pub field: ConfigField,
    pub lo: End,
    pub hi: End,
}

impl Bound {
    /// Whether `v` (finite, in the field's unit) is inside the range.
    pub fn admits(&self, v: f64) -> bool {
        let above = match self.lo {
            End::Closed(a) => v >= a,
            End::Open(a) => v > a,
        };
        let below = match self.hi {
            End::Closed(b) => v <= b,
            End::Open(b) => v < b,
        };
        v.is_finite() && above && below
    }
}

const fn row(field: ConfigField, lo: End, hi: End) -> Bound {
    Bound { field, lo, hi }
}

use End::{Closed, Open};

/// The table: each guarding field and its range (docs/rig.md, "Safety limits").
pub const BOUNDS: [Bound; 14] = [
    row(ConfigField::LinkTimeoutMs, Closed(500.0), Closed(10_000.0)),
    row(ConfigField::ControlHz, Closed(100.0), Closed(12_000.0)),
    row(
        ConfigField::SampleHz,
        Closed(super::config::MIN_SAMPLE_HZ as f64),
        Closed(super::config::MAX_SAMPLE_HZ as f64),
    ),
    row(ConfigField::OmegaMax, Open(0.0), Closed(1_000.0)),
    row(ConfigField::OmegaRateMax, Closed(10.0), Closed(1_000.0)),
    row(ConfigField::DriveAngleMin, Closed(-180.0), Closed(180.0)),
    row(ConfigField::DriveAngleMax, Closed(0.0), Closed(360.0)),
    row(ConfigField::DriveAngleRateMax, Closed(1.0), Closed(360.0)),
    row(ConfigField::CurrentMax, Open(0.0), Closed(6.0)),
    row(ConfigField::OvercurrentMs, Closed(1.0), Closed(1_000.0)),
    row(ConfigField::StallMinOmega, Open(0.0), Closed(100.0)),
    row(ConfigField::StallFraction, Closed(0.05), Closed(0.9)),
    row(ConfigField::StallMs, Closed(50.0), Closed(2_000.0)),
    row(ConfigField::DutyMax, Open(0.0), Closed(1.0)),
];

/// The table's row for `field`, if it has one.
pub fn bound(field: ConfigField) -> Option<&'static Bound> {
    BOUNDS.iter().find(|b| b.field == field)
}

/// The value of a table field in `cfg` (in the table's unit); `None` for a field without a row.
pub fn value(cfg: &RigConfig, field: ConfigField) -> Option<f64> {
    let l = &cfg.limits;
    Some(match field {
        ConfigField::LinkTimeoutMs => f64::from(l.link_timeout_ms),
        ConfigField::ControlHz => f64::from(cfg.control_hz),
        ConfigField::SampleHz => f64::from(cfg.sample_hz),
        ConfigField::OmegaMax => l.omega_max,
        ConfigField::OmegaRateMax => l.omega_rate_max,
        ConfigField::DriveAngleMin => l.drive_angle_min_deg,
        ConfigField::DriveAngleMax => l.drive_angle_max_deg,
        ConfigField::DriveAngleRateMax => l.drive_angle_rate_max_deg,
        ConfigField::CurrentMax => l.current_max,
        ConfigField::OvercurrentMs => f64::from(l.overcurrent_ms),
        ConfigField::StallMinOmega => l.stall_min_omega,
        ConfigField::StallFraction => l.stall_fraction,
        ConfigField::StallMs => f64::from(l.stall_ms),
        ConfigField::DutyMax => l.duty_max,
        _ => return None,
    })
}

/// The first table field of `cfg` outside its range, with its value.
pub fn check(cfg: &RigConfig) -> Result<(), (ConfigField, f64)> {
    for b in &BOUNDS {
        if let Some(v) = value(cfg, b.field) {
            if !b.admits(v) {
                return Err((b.field, v));
            }
        }
    }
    Ok(())
}

/// `field` of `cfg` set back to [`RigConfig::REFERENCE`]'s.
pub fn restore_default(cfg: &mut RigConfig, field: ConfigField) {
    use ConfigField as F;
    let d = RigConfig::REFERENCE;
    let (l, dl) = (&mut cfg.limits, &d.limits);
    let (m, dm) = (&mut cfg.motor, &d.motor);
    let (c, dc) = (&mut cfg.calibration, &d.calibration);
    let (e, de) = (&mut c.estimator, &dc.estimator);
    match field {
        F::Amplitude => cfg.amplitude = d.amplitude,
        F::Geometry => cfg.geometry = d.geometry,
        F::Gravity => cfg.gravity = d.gravity,
        F::OmegaMax => l.omega_max = dl.omega_max,
        F::OmegaRateMax => l.omega_rate_max = dl.omega_rate_max,
        F::DriveAngleRateMax => l.drive_angle_rate_max_deg = dl.drive_angle_rate_max_deg,
        F::CurrentMax => l.current_max = dl.current_max,
        F::StallMinOmega => l.stall_min_omega = dl.stall_min_omega,
        F::StallFraction => l.stall_fraction = dl.stall_fraction,
        F::OmegaPerDuty => m.omega_per_duty = dm.omega_per_duty,
        F::Lag => m.lag = dm.lag,
        F::Kp => m.kp = dm.kp,
        F::Ki => m.ki = dm.ki,
        F::MaxCorrection => m.max_correction = dm.max_correction,
        F::SampleHz => cfg.sample_hz = d.sample_hz,
        F::DutyMax => l.duty_max = dl.duty_max,
        F::PendulumZero => c.pendulum_zero = dc.pendulum_zero,
        F::PendulumSign => c.pendulum_sign = dc.pendulum_sign,
        F::CrankSign => c.crank_sign = dc.crank_sign,
        F::ServoPulse => {
            c.servo.min_us = dc.servo.min_us;
            c.servo.max_us = dc.servo.max_us;
        }
        F::ServoRange => c.servo.range_deg = dc.servo.range_deg,
        F::ServoCentre => c.servo.centre_deg = dc.servo.centre_deg,
        F::CurrentOffset => c.current_offset = dc.current_offset,
        F::CurrentScale => c.current_scale = dc.current_scale,
        F::Hysteresis => e.hysteresis = de.hysteresis,
        F::MinSwing => e.min_swing = de.min_swing,
        F::SettleBand => e.settle_band = de.settle_band,
        F::BlockS => e.block_s = de.block_s,
        F::QuietBlocks => e.quiet_blocks = de.quiet_blocks,
        F::ClosedLoopBand => cfg.closed_loop.band = d.closed_loop.band,
        F::ClosedLoopRateMax => cfg.closed_loop.rate_max = d.closed_loop.rate_max,
        F::ConnectingRod => cfg.connecting_rod = d.connecting_rod,
        F::ControlHz => cfg.control_hz = d.control_hz,
        F::OvercurrentMs => l.overcurrent_ms = dl.overcurrent_ms,
        F::StallMs => l.stall_ms = dl.stall_ms,
        F::LinkTimeoutMs => l.link_timeout_ms = dl.link_timeout_ms,
        F::DriveAngleMin => l.drive_angle_min_deg = dl.drive_angle_min_deg,
        F::DriveAngleMax => l.drive_angle_max_deg = dl.drive_angle_max_deg,
        F::Other => {}
    }
}

/// A configuration `validate` refuses, made valid by giving each refused field its default in
/// turn: the valid configuration and the fields that took their defaults. When a field is
/// refused again after its default (two fields that only fail together), everything but the
/// calibration and the closed loop takes its default. `Err` names the field that no default
/// repairs.
pub fn repair(cfg: RigConfig) -> Result<(RigConfig, FieldSet), ConfigField> {
    let stored = cfg;
    let mut cfg = cfg;
    let mut defaulted = FieldSet::EMPTY;
    let mut last = ConfigField::Other;
    for _ in 0..ConfigField::ALL.len() {
        match cfg.validate() {
            Ok(c) => return Ok((c, defaulted)),
            Err(e) => {
                last = ConfigField::from_param_name(e.name);
                if last == ConfigField::Other || defaulted.contains(last) {
                    break;
                }
                restore_default(&mut cfg, last);
                defaulted.insert(last);
            }
        }
    }
    let kept = RigConfig {
        calibration: cfg.calibration,
        closed_loop: cfg.closed_loop,
        ..RigConfig::REFERENCE
    };
    let kept = kept.validate().map_err(|_| last)?;
    for f in ConfigField::ALL {
        let mut c = stored;
        restore_default(&mut c, f);
        let calibration = c.calibration != stored.calibration || c.closed_loop != stored.closed_loop;
        if !calibration && !same(&c, &stored) {
            defaulted.insert(f);
        }
    }
    Ok((kept, defaulted))
}

/// Equal field for field, a NaN equal to itself: compared as their wire images' bytes.
fn same(a: &RigConfig, b: &RigConfig) -> bool {
    use crate::link::WireConfig;
    use postcard::experimental::max_size::MaxSize;
    let mut x = [0u8; WireConfig::POSTCARD_MAX_SIZE];
    let mut y = [0u8; WireConfig::POSTCARD_MAX_SIZE];
    match (
        postcard::to_slice(&WireConfig::from(*a), &mut x),
        postcard::to_slice(&WireConfig::from(*b), &mut y),
    ) {
        (Ok(p), Ok(q)) => p == q,
        _ => false,
    }
}
