//! Rig files (TOML): the true physics of a simulated rig and, apart from it, what the rig is
//! configured with — the way a real bench differs from what was typed in.
//!
//! The pendulum, gravity and stroke are written as in a scene (`[pendulum]`, `[environment]`,
//! `[drive] amplitude`, `[effects]` with `viscous`, `coulomb`, `slider_crank`); the rest is the
//! rig's own hardware. Every key is optional but `[pendulum]` and `[drive]`; docs/rig-file.md
//! lists them. `[configured]` gives the configuration's pendulum and stroke where they differ
//! (a mis-typed rig); by default the rig is configured with the file's true ones.

use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use kapitza_core::math;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::simrig::body::Body;
use kapitza_core::simrig::plant::MotorModel;
use kapitza_core::simrig::sensor::Line;
use kapitza_core::simrig::Params;
use serde::Deserialize;

use crate::scene_file::{out_of_range, pendulum, RawEnvironment, RawPendulum};

/// A simulated rig: its truth and its configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct RigFile {
    pub title: String,
    pub params: Params,
    pub config: RigConfig,
}

impl RigFile {
    /// The demo rod (physics §4) configured as it is.
    pub fn demo() -> Self {
        Self {
            title: "the demo rod (L = 0.25 m, A = 12.7 mm)".into(),
            params: Params::DEMO,
            config: Params::DEMO.configured(),
        }
    }
}

/// Reads and checks a rig file.
pub fn load(path: &Path) -> Result<RigFile> {
    let text = crate::files::read_input("the rig file", path)?;
    parse(&text).map_err(|e| match scene_instead(&text) {
        true => anyhow!(
            "{} is a scene file (for `kapitza simulate` and `chart`), not a rig file: a rig file \
             describes a simulated bench's hardware ([motor], [sensor], [servo], …), see docs/rig.md \
             ({e})",
            path.display()
        ),
        false => e.context(format!("rig file {}", path.display())),
    })
}

/// Whether `text` is a scene file: a run, an expectation, or a drive given by its frequency,
/// R or angle (a rig's drive is its stroke alone).
fn scene_instead(text: &str) -> bool {
    let Ok(t) = text.parse::<toml::Table>() else {
        return false;
    };
    let drive_keys = t
        .get("drive")
        .and_then(toml::Value::as_table)
        .is_some_and(|d| {
            ["omega", "angle_deg", "r", "frequency_hz"]
                .iter()
                .any(|k| d.contains_key(*k))
        });
    t.contains_key("run") || t.contains_key("expect") || drive_keys
}

/// Parses and checks the text of a rig file.
pub fn parse(text: &str) -> Result<RigFile> {
    let de = toml::Deserializer::parse(text).map_err(|e| anyhow!("{e}"))?;
    let raw: RawRig = serde_path_to_error::deserialize(de).map_err(|e| anyhow!("{e}"))?;
    convert(raw)
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a rig table")]
struct RawRig {
    title: Option<String>,
    pendulum: RawPendulum,
    #[serde(default)]
    environment: RawEnvironment,
    drive: RawStroke,
    #[serde(default)]
    effects: RawLosses,
    #[serde(default)]
    sensor: RawSensor,
    #[serde(default)]
    motor: RawMotor,
    #[serde(default)]
    crank: RawCrank,
    #[serde(default)]
    servo: RawServo,
    #[serde(default)]
    current: RawCurrent,
    #[serde(default)]
    initial: RawInitial,
    #[serde(default)]
    operator: RawOperator,
    #[serde(default)]
    body: RawBody,
    seed: Option<u64>,
    configured: Option<RawConfigured>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [drive] amplitude = … (m)")]
struct RawStroke {
    amplitude: f64,
}

#[derive(Debug, Default, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table of effects: viscous, coulomb, slider_crank"
)]
struct RawLosses {
    viscous: Option<RawViscous>,
    coulomb: Option<RawCoulomb>,
    slider_crank: Option<RawSliderCrank>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: viscous = { q = … }")]
struct RawViscous {
    q: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: coulomb = { torque = … }")]
struct RawCoulomb {
    torque: f64,
}

#[derive(Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table: slider_crank = { rod_length = … }"
)]
struct RawSliderCrank {
    rod_length: f64,
}

