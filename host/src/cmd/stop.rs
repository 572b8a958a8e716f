//! `kapitza stop` and `kapitza clear`: the two commands without arguments.

use std::io::Write;

use anyhow::Result;

use super::rig_args::RigArgs;

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

pub fn clear(args: &ClearArgs, out: &mut dyn Write) -> Result<()> {
    let mut s = args.rig.connect()?;
    s.call(|c| c.clear_fault())?;
    writeln!(out, "{}: fault cleared", s.name)?;
    Ok(())
}
