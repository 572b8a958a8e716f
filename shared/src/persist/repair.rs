//! A stored configuration that [`RigConfig::validate`] refuses, made valid field by field: each
//! refused field takes its default ([`RigConfig::REFERENCE`]'s), the rest is kept.

use crate::link::origin::FieldSet;
use crate::link::reason::ConfigField;
use crate::rig::config::RigConfig;

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
    // A field took its default when setting it back changes the record: equal field for field,
    // a NaN equal to itself, is compared as the wire images' bytes. The stored image is made
    // once, outside the loop.
    let mut x = [0u8; IMAGE];
    let mut y = [0u8; IMAGE];
    let before = image(&stored, &mut x);
    for f in ConfigField::ALL {
        let mut c = stored;
        restore_default(&mut c, f);
        let calibration =
            c.calibration != stored.calibration || c.closed_loop != stored.closed_loop;
        if !calibration && (before.is_none() || image(&c, &mut y) != before) {
            defaulted.insert(f);
        }
    }
    Ok((kept, defaulted))
}

const IMAGE: usize =
    <crate::link::WireConfig as postcard::experimental::max_size::MaxSize>::POSTCARD_MAX_SIZE;

/// `cfg`'s wire image in `buf` (None if it does not serialise). Never inlined: one copy of the
/// conversion and serialiser serves both calls above (inlined, each call carried its own).
#[inline(never)]
fn image<'a>(cfg: &RigConfig, buf: &'a mut [u8; IMAGE]) -> Option<&'a [u8]> {
    postcard::to_slice(&crate::link::WireConfig::from(*cfg), buf)
        .ok()
        .map(|s| &*s)
}
