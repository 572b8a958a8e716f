//! `kapitza stop` and `kapitza clear`: the two commands without arguments.

use std::io::Write;

use anyhow::Result;

use kapitza_core::link::message::Mode;

use super::rig_args::RigArgs;
use crate::rig::names::fault_name;

/// Soft-stop the drive (ramped down at the rate limit; an inverted pendulum falls gently).
#[derive(Debug, clap::Args)]
pub struct StopArgs {
    #[command(flatten)]
    pub rig: RigArgs,
}

/// Leave a latched fault once its cause is gone (the e-stop released).
#[derive(Debug, clap::Args)]
pub struct ClearArgs {
    #[command(flatten)]
    pub rig: RigArgs,
}

pub fn stop(args: &StopArgs, out: &mut dyn Write) -> Result<()> {
    let mut s = args.rig.connect()?;
    s.call(|c| c.stop())?;
    writeln!(out, "{}: stopping (soft stop)", s.name)?;
    Ok(())
}

/// Asks the rig first: with no fault latched there is nothing to send, and the rig is left as
/// it is.
pub fn clear(args: &ClearArgs, out: &mut dyn Write) -> Result<()> {
    let mut s = args.rig.connect()?;
    let status = s.call(|c| c.status())?;
    let Mode::Faulted(f) = status.mode else {
        writeln!(out, "{}: no fault to clear", s.name)?;
        return Ok(());
    };
    s.call(|c| c.clear_fault())?;
    writeln!(out, "{}: fault cleared ({})", s.name, fault_name(&f))?;
    Ok(())
}
