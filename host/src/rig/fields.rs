//! The core's safety table ([`kapitza_core::rig::fields::BOUNDS`]) with what the firmware does
//! not carry: each field's key as `config get` prints it, its unit and why its bound is there.
//! The checks of `config set` and of rig files, the status's `config_fallbacks` and the table
//! in docs/rig.md all come from here.

use kapitza_core::error::Compact;
use kapitza_core::link::reason::ConfigField;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::fields::{self, Bound, End, Field, BOUNDS};

/// One row of the table, for a person.
#[derive(Debug, Clone, Copy)]
pub struct Row {
    pub bound: Bound,
    pub key: &'static str,
    pub unit: &'static str,
    pub why: &'static str,
}

/// The key of `field` in the configuration file (`config get` / `config set`).
pub fn key(field: ConfigField) -> &'static str {
    use ConfigField as F;
    match field {
        F::Amplitude => "amplitude",
        F::Geometry => "pendulum",
        F::Gravity => "gravity",
        F::OmegaMax => "limits.omega_max",
        F::OmegaRateMax => "limits.omega_rate_max",
        F::DriveAngleRateMax => "limits.drive_angle_rate_max_deg",
        F::CurrentMax => "limits.current_max",
        F::StallMinOmega => "limits.stall_min_omega",
        F::StallFraction => "limits.stall_fraction",
        F::OmegaPerDuty => "motor.omega_per_duty",
        F::Lag => "motor.lag",
        F::Kp => "motor.kp",
        F::Ki => "motor.ki",
        F::MaxCorrection => "motor.max_correction",
        F::SampleHz => "sample_hz",
        F::DutyMax => "limits.duty_max",
        F::PendulumZero => "calibration.pendulum_zero",
        F::PendulumSign => "calibration.pendulum_sign",
        F::CrankSign => "calibration.crank_sign",
        F::ServoPulse => "calibration.servo_min_us/servo_max_us",
        F::ServoRange => "calibration.servo_range_deg",
        F::ServoCentre => "calibration.servo_centre_deg",
        F::CurrentOffset => "calibration.current_offset",
        F::CurrentScale => "calibration.current_scale",
        F::Hysteresis => "calibration.hysteresis",
        F::MinSwing => "calibration.min_swing",
        F::SettleBand => "calibration.settle_band",
        F::BlockS => "calibration.block_s",
        F::QuietBlocks => "calibration.quiet_blocks",
        F::ClosedLoopBand => "closed_loop.band",
        F::ClosedLoopRateMax => "closed_loop.rate_max",
        F::ConnectingRod => "connecting_rod",
        F::ControlHz => "control_hz",
        F::OvercurrentMs => "limits.overcurrent_ms",
        F::StallMs => "limits.stall_ms",
        F::LinkTimeoutMs => "limits.link_timeout_ms",
        F::DriveAngleMin => "limits.drive_angle_min_deg",
        F::DriveAngleMax => "limits.drive_angle_max_deg",
        F::Other => "a configuration value",
    }
}

