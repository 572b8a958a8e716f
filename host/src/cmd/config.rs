//! `kapitza config get | set FILE`: the rig's configuration as a TOML file.
//!
//! `get` prints every field; `set` takes a file with any of them (the rest stay as the rig has
//! them), checks it here, then sends it: the rig checks it again, applies it only while idle,
//! and stores it in flash. A value out of range is refused with its field and the allowed range,
//! and nothing changes.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, Context, Result};
use kapitza_core::model::Geometry;
use kapitza_core::rig::config::{Limits, MotorConfig, RigConfig};
use serde::{Deserialize, Serialize};

use super::rig_args::RigArgs;
use crate::rig::{Exit, Failure};

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
    gravity: f64,
    sample_hz: u32,
    control_hz: u32,
    pendulum: PendulumFile,
    limits: LimitsFile,
    motor: MotorFile,
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
            },
            motor: MotorFile {
                omega_per_duty: m.omega_per_duty,
                lag: m.lag,
                kp: m.kp,
                ki: m.ki,
                max_correction: m.max_correction,
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
            },
            motor: MotorConfig {
                omega_per_duty: m.omega_per_duty,
                lag: m.lag,
                kp: m.kp,
                ki: m.ki,
                max_correction: m.max_correction,
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

/// The configuration `file` describes, on top of `current`.
pub fn read(file: &std::path::Path, current: &RigConfig) -> Result<RigConfig> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("cannot read {}", file.display()))?;
    let over: toml::Table = text
        .parse()
        .map_err(|e| anyhow!("{}: {e}", file.display()))?;
    let mut table = toml::Table::try_from(ConfigFile::from(current))?;
    merge(&mut table, over);
    let parsed: ConfigFile = serde_path_to_error::deserialize(toml::Value::Table(table))
        .map_err(|e| anyhow!("{}: {e}", file.display()))?;
    RigConfig::from(&parsed)
        .validate()
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
                write!(out, "{}", toml::to_string(&f)?)?;
            }
        }
        Action::Set { rig, file } => {
            let mut s = rig.connect()?;
            let new =
                read(file, &s.config).map_err(|e| Failure::new(Exit::Refused, format!("{e:#}")))?;
            s.call(|c| c.set_config(&new))?;
            writeln!(out, "{}: configuration replaced and stored", s.name)?;
        }
    }
    Ok(())
}
