//! The safety ranges of the configuration fields that guard the rig, declared once: numbers
//! only, so the firmware carries no units or reasons (the host pairs each row with its key,
//! unit and why). [`RigConfig::validate`] checks them first and names the field as every
//! refusal does (its parameter name, which the link's `ConfigField` maps);
//! `persist::repair` gives a stored record's out-of-range fields their defaults.
//!
//! Every range is closed or half-open in the field's own unit (ms, Hz, rad/s, rad/s², deg,
//! deg/s, A, or 1); docs/rig.md shows the table with its reasons.

use super::config::RigConfig;

/// A field with a row in [`BOUNDS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    LinkTimeoutMs,
    ControlHz,
    SampleHz,
    OmegaMax,
    OmegaRateMax,
    DriveAngleMin,
    DriveAngleMax,
    DriveAngleRateMax,
    CurrentMax,
    OvercurrentMs,
    StallMinOmega,
    StallFraction,
    StallMs,
    DutyMax,
}

impl Field {
    /// The name refusals use ([`crate::ParamError::name`]): the field's own in [`RigConfig`].
    pub fn name(self) -> &'static str {
        match self {
            Field::LinkTimeoutMs => "link_timeout_ms",
            Field::ControlHz => "control_hz",
            Field::SampleHz => "sample_hz",
            Field::OmegaMax => "omega_max",
            Field::OmegaRateMax => "omega_rate_max",
            Field::DriveAngleMin => "drive_angle_min_deg",
            Field::DriveAngleMax => "drive_angle_max_deg",
            Field::DriveAngleRateMax => "drive_angle_rate_max_deg",
            Field::CurrentMax => "current_max",
            Field::OvercurrentMs => "overcurrent_ms",
            Field::StallMinOmega => "stall_min_omega",
            Field::StallFraction => "stall_fraction",
            Field::StallMs => "stall_ms",
            Field::DutyMax => "duty_max",
        }
    }
}

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
    pub field: Field,
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

const fn row(field: Field, lo: End, hi: End) -> Bound {
    Bound { field, lo, hi }
}

use End::{Closed, Open};

/// The table: each guarding field and its range (docs/rig.md, "Safety limits").
pub const BOUNDS: [Bound; 14] = [
    row(Field::LinkTimeoutMs, Closed(500.0), Closed(10_000.0)),
    row(Field::ControlHz, Closed(100.0), Closed(12_000.0)),
    row(
        Field::SampleHz,
        Closed(super::config::MIN_SAMPLE_HZ as f64),
        Closed(super::config::MAX_SAMPLE_HZ as f64),
    ),
    row(Field::OmegaMax, Open(0.0), Closed(1_000.0)),
    row(Field::OmegaRateMax, Closed(10.0), Closed(1_000.0)),
    row(Field::DriveAngleMin, Closed(-180.0), Closed(180.0)),
    row(Field::DriveAngleMax, Closed(0.0), Closed(360.0)),
    row(Field::DriveAngleRateMax, Closed(1.0), Closed(360.0)),
    row(Field::CurrentMax, Open(0.0), Closed(6.0)),
    row(Field::OvercurrentMs, Closed(1.0), Closed(1_000.0)),
    row(Field::StallMinOmega, Open(0.0), Closed(100.0)),
    row(Field::StallFraction, Closed(0.05), Closed(0.9)),
    row(Field::StallMs, Closed(50.0), Closed(2_000.0)),
    row(Field::DutyMax, Open(0.0), Closed(1.0)),
];

/// The table's row for `field`.
pub fn bound(field: Field) -> Bound {
    match BOUNDS.iter().find(|b| b.field == field) {
        Some(b) => *b,
        // Every field has its row (tested).
        None => BOUNDS[0],
    }
}

/// The value of a table field in `cfg`, in the table's unit.
pub fn value(cfg: &RigConfig, field: Field) -> f64 {
    let l = &cfg.limits;
    match field {
        Field::LinkTimeoutMs => f64::from(l.link_timeout_ms),
        Field::ControlHz => f64::from(cfg.control_hz),
        Field::SampleHz => f64::from(cfg.sample_hz),
        Field::OmegaMax => l.omega_max,
        Field::OmegaRateMax => l.omega_rate_max,
        Field::DriveAngleMin => l.drive_angle_min_deg,
        Field::DriveAngleMax => l.drive_angle_max_deg,
        Field::DriveAngleRateMax => l.drive_angle_rate_max_deg,
        Field::CurrentMax => l.current_max,
        Field::OvercurrentMs => f64::from(l.overcurrent_ms),
        Field::StallMinOmega => l.stall_min_omega,
        Field::StallFraction => l.stall_fraction,
        Field::StallMs => f64::from(l.stall_ms),
        Field::DutyMax => l.duty_max,
    }
}

/// The first table field of `cfg` outside its range, with its value.
pub fn check(cfg: &RigConfig) -> Result<(), (Field, f64)> {
    for b in &BOUNDS {
        let v = value(cfg, b.field);
        if !b.admits(v) {
            return Err((b.field, v));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_has_one_row_and_the_reference_is_inside() {
        for (i, b) in BOUNDS.iter().enumerate() {
            assert_eq!(bound(b.field), *b);
            assert!(BOUNDS[i + 1..].iter().all(|o| o.field != b.field), "{b:?}");
            assert!(b.admits(value(&RigConfig::REFERENCE, b.field)), "{b:?}");
        }
    }
}