/// `[operator]`: a simulated lab hand for `kapitza calibrate` (`simrig::hand`).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [operator] release_deg = …")]
struct RawOperator {
    release_deg: Option<f64>,
}

/// `[body]`: the actuator's body that keeps the rod within 90° of the blade (`simrig::body`).
#[derive(Debug, Default, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table: [body] present = true/false, restitution = …"
)]
struct RawBody {
    present: Option<bool>,
    restitution: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [sensor]")]
struct RawSensor {
    noise_deg: Option<f64>,
    zero_deg: Option<f64>,
    #[serde(default)]
    reversed: bool,
    #[serde(default)]
    line: RawLine,
}

/// The pendulum sensor's cable.
#[derive(Debug, Default, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
enum RawLine {
    #[default]
    Connected,
    /// Cut, with MISO's pull-up as on the board: every bit reads 1.
    Cut,
    /// Cut with MISO floating low: every bit reads 0.
    StuckLow,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [motor]")]
struct RawMotor {
    omega_per_duty: Option<f64>,
    lag_s: Option<f64>,
    volts: Option<f64>,
    ke: Option<f64>,
    ohms: Option<f64>,
    #[serde(default)]
    reversed: bool,
    #[serde(default)]
    stalled: bool,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [crank]")]
struct RawCrank {
    #[serde(default)]
    reversed: bool,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [servo]")]
struct RawServo {
    rate_deg_s: Option<f64>,
    offset_deg: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [current]")]
struct RawCurrent {
    offset: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [initial]")]
struct RawInitial {
    angle_deg: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [configured]")]
struct RawConfigured {
    pendulum: Option<RawPendulum>,
    amplitude: Option<f64>,
    connecting_rod: Option<f64>,
    gravity: Option<f64>,
    duty_max: Option<f64>,
    #[serde(default)]
    calibration: RawCalibration,
    #[serde(default)]
    closed_loop: RawClosedLoop,
}

/// `[configured.calibration]`: any of the calibration's fields (`kapitza config get` names).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [configured.calibration]")]
struct RawCalibration {
    pendulum_zero: Option<u16>,
    pendulum_sign: Option<i8>,
    crank_sign: Option<i8>,
    servo_min_us: Option<u32>,
    servo_max_us: Option<u32>,
    servo_range_deg: Option<f64>,
    servo_centre_deg: Option<f64>,
    current_offset: Option<f64>,
    current_scale: Option<f64>,
    hysteresis: Option<f64>,
    min_swing: Option<f64>,
    settle_band: Option<f64>,
    block_s: Option<f64>,
    quiet_blocks: Option<u32>,
}

/// `[configured.closed_loop]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [configured.closed_loop]")]
struct RawClosedLoop {
    enabled: Option<bool>,
    band: Option<f64>,
    rate_max: Option<f64>,
}

impl RawCalibration {
    fn apply(&self, c: &mut kapitza_core::rig::calibration::Calibration) {
        fn set<T: Copy>(to: &mut T, v: Option<T>) {
            if let Some(v) = v {
                *to = v;
            }
        }
        set(&mut c.pendulum_zero, self.pendulum_zero);
        set(&mut c.pendulum_sign, self.pendulum_sign);
        set(&mut c.crank_sign, self.crank_sign);
        set(&mut c.servo.min_us, self.servo_min_us);
        set(&mut c.servo.max_us, self.servo_max_us);
        set(&mut c.servo.range_deg, self.servo_range_deg);
        set(&mut c.servo.centre_deg, self.servo_centre_deg);
        set(&mut c.current_offset, self.current_offset);
        set(&mut c.current_scale, self.current_scale);
        set(&mut c.estimator.hysteresis, self.hysteresis);
        set(&mut c.estimator.min_swing, self.min_swing);
        set(&mut c.estimator.settle_band, self.settle_band);
        set(&mut c.estimator.block_s, self.block_s);
        set(&mut c.estimator.quiet_blocks, self.quiet_blocks);
    }
}

fn in_range(key: &str, v: f64, lo: f64, hi: f64, allowed: &str) -> Result<f64> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(out_of_range(key, v, allowed))
    }
}

fn positive(key: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(out_of_range(key, v, "a finite number > 0"))
    }
}

fn sign(reversed: bool) -> f64 {
    if reversed {
        -1.0
    } else {
        1.0
    }
}

/// The body, unless `present = false`; a restitution given for an absent body is refused
/// rather than ignored.
fn body(raw: &RawBody) -> Result<Option<Body>> {
    let restitution = match raw.restitution {
        Some(e) => Some(in_range("body.restitution", e, 0.0, 1.0, "in [0, 1]")?),
        None => None,
    };
    match (raw.present.unwrap_or(true), restitution) {
        (true, e) => Ok(Some(Body {
            restitution: e.unwrap_or(Body::DEFAULT.restitution),
        })),
        (false, None) => Ok(None),
        (false, Some(e)) => bail!(
            "body.restitution = {e} given with body.present = false: a rig without a body has no \
             contact (drop one of the two)"
        ),
    }
}

fn convert(raw: RawRig) -> Result<RigFile> {
    let geometry = pendulum(&raw.pendulum)?;
    let gravity = positive("environment.gravity", raw.environment.gravity)?;
    let ell = geometry.equivalent_length();
    let amplitude = in_range(
        "drive.amplitude",
        raw.drive.amplitude,
        f64::MIN_POSITIVE,
        0.1 * ell,
        "in (0, 0.1 ℓ] m: a stroke small beside the pendulum",
    )?;
    let omega0 = math::sqrt(gravity / ell);
    let damping = match &raw.effects.viscous {
        Some(v) => omega0 / positive("effects.viscous.q", v.q)?,
        None => 0.0,
    };
    let coulomb = match &raw.effects.coulomb {
        Some(c) => in_range(
            "effects.coulomb.torque",
            c.torque,
            0.0,
            omega0 * omega0,
            "in [0, ω0²] rad/s² (beyond it the pendulum could not hang)",
        )?,
        None => 0.0,
    };
    let connecting_rod = match &raw.effects.slider_crank {
        Some(s) if s.rod_length.is_finite() && s.rod_length > 2.0 * amplitude => Some(s.rod_length),
        Some(s) => {
            return Err(out_of_range(
                "effects.slider_crank.rod_length",
                s.rod_length,
                "a length > 2 × drive.amplitude (m)",
            ))
        }
        None => None,
    };
    let d = MotorModel::DEFAULT;
    let m = &raw.motor;
    let motor = MotorModel {
        omega_per_duty: positive(
            "motor.omega_per_duty",
            m.omega_per_duty.unwrap_or(d.omega_per_duty),
        )?,
        tau: positive("motor.lag_s", m.lag_s.unwrap_or(d.tau))?,
        volts: positive("motor.volts", m.volts.unwrap_or(d.volts))?,
        ke: positive("motor.ke", m.ke.unwrap_or(d.ke))?,
        ohms: positive("motor.ohms", m.ohms.unwrap_or(d.ohms))?,
        direction: sign(m.reversed),
    };
    let p = Params::DEMO;
    let params = Params {
        geometry,
        gravity,
        amplitude,
        connecting_rod,
        damping,
        coulomb,
        motor,
        sensor_noise: math::to_rad(in_range(
            "sensor.noise_deg",
            raw.sensor.noise_deg.unwrap_or(math::to_deg(p.sensor_noise)),
            0.0,
            10.0,
            "in [0, 10] degrees",
        )?),
        sensor_zero: math::to_rad(in_range(
            "sensor.zero_deg",
            raw.sensor.zero_deg.unwrap_or(0.0),
            -180.0,
            180.0,
            "in [-180, 180] degrees",
        )?),
        sensor_sign: sign(raw.sensor.reversed),
        crank_sign: sign(raw.crank.reversed),
        servo_rate_deg: positive(
            "servo.rate_deg_s",
            raw.servo.rate_deg_s.unwrap_or(p.servo_rate_deg),
        )?,
        servo_offset_deg: in_range(
            "servo.offset_deg",
            raw.servo.offset_deg.unwrap_or(0.0),
            -30.0,
            30.0,
            "in [-30, 30] degrees",
        )?,
        current_offset: in_range(
            "current.offset",
            raw.current.offset.unwrap_or(0.0),
            -5.0,
            5.0,
            "in [-5, 5] A",
        )?,
        stalled: m.stalled,
        sensor_line: match raw.sensor.line {
            RawLine::Connected => Line::Connected,
            RawLine::Cut => Line::CutPulledUp,
            RawLine::StuckLow => Line::CutPulledDown,
        },
        theta0: math::to_rad(in_range(
            "initial.angle_deg",
            raw.initial.angle_deg.unwrap_or(0.0),
            -180.0,
            180.0,
            "in [-180, 180] degrees",
        )?),
        hand: match raw.operator.release_deg {
            Some(d) => Some(math::to_rad(in_range(
                "operator.release_deg",
                d,
                5.0,
                60.0,
                "in [5, 60] degrees counter-clockwise",
            )?)),
            None => None,
        },
        body: body(&raw.body)?,
        seed: raw.seed.unwrap_or(1),
    };
    let mut config = params.configured();
    if let Some(c) = &raw.configured {
        if let Some(pd) = &c.pendulum {
            config.geometry = pendulum(pd).context("configured")?;
        }
        if let Some(a) = c.amplitude {
            config.amplitude = positive("configured.amplitude", a)?;
        }
        if let Some(b) = c.connecting_rod {
            config.connecting_rod = b;
        }
        if let Some(g) = c.gravity {
            config.gravity = positive("configured.gravity", g)?;
        }
        if let Some(d) = c.duty_max {
            config.limits.duty_max = d;
        }
        c.calibration.apply(&mut config.calibration);
        let l = &c.closed_loop;
        let cl = &mut config.closed_loop;
        cl.enabled = l.enabled.unwrap_or(cl.enabled);
        cl.band = l.band.unwrap_or(cl.band);
        cl.rate_max = l.rate_max.unwrap_or(cl.rate_max);
    }
    // Of the safety table's fields a rig file sets only the duty ceiling; the rest are the
    // reference's.
    super::fields::check(&config, |f| match f {
        kapitza_core::link::reason::ConfigField::DutyMax => "configured.duty_max".into(),
        f => super::fields::key(f).into(),
    })
    .map_err(|e| anyhow!("{e}"))?;
    let config = config.validate().map_err(|e| anyhow!("configured: {e}"))?;
    if amplitude > 0.1 * ell {
        bail!("drive.amplitude = {amplitude} is too large for the pendulum");
    }
    Ok(RigFile {
        title: raw.title.unwrap_or_else(|| "simulated rig".into()),
        params,
        config,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_demo_file_is_the_demo_rig() {
        let f = parse(include_str!("../../../rigs/demo.toml")).unwrap();
        assert_eq!(f.params.geometry, Params::DEMO.geometry);
        assert_eq!(f.params.amplitude, Params::DEMO.amplitude);
        // Q = 10 in the file; Params::DEMO writes c = ω0/10 to 4 digits.
        assert!((f.params.damping / Params::DEMO.damping - 1.0).abs() < 1e-4);
        assert_eq!(f.config, Params::DEMO.configured());
    }

    #[test]
    fn a_mistyped_rig_keeps_its_truth_apart() {
        let f = parse(include_str!("../../../rigs/mistyped.toml")).unwrap();
        assert_ne!(f.config.geometry, f.params.geometry);
        assert_eq!(f.params.sensor_zero, math::to_rad(1.5));
    }

    #[test]
    fn bench_faults_and_calibration_are_read() {
        let f = parse(
            "[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n\
             [sensor]\nline = \"stuck_low\"\n[motor]\nstalled = true\n[crank]\nreversed = true\n\
             [configured]\nduty_max = 0.5\n[configured.calibration]\ncrank_sign = -1\n\
             current_offset = 12.0\n[configured.closed_loop]\nenabled = true\n",
        )
        .unwrap();
        assert_eq!(f.params.sensor_line, Line::CutPulledDown);
        assert!(f.params.stalled);
        assert_eq!(f.params.crank_sign, -1.0);
        assert_eq!(f.config.limits.duty_max, 0.5);
        assert_eq!(f.config.calibration.crank_sign, -1);
        assert_eq!(f.config.calibration.current_offset, 12.0);
        assert!(f.config.closed_loop.enabled);
        // Out of range: named by the configuration's check.
        let e = parse(
            "[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n\
             [configured.calibration]\ncrank_sign = 0\n",
        )
        .unwrap_err();
        assert!(format!("{e:#}").contains("crank_sign"), "{e:#}");
    }

    #[test]
    fn the_body_is_there_unless_the_file_says_not() {
        let base = "[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n";
        assert_eq!(parse(base).unwrap().params.body, Some(Body::DEFAULT));
        let f = parse(&format!("{base}[body]\nrestitution = 0.8\n")).unwrap();
        assert_eq!(f.params.body, Some(Body { restitution: 0.8 }));
        let f = parse(&format!("{base}[body]\npresent = false\n")).unwrap();
        assert_eq!(f.params.body, None);
        for bad in [
            "restitution = 1.5",
            "restitution = -0.1",
            "restitution = nan",
        ] {
            let e = parse(&format!("{base}[body]\n{bad}\n")).unwrap_err();
            let e = format!("{e:#}");
            assert!(
                e.contains("body.restitution") && e.contains("[0, 1]"),
                "{e}"
            );
        }
        let e = parse(&format!(
            "{base}[body]\npresent = false\nrestitution = 0.5\n"
        ))
        .unwrap_err();
        assert!(format!("{e:#}").contains("body.present = false"), "{e:#}");
        let e = parse(&format!("{base}[body]\nthere = 1\n")).unwrap_err();
        assert!(format!("{e:#}").contains("there"), "{e:#}");
    }

    #[test]
    fn bad_values_name_their_key() {
        let e = parse("[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n[servo]\noffset_deg = 90\n")
            .unwrap_err();
        assert!(format!("{e:#}").contains("servo.offset_deg = 90"), "{e:#}");
        let e = parse("[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\nspeed = 3\n")
            .unwrap_err();
        assert!(format!("{e:#}").contains("speed"), "{e:#}");
    }

    #[test]
    fn a_duty_ceiling_outside_the_safety_table_is_refused_by_its_key() {
        // The table's duty_max row: (0, 1] (rig::fields::BOUNDS).
        for d in ["0", "1.5", "-0.2"] {
            let e = parse(&format!(
                "[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n\
                 [configured]\nduty_max = {d}\n"
            ))
            .unwrap_err();
            let e = format!("{e:#}");
            assert!(e.contains(&format!("configured.duty_max = {d}")), "{e}");
            assert!(e.contains("allowed (0, 1]"), "{e}");
        }
        let ok = parse(
            "[pendulum]\ngeometry = \"rod\"\nlength = 0.25\n[drive]\namplitude = 0.0127\n\
             [configured]\nduty_max = 1\n",
        );
        assert!(ok.is_ok(), "{ok:?}");
    }
}
