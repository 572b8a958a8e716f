//! `kapitza status`: the rig's state, once.

use std::io::Write;

use anyhow::Result;

use super::rig_args::RigArgs;

/// Show the rig's mode, drive, pendulum estimate and link counters.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub rig: RigArgs,
    /// One JSON object: mode, fault, r_target, omega, omega_target, drive_angle_deg,
    /// drive_angle_target_deg, theta_deg, slow_angle_deg, omega_p, r_estimate (null unless the
    /// drive runs), settled, predicted (with other_stable, outside_reach), commands, counters.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let mut s = args.rig.connect()?;
    let view = s.snapshot()?;
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&view)?)?;
    } else {
        writeln!(out, "{}\n{}", s.name, view.text())?;
    }
    Ok(())
}
