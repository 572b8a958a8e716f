//! `kapitza calibrate`: the guided sequence that measures a bench and writes what it found into
//! the rig's configuration. The measurements are `kapitza_core::calib`'s; this module carries
//! them out over the link and talks to the person at the rig.
//!
//! | module | concept |
//! |---|---|
//! | [`record`] | sensor streams over the link for a stretch of rig time, the link kept alive |
//! | [`steps`] | the steps: what each asks of the person, measures, refuses and changes |
//! | [`operator`] | the person at the rig: prompts, confirmations, `--yes` |
//! | [`watch`] | what ends a step early: a signal, a stop from elsewhere; the socket served |
//!
//! ```text
//! sensor    ring-down in bring-up mode (motor off): direction from the counter-clockwise
//!           release, zero from the swing's centre              → pendulum_sign, pendulum_zero
//! crank     a 0.3 s pulse of 15 % duty in bring-up mode        → crank_sign
//! servo     jog-to-mark pairs (a person at the marks), and the current sense at rest
//!                                                              → servo map, current_offset
//! ringdown  ring-down with the zero applied: ω0, ℓ, Q, Coulomb → the pendulum's length
//! stroke    R = 0.5 at θd = 90°, settled: the wobble's amplitude → amplitude; the pendulum's
//!           lean gives the mount's true angle                  → servo centre (without marks)
//! ```
//! The configuration is written after every step that passed, so later steps run on what the
//! earlier ones found; the one the rig had before is saved to a file first. A step ended early
//! (a signal, `kapitza stop`, the monitor's `s`) stops the drive and writes nothing.

pub mod operator;
pub mod record;
pub mod steps;
pub mod watch;

use serde::Serialize;

/// A calibration step, by the name `--step` takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Step {
    /// Pendulum sensor direction and zero (a ring-down).
    Sensor,
    /// Crank encoder direction (a short low-duty pulse).
    Crank,
    /// Servo map (jog to marks) and the current sense's offset at rest.
    Servo,
    /// ℓ, Q and Coulomb friction from a ring-down with the drive off.
    Ringdown,
    /// The stroke A from the fast wobble, hanging at θd = 90°.
    Stroke,
}

impl Step {
    pub const ALL: [Self; 5] = [
        Self::Sensor,
        Self::Crank,
        Self::Servo,
        Self::Ringdown,
        Self::Stroke,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Self::Sensor => "sensor",
            Self::Crank => "crank",
            Self::Servo => "servo",
            Self::Ringdown => "ringdown",
            Self::Stroke => "stroke",
        }
    }
}

/// What one step measured and wrote: name → value pairs in SI units and degrees, as the JSON
/// output prints them.
#[derive(Debug, Clone, Serialize)]
pub struct StepReport {
    pub step: Step,
    pub measured: serde_json::Map<String, serde_json::Value>,
    /// The configuration fields this step changed (`config get`'s names).
    pub wrote: serde_json::Map<String, serde_json::Value>,
}

impl StepReport {
    pub fn new(step: Step) -> Self {
        Self {
            step,
            measured: serde_json::Map::new(),
            wrote: serde_json::Map::new(),
        }
    }

    pub fn measured(&mut self, key: &str, v: impl Into<serde_json::Value>) {
        self.measured.insert(key.into(), v.into());
    }

    pub fn wrote(&mut self, key: &str, v: impl Into<serde_json::Value>) {
        self.wrote.insert(key.into(), v.into());
    }

    /// One line per value, for people.
    pub fn text(&self) -> String {
        let mut s = String::new();
        for (k, v) in &self.measured {
            s += &format!("  measured  {k} = {v}\n");
        }
        for (k, v) in &self.wrote {
            s += &format!("  wrote     {k} = {v}\n");
        }
        s
    }
}