/// The unit and the reason of a table field.
fn words(field: Field) -> (&'static str, &'static str) {
    use Field as F;
    match field {
        F::LinkTimeoutMs => (
            "ms",
            "the owner's keep-alive comes every 250 ms, so 500 ms survives one lost keep-alive; \
             at most 10 s of a drive running on with nobody connected",
        ),
        F::ControlHz => (
            "Hz",
            "the watchdog's timeout covers 3 control periods and a flash page's erase and \
             program at the floor (72.9 ms, `rig::watchdog`), so no accepted rate can starve it \
             (and the sample rate, a multiple, tops it)",
        ),
        F::SampleHz => (
            "Hz",
            "from 1 kHz (the control tick's own rate) to 12 kHz, the firmware's sample budget \
             with a fifth in reserve",
        ),
        F::OmegaMax => (
            "rad/s",
            "above 0, and at most 1000 rad/s (159 Hz), twice the reference motor's full-duty \
             speed: no lecture shaker turns faster",
        ),
        F::OmegaRateMax => (
            "rad/s²",
            "the soft start and stop ramp: at 10 rad/s² a stop from 420 rad/s takes 42 s; \
             above 1000 rad/s² the ramp is a jump the motor cannot follow",
        ),
        F::DriveAngleMin => (
            "deg",
            "the mount's travel starts within half a turn of the hanging position",
        ),
        F::DriveAngleMax => (
            "deg",
            "the mount's travel ends within a turn of 0° (and less than a turn past its start)",
        ),
        F::DriveAngleRateMax => (
            "deg/s",
            "the tilt servo's slew: at least 1°/s so a new θd is reached, at most a turn a \
             second, beyond any hobby servo",
        ),
        F::CurrentMax => (
            "A",
            "the over-current trip sits at or below the DRV8874's 6 A peak",
        ),
        F::OvercurrentMs => (
            "ms",
            "how long the current may exceed current_max: at most 1 s, so the trip still \
             protects the bridge and the winding",
        ),
        F::StallMinOmega => (
            "rad/s",
            "the commanded speed above which a stall is detected: at most 100 rad/s (and below \
             omega_max), else the stall detector never arms",
        ),
        F::StallFraction => (
            "1",
            "a crank slower than this fraction of its command is stalled: 0.05 still tells a \
             stopped crank from a turning one, 0.9 leaves room for the phase lock's lag",
        ),
        F::StallMs => (
            "ms",
            "how long a stall or the duty ceiling may last: 50 ms rides through a start, 2 s \
             bounds a stalled motor's heating",
        ),
        F::DutyMax => (
            "1",
            "the duty ceiling is a fraction of full duty: above 0 or the drive cannot run, \
             at most 1",
        ),
    }
}

/// The table, in the core's order, with keys, units and reasons.
pub fn rows() -> Vec<Row> {
    BOUNDS
        .iter()
        .map(|b| {
            let (unit, why) = words(b.field);
            Row {
                bound: *b,
                key: key(b.field.into()),
                unit,
                why,
            }
        })
        .collect()
}

/// A range as messages and docs/rig.md write it: `[500, 10000]`, `(0, 1]`.
pub fn range_text(b: &Bound) -> String {
    let (lo, l) = match b.lo {
        End::Closed(x) => (x, '['),
        End::Open(x) => (x, '('),
    };
    let (hi, h) = match b.hi {
        End::Closed(x) => (x, ']'),
        End::Open(x) => (x, ')'),
    };
    format!("{l}{}, {}{h}", Compact(lo), Compact(hi))
}

/// The range with its unit: `[500, 10000] ms`.
fn range_with_unit(b: &Bound) -> String {
    match words(b.field).0 {
        "1" => range_text(b),
        unit => format!("{} {unit}", range_text(b)),
    }
}

/// The range of a table field with its unit (`[500, 10000] ms`), for a refusal by the rig.
pub fn allowed(field: ConfigField) -> Option<String> {
    BOUNDS
        .iter()
        .find(|b| ConfigField::from(b.field) == field)
        .map(range_with_unit)
}

/// The first table field of `cfg` outside its range, as a refusal that names the key the user
/// typed (`typed` maps a field to it) and the allowed range with its unit.
pub fn check(cfg: &RigConfig, typed: impl Fn(ConfigField) -> String) -> Result<(), String> {
    match fields::check(cfg) {
        Ok(()) => Ok(()),
        Err((field, value)) => {
            let b = fields::bound(field);
            Err(format!(
                "{} = {} is out of range: allowed {} ({})",
                typed(field.into()),
                Compact(value),
                range_with_unit(&b),
                words(field).1
            ))
        }
    }
}

