//! The arguments every rig command shares: which rig, and the simulated one's physics.

use std::path::PathBuf;

use anyhow::{bail, Result};

use crate::rig::file::{self, RigFile};
use crate::rig::port::{self, Target};
use crate::rig::session::{self, Session};
use crate::rig::simhost::SimOptions;
use crate::rig::{served, Exit, Failure};

#[derive(Debug, Clone, clap::Args)]
pub struct RigArgs {
    /// The rig's serial port: a device path (a board's virtual COM port, or the pty that
    /// `kapitza rig serve` prints), `auto` (the one ST-LINK virtual COM port attached), or `sim`
    /// (a simulated rig in this process). Default: $KAPITZA_PORT, else `auto`.
    #[arg(long, value_name = "PORT")]
    pub port: Option<String>,
    /// With `--port sim`: the simulated rig's file (default: the demo rod, rigs/demo.toml).
    #[arg(long, value_name = "FILE")]
    pub sim: Option<PathBuf>,
    /// With `--port sim`: rig seconds per wall second (0: as fast as the laptop reads).
    #[arg(
        allow_hyphen_values = true,
        long,
        default_value_t = 1.0,
        value_name = "X"
    )]
    pub speed: f64,
}

impl RigArgs {
    /// The rig `--port` names; `--sim` or a `--speed` other than 1 beside a real port is
    /// refused, as they cannot act on it.
    pub fn target(&self) -> Result<Target> {
        let target = port::resolve(self.port.as_deref())?;
        if let Target::Serial { path } = &target {
            if let Some(f) = &self.sim {
                bail!(
                    "--sim {} acts only with --port sim; {path} is a real rig (its physics is \
                     its own): drop --sim, or use --port sim",
                    f.display()
                );
            }
            if self.speed != 1.0 {
                bail!(
                    "--speed {} acts only with --port sim; {path} is a real rig and runs in real \
                     time: drop --speed, or use --port sim",
                    self.speed
                );
            }
        }
        Ok(target)
    }

    pub fn sim_options(&self) -> Result<SimOptions> {
        let rig = match &self.sim {
            Some(p) => file::load(p)?,
            None => RigFile::demo(),
        };
        let speed = match crate::input::non_negative("--speed", self.speed)? {
            0.0 => f64::INFINITY,
            x => x,
        };
        Ok(SimOptions::new(rig, speed))
    }

    /// A checked connection to the rig.
    pub fn connect(&self) -> Result<Session> {
        session::connect(&self.target()?, &self.sim_options()?)
    }

    /// A checked connection for `command`, which changes the rig: refused, before anything is
    /// sent, while a command that must not be disturbed (a calibration) owns the port.
    pub fn connect_to_change(&self, command: &str) -> Result<Session> {
        let target = self.target()?;
        let s = session::connect(&target, &self.sim_options()?)?;
        if let (Target::Serial { path }, true) = (&target, s.via_owner) {
            if let Some(why) = served::busy(path) {
                return Err(Failure::new(
                    Exit::Refused,
                    format!("{path}: {why}: `{command}` was not sent; nothing changed"),
                )
                .into());
            }
        }
        Ok(s)
    }
}
