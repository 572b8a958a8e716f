//! What ends a step early: a signal, a stop from another terminal (through the control socket
//! this command serves, or through the port's owner: the monitor's `s`), or the drive stopped
//! under the step. Checked on every turn of every wait, so a step interrupted at any point
//! stores nothing.

use std::fmt;

use anyhow::Result;
use kapitza_core::link::message::{Check, Mode};
use kapitza_core::link::{Status, Telemetry};

use crate::rig::served::Served;
use crate::rig::session::{line_failure, Session};
use crate::signals::{self, Signal};

/// Why a step ended before it finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Halt {
    Signal(Signal),
    /// `kapitza stop`, the monitor's `s`, or anything else that stopped the drive the step
    /// was running.
    StoppedElsewhere,
}

impl fmt::Display for Halt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Signal(s) => write!(f, "{}", s.name()),
            Self::StoppedElsewhere => f.write_str("the drive was stopped from elsewhere"),
        }
    }
}

impl std::error::Error for Halt {}

/// The checks, and the control socket while this command owns the port.
#[derive(Default)]
pub struct Watch {
    pub served: Option<Served>,
}

impl Watch {
    /// Serves the socket's clients and ends the step on a signal or a relayed stop.
    pub fn tick(&mut self, s: &mut Session) -> Result<()> {
        if let Some(sig) = signals::caught() {
            return Err(Halt::Signal(sig).into());
        }
        if let Some(sv) = self.served.as_mut() {
            if sv
                .serve(&mut s.client)
                .map_err(|e| line_failure(&s.name, e))?
            {
                return Err(Halt::StoppedElsewhere.into());
            }
        }
        Ok(())
    }

    /// Copies a frame the step read to the socket's clients that asked for telemetry.
    pub fn fan_out(&mut self, t: &Telemetry) {
        if let Some(sv) = self.served.as_mut() {
            sv.fan_out(t);
        }
    }
}

/// Whether the drive or bring-up mode is on (a start's pre-run check included).
pub fn active(st: &Status) -> bool {
    st.mode == Mode::Running || st.bring_up.is_some() || st.check == Some(Check::Running)
}

/// Follows the rig's status through a stretch the step drives: once the drive was seen on,
/// its end is someone else's stop.
#[derive(Default)]
pub struct Driving {
    seen: bool,
    /// The last status showed a start's pre-run check running.
    checking: bool,
}

impl Driving {
    pub fn check(&mut self, st: &Status) -> Result<()> {
        if let Mode::Faulted(f) = st.mode {
            anyhow::bail!(
                "the rig faulted ({}): `kapitza clear` once its cause is gone",
                crate::rig::names::fault_name(&f)
            );
        }
        // A start's check that fails after it ran: its verdict, not someone else's stop.
        if let (true, Some(Check::Failed(why))) = (self.checking, st.check) {
            anyhow::bail!("the drive did not start: the pre-run check failed: {why}");
        }
        self.checking = st.check == Some(Check::Running);
        let on = active(st);
        if self.seen && !on {
            return Err(Halt::StoppedElsewhere.into());
        }
        self.seen |= on;
        Ok(())
    }
}
