//! What the monitor reads and what it may ask: a [`Feed`] of [`Event`]s from one rig, and the
//! [`Command`]s a person (or the demo's script) sends back through it.
//!
//! The feed hides where the rig is — a serial port, a simulated rig in this process — and who
//! keeps its link alive: the monitor only draws what arrives and forwards keys. A feed that
//! loses its line says so ([`Event::LinkLost`]) and, when the rig is back and has passed the
//! version check again, starts over with [`Event::Linked`].

use std::time::Duration;

use kapitza_core::link::{Status, Telemetry};
use kapitza_core::rig::config::RigConfig;

/// One thing that happened on the link.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// The rig answered the version check (again, after a loss) and sent its configuration.
    Linked {
        protocol: u8,
        firmware: [u16; 3],
        config: Box<RigConfig>,
    },
    Telemetry(Telemetry),
    /// The answer to the keep-alive.
    Status(Status),
    /// The line failed; the feed keeps trying to reach the rig.
    LinkLost(String),
    /// Something worth a line in the event log (a reconnect attempt, a port name).
    Note(String),
}

/// What the monitor may ask of the rig.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// Soft stop: accepted in every mode.
    Stop,
    ClearFault,
    /// Start or change the drive: strength R and drive angle θd (degrees along the mount).
    SetDrive {
        r: f64,
        theta_d_deg: f64,
    },
}

impl Command {
    pub fn label(&self) -> String {
        match self {
            Self::Stop => "stop".into(),
            Self::ClearFault => "clear fault".into(),
            Self::SetDrive { r, theta_d_deg } => format!("set R = {r} at θd = {theta_d_deg}°"),
        }
    }
}

/// A rig's link as the monitor sees it.
pub trait Feed {
    /// The next event, waiting at most `timeout`; `None` when nothing came.
    fn next_event(&mut self, timeout: Duration) -> Option<Event>;
    /// Carries out `c`; `Err` names why not (the line, or the rig's refusal and its reason).
    fn command(&mut self, c: Command) -> Result<(), String>;
    /// Stops the drive and lets go of the rig: whether the rig confirmed the stop (`None`: a
    /// feed that drives nothing).
    fn close(&mut self) -> Option<bool> {
        None
    }
}