/// The table for docs/rig.md (Markdown), between its markers.
pub fn markdown() -> String {
    let mut s = String::from("| field | unit | range | why this bound |\n|---|---|---|---|\n");
    for r in rows() {
        s += &format!(
            "| `{}` | {} | {} | {} |\n",
            r.key,
            r.unit,
            range_text(&r.bound),
            r.why
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// `cfg` with table field `f` set to `v` (a u32 field takes `v` rounded and saturated,
    /// as a TOML integer would be refused past u32 by the file's parser).
    fn with(f: Field, v: f64) -> RigConfig {
        let mut c = RigConfig::REFERENCE;
        let l = &mut c.limits;
        let u = v.clamp(0.0, f64::from(u32::MAX)) as u32;
        match f {
            Field::LinkTimeoutMs => l.link_timeout_ms = u,
            Field::ControlHz => {
                c.control_hz = u;
                // Keep the sample rate a multiple within its range where one exists.
                c.sample_hz = (12_000 / u.max(1)).max(1) * u;
            }
            Field::SampleHz => c.sample_hz = u,
            Field::OmegaMax => l.omega_max = v,
            Field::OmegaRateMax => l.omega_rate_max = v,
            Field::DriveAngleMin => l.drive_angle_min_deg = v,
            Field::DriveAngleMax => l.drive_angle_max_deg = v,
            Field::DriveAngleRateMax => l.drive_angle_rate_max_deg = v,
            Field::CurrentMax => l.current_max = v,
            Field::OvercurrentMs => l.overcurrent_ms = u,
            Field::StallMinOmega => l.stall_min_omega = v,
            Field::StallFraction => l.stall_fraction = v,
            Field::StallMs => l.stall_ms = u,
            Field::DutyMax => l.duty_max = v,
        }
        c
    }

    #[test]
    fn every_row_has_a_unit_a_reason_and_a_key_that_names_its_field() {
        for r in rows() {
            assert!(!r.unit.is_empty() && !r.why.is_empty(), "{}", r.key);
            assert!(r.key.ends_with(r.bound.field.name()), "{}", r.key);
        }
    }

    /// Values that would switch a guard off (no link-loss stop, an over-current never acted on,
    /// a watchdog firing before the first control tick), refused with the key and the range.
    #[test]
    fn issue_23s_values_are_refused_by_name() {
        let key = |f| key(f).to_string();
        for (f, v, range) in [
            (Field::LinkTimeoutMs, 0.0, "[500, 10000] ms"),
            (Field::LinkTimeoutMs, 4_294_967_295.0, "[500, 10000] ms"),
            (Field::OvercurrentMs, 4_294_967_295.0, "[1, 1000] ms"),
            (Field::ControlHz, 5.0, "[100, 12000] Hz"),
        ] {
            let e = check(&with(f, v), key).unwrap_err();
            assert!(
                e.starts_with(&format!("{} = ", super::key(f.into()))),
                "{e}"
            );
            assert!(e.contains(range), "{e}");
        }
    }

    /// The table in docs/rig.md is this table.
    #[test]
    fn docs_rig_md_shows_the_table() {
        let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/rig.md"))
            .unwrap();
        assert!(
            doc.contains(&markdown()),
            "docs/rig.md's safety table differs from the code; it should read:\n{}",
            markdown()
        );
    }

    fn row_and_value() -> impl Strategy<Value = (usize, f64)> {
        (
            0..BOUNDS.len(),
            prop_oneof![any::<f64>(), -1e5..2e4f64, 0.0..1.0f64],
        )
    }

    proptest! {
        /// Inside a row's range the host and the core's table accept the value; outside, both
        /// and `RigConfig::validate` refuse it by that field; no value panics.
        #[test]
        fn inside_accepted_outside_refused((i, v) in row_and_value()) {
            let b = BOUNDS[i];
            let cfg = with(b.field, v);
            let stored = fields::value(&cfg, b.field);
            let host = check(&cfg, |f| key(f).to_string());
            if b.admits(stored) {
                prop_assert!(host.is_ok(), "{host:?}");
                prop_assert!(fields::check(&cfg).is_ok());
            } else {
                let e = host.unwrap_err();
                prop_assert!(e.starts_with(key(b.field.into())), "{e}");
                prop_assert_eq!(fields::check(&cfg).unwrap_err().0, b.field);
                let core = cfg.validate().unwrap_err();
                prop_assert_eq!(
                    ConfigField::from_param_name(core.name),
                    ConfigField::from(b.field)
                );
            }
        }
    }
}
