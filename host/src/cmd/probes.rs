//! `kapitza probes`: the debug probes attached, as `kapitza flash --probe` names them.

use std::io::Write;

use anyhow::Result;
use probe_rs::probe::list::Lister;

use crate::flash::probes::{self, UDEV_HINT};

/// List the debug probes attached (a NUCLEO's on-board ST-LINK among them), each with the
/// VID:PID:SERIAL that `kapitza flash --probe` takes, and whether this user may open it.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// One JSON array of {selector, name, vid, pid, serial_number, kind, accessible}.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    run_with(args, &Lister::new(), out)
}

/// [`run`] with the probes `lister` finds.
pub fn run_with(args: &Args, lister: &Lister, out: &mut dyn Write) -> Result<()> {
    let found = probes::list(lister);
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&found)?)?;
        return Ok(());
    }
    if found.is_empty() {
        writeln!(
            out,
            "no debug probe found. Plug in the NUCLEO's ST-LINK USB port (CN1); on Linux a probe \
             this user may not open can go unseen too"
        )?;
    }
    for p in &found {
        writeln!(out, "{}", p.line())?;
    }
    if found.iter().any(|p| !p.accessible) {
        writeln!(out, "no permission: {UDEV_HINT}")?;
    }
    Ok(())
}
