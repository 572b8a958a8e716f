//! The scene file as written: raw structs that mirror the TOML, `deny_unknown_fields`
//! everywhere, so a misspelt key or an unknown effect is an error listing the allowed ones.

use crate::outcome::ExpectKind;
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a scene table")]
pub(super) struct RawScene {
    pub(super) title: Option<String>,
    pub(super) pendulum: RawPendulum,
    pub(super) drive: RawDrive,
    #[serde(default)]
    pub(super) environment: RawEnvironment,
    #[serde(default)]
    pub(super) initial: RawInitial,
    pub(super) run: RawRun,
    #[serde(default)]
    pub(super) effects: RawEffects,
    pub(super) expect: Option<RawExpect>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum GeometryName {
    Rod,
    Point,
    General,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [pendulum]")]
pub(crate) struct RawPendulum {
    pub(super) geometry: GeometryName,
    pub(super) length: Option<f64>,
    pub(super) inertia: Option<f64>,
    pub(super) mass: Option<f64>,
    pub(super) com: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [drive]")]
pub(super) struct RawDrive {
    pub(super) amplitude: f64,
    pub(super) omega: Option<f64>,
    pub(super) r: Option<f64>,
    pub(super) angle_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [environment]")]
pub(crate) struct RawEnvironment {
    #[serde(default = "standard_gravity")]
    pub(crate) gravity: f64,
}

pub(super) fn standard_gravity() -> f64 {
    9.81
}

impl Default for RawEnvironment {
    fn default() -> Self {
        Self {
            gravity: standard_gravity(),
        }
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [initial]")]
pub(super) struct RawInitial {
    #[serde(default)]
    pub(super) angle_deg: f64,
    #[serde(default)]
    pub(super) rate: f64,
}

#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum FidelityName {
    Full,
    Averaged,
    Linearised,
    #[default]
    Auto,
}

#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum MethodName {
    #[default]
    Auto,
    Dop853,
    Rkn86,
    Rkn1210,
    Rk4,
    Verlet,
    Yoshida4,
    Yoshida6,
}

#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum ControllerName {
    #[default]
    Standard,
    Pi,
}

#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum FormatName {
    #[default]
    F64,
    F32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [run]")]
pub(super) struct RawRun {
    pub(super) periods: Option<f64>,
    pub(super) duration: Option<f64>,
    #[serde(default)]
    pub(super) fidelity: FidelityName,
    #[serde(default)]
    pub(super) method: MethodName,
    pub(super) rtol: Option<f64>,
    pub(super) atol: Option<f64>,
    pub(super) steps_per_period: Option<f64>,
    #[serde(default)]
    pub(super) controller: ControllerName,
    #[serde(default)]
    pub(super) format: FormatName,
    pub(super) seed: Option<u64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table of effects")]
pub(super) struct RawEffects {
    pub(super) viscous: Option<RawViscous>,
    pub(super) coulomb: Option<RawCoulomb>,
    pub(super) tilt: Option<RawTilt>,
    pub(super) slider_crank: Option<RawSliderCrank>,
    pub(super) ramp: Option<RawRamp>,
    pub(super) sensor: Option<RawSensor>,
    pub(super) actuator: Option<RawActuator>,
}

#[derive(Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table: viscous = { q = … } or { gamma = … }"
)]
pub(super) struct RawViscous {
    pub(super) q: Option<f64>,
    pub(super) gamma: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: coulomb = { torque = … }")]
pub(super) struct RawCoulomb {
    pub(super) torque: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: tilt = { angle_deg = … }")]
pub(super) struct RawTilt {
    pub(super) angle_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table: slider_crank = { rod_length = … }"
)]
pub(super) struct RawSliderCrank {
    pub(super) rod_length: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: ramp = { seconds = … }")]
pub(super) struct RawRamp {
    pub(super) seconds: f64,
}

#[derive(Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table: sensor = { bits = …, noise_deg = …, rate_hz = … }"
)]
pub(super) struct RawSensor {
    pub(super) bits: u32,
    #[serde(default)]
    pub(super) noise_deg: f64,
    pub(super) rate_hz: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: actuator = { lag_s = … }")]
pub(super) struct RawActuator {
    pub(super) lag_s: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table: [expect]")]
pub(super) struct RawExpect {
    pub(super) kind: ExpectKind,
    pub(super) angle_deg: Option<f64>,
    pub(super) tolerance_deg: Option<f64>,
    pub(super) order: Option<u32>,
    pub(super) direction: Option<i64>,
}

// ---------------------------------------------------------------------------------------------
// Conversion and checks.
