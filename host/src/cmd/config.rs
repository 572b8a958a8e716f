//! `kapitza config get | set FILE`: the rig's configuration as a TOML file.
//!
//! `get` prints every field; `set` takes a file with any of them (the rest stay as the rig has
//! them), checks it here, then sends it: the rig checks it again, applies it only while idle,
//! and stores it in flash. A value out of range is refused with its field and the allowed range,
//! and nothing changes.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, Result};
use kapitza_core::model::Geometry;
use kapitza_core::rig::calibration::Calibration;
use kapitza_core::rig::closed_loop::ClosedLoopR;
use kapitza_core::rig::config::{Limits, MotorConfig, RigConfig};
use kapitza_core::rig::estimator::Tuning;
use kapitza_core::rig::servo::ServoMap;
use serde::{Deserialize, Serialize};

use super::rig_args::RigArgs;
use crate::rig::{fields, Exit, Failure};

#[derive(Debug, clap::Subcommand)]
pub enum Action {
    /// Print the rig's configuration (TOML, or JSON with --json).
    Get {
        #[command(flatten)]
        rig: RigArgs,
        #[arg(long)]
        json: bool,
    },
    /// Replace the rig's configuration (only while it is idle) with the fields a TOML file
    /// gives; the others keep the rig's values. The rig stores it in flash.
    Set {
        #[command(flatten)]
        rig: RigArgs,
        /// The TOML file (as `config get` prints it; any subset of its fields).
        file: PathBuf,
    },
}

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub action: Action,
}

/// The configuration as a file: SI units, the pendulum written as in a scene.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConfigFile {
    /// Drive amplitude A (m): half the peak-to-peak stroke.
    amplitude: f64,
    /// The connecting rod (m) from the crank pin to the carriage; 0 for a pure sine.
    connecting_rod: f64,
    gravity: f64,
    sample_hz: u32,
    control_hz: u32,
    pendulum: PendulumFile,
    limits: LimitsFile,
    motor: MotorFile,
    calibration: CalibrationFile,
    closed_loop: ClosedLoopFile,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "geometry", rename_all = "lowercase", deny_unknown_fields)]
enum PendulumFile {
    Rod { length: f64 },
    Point { length: f64 },
    General { inertia: f64, mass: f64, com: f64 },
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LimitsFile {
    omega_max: f64,
    omega_rate_max: f64,
    drive_angle_min_deg: f64,
    drive_angle_max_deg: f64,
    drive_angle_rate_max_deg: f64,
    current_max: f64,
    overcurrent_ms: u32,
    stall_min_omega: f64,
    stall_fraction: f64,
    stall_ms: u32,
    link_timeout_ms: u32,
    duty_max: f64,
}

/// The bench's calibration (`kapitza_core::rig::calibration`), as `config get` and
/// `status --json` print it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationFile {
    /// Pendulum sensor count at rest (0..16383), and +1/−1 for its direction.
    pendulum_zero: u16,
    pendulum_sign: i8,
    /// +1/−1: the crank encoder counts with positive duty, or against it.
    crank_sign: i8,
    servo_min_us: u32,
    servo_max_us: u32,
    servo_range_deg: f64,
    servo_centre_deg: f64,
    /// Current sense: ADC counts at zero current, and A per count.
    current_offset: f64,
    current_scale: f64,
    /// Estimator thresholds (rad, s, blocks).
    hysteresis: f64,
    min_swing: f64,
    settle_band: f64,
    block_s: f64,
    quiet_blocks: u32,
}

/// Closed-loop R (carried; off by default).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ClosedLoopFile {
    enabled: bool,
    band: f64,
    rate_max: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MotorFile {
    omega_per_duty: f64,
    lag: f64,
    kp: f64,
    ki: f64,
    max_correction: f64,
}

impl From<&RigConfig> for ConfigFile {
    fn from(c: &RigConfig) -> Self {
        let l = &c.limits;
        let m = &c.motor;
        Self {
            amplitude: c.amplitude,
            connecting_rod: c.connecting_rod,
            gravity: c.gravity,
            sample_hz: c.sample_hz,
            control_hz: c.control_hz,
            pendulum: match c.geometry {
                Geometry::Rod { length } => PendulumFile::Rod { length },
                Geometry::PointMass { length } => PendulumFile::Point { length },
                Geometry::General { inertia, mass, com } => {
                    PendulumFile::General { inertia, mass, com }
                }
            },
            limits: LimitsFile {
                omega_max: l.omega_max,
                omega_rate_max: l.omega_rate_max,
                drive_angle_min_deg: l.drive_angle_min_deg,
                drive_angle_max_deg: l.drive_angle_max_deg,
                drive_angle_rate_max_deg: l.drive_angle_rate_max_deg,
                current_max: l.current_max,
                overcurrent_ms: l.overcurrent_ms,
                stall_min_omega: l.stall_min_omega,
                stall_fraction: l.stall_fraction,
                stall_ms: l.stall_ms,
                link_timeout_ms: l.link_timeout_ms,
                duty_max: l.duty_max,
            },
            motor: MotorFile {
                omega_per_duty: m.omega_per_duty,
                lag: m.lag,
                kp: m.kp,
                ki: m.ki,
                max_correction: m.max_correction,
            },
            calibration: CalibrationFile::from(&c.calibration),
            closed_loop: ClosedLoopFile {
                enabled: c.closed_loop.enabled,
                band: c.closed_loop.band,
                rate_max: c.closed_loop.rate_max,
            },
        }
    }
}

impl From<&ConfigFile> for RigConfig {
    fn from(f: &ConfigFile) -> Self {
        let l = &f.limits;
        let m = &f.motor;
        Self {
            amplitude: f.amplitude,
            connecting_rod: f.connecting_rod,
            gravity: f.gravity,
            sample_hz: f.sample_hz,
            control_hz: f.control_hz,
            geometry: match f.pendulum {
                PendulumFile::Rod { length } => Geometry::Rod { length },
                PendulumFile::Point { length } => Geometry::PointMass { length },
                PendulumFile::General { inertia, mass, com } => {
                    Geometry::General { inertia, mass, com }
                }
            },
            limits: Limits {
                omega_max: l.omega_max,
                omega_rate_max: l.omega_rate_max,
                drive_angle_min_deg: l.drive_angle_min_deg,
                drive_angle_max_deg: l.drive_angle_max_deg,
                drive_angle_rate_max_deg: l.drive_angle_rate_max_deg,
                current_max: l.current_max,
                overcurrent_ms: l.overcurrent_ms,
                stall_min_omega: l.stall_min_omega,
                stall_fraction: l.stall_fraction,
                stall_ms: l.stall_ms,
                link_timeout_ms: l.link_timeout_ms,
                duty_max: l.duty_max,
            },
            motor: MotorConfig {
                omega_per_duty: m.omega_per_duty,
                lag: m.lag,
                kp: m.kp,
                ki: m.ki,
                max_correction: m.max_correction,
            },
            calibration: Calibration::from(&f.calibration),
            closed_loop: ClosedLoopR {
                enabled: f.closed_loop.enabled,
                band: f.closed_loop.band,
                rate_max: f.closed_loop.rate_max,
            },
        }
    }
}

impl From<&Calibration> for CalibrationFile {
    fn from(c: &Calibration) -> Self {
        Self {
            pendulum_zero: c.pendulum_zero,
            pendulum_sign: c.pendulum_sign,
            crank_sign: c.crank_sign,
            servo_min_us: c.servo.min_us,
            servo_max_us: c.servo.max_us,
            servo_range_deg: c.servo.range_deg,
            servo_centre_deg: c.servo.centre_deg,
            current_offset: c.current_offset,
            current_scale: c.current_scale,
            hysteresis: c.estimator.hysteresis,
            min_swing: c.estimator.min_swing,
            settle_band: c.estimator.settle_band,
            block_s: c.estimator.block_s,
            quiet_blocks: c.estimator.quiet_blocks,
        }
    }
}

impl From<&CalibrationFile> for Calibration {
    fn from(f: &CalibrationFile) -> Self {
        Self {
            pendulum_zero: f.pendulum_zero,
            pendulum_sign: f.pendulum_sign,
            crank_sign: f.crank_sign,
            servo: ServoMap {
                min_us: f.servo_min_us,
                max_us: f.servo_max_us,
                range_deg: f.servo_range_deg,
                centre_deg: f.servo_centre_deg,
            },
            current_offset: f.current_offset,
            current_scale: f.current_scale,
            estimator: Tuning {
                hysteresis: f.hysteresis,
                min_swing: f.min_swing,
                settle_band: f.settle_band,
                block_s: f.block_s,
                quiet_blocks: f.quiet_blocks,
            },
        }
    }
}

/// `over` laid onto `base`, table by table.
fn merge(base: &mut toml::Table, over: toml::Table) {
    for (k, v) in over {
        match (base.get_mut(&k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) if k != "pendulum" => merge(b, o),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

/// `cfg` as the TOML file `get` prints and `set` reads.
pub fn to_toml(cfg: &RigConfig) -> Result<String> {
    Ok(toml::to_string(&ConfigFile::from(cfg))?)
}

/// The configuration `file` describes, on top of `current`.
pub fn read(file: &std::path::Path, current: &RigConfig) -> Result<RigConfig> {
    let text = crate::files::read_input("the configuration file", file)?;
    let over: toml::Table = text
        .parse()
        .map_err(|e| anyhow!("{}: {e}", file.display()))?;
    let mut table = toml::Table::try_from(ConfigFile::from(current))?;
    merge(&mut table, over);
    let parsed: ConfigFile = serde_path_to_error::deserialize(toml::Value::Table(table))
        .map_err(|e| anyhow!("{}: {e}", file.display()))?;
    let cfg = RigConfig::from(&parsed);
    fields::check(&cfg, |f| fields::key(f).to_string())
        .map_err(|e| anyhow!("{}: {e}; nothing was sent", file.display()))?;
    cfg.validate()
        .map_err(|e| anyhow!("{}: {e}; nothing was sent", file.display()))
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    match &args.action {
        Action::Get { rig, json } => {
            let s = rig.connect()?;
            let f = ConfigFile::from(&s.config);
            if *json {
                writeln!(out, "{}", serde_json::to_string_pretty(&f)?)?;
            } else {
                write!(out, "{}", to_toml(&s.config)?)?;
            }
        }
        Action::Set { rig, file } => {
            crate::files::check_input("the configuration file", file)?;
            let mut s = rig.connect_to_change("kapitza config set")?;
            let new =
                read(file, &s.config).map_err(|e| Failure::new(Exit::Refused, format!("{e:#}")))?;
            s.call(|c| c.set_config(&new))?;
            writeln!(out, "{}: configuration replaced and stored", s.name)?;
        }
    }
    Ok(())
}
