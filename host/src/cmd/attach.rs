//! `kapitza attach`: own the rig's port without a dashboard.

use std::io::Write;
use std::time::{Duration, Instant};

use anyhow::Result;

use super::rig_args::RigArgs;
use crate::rig::owner::{Event, Owner};
use crate::rig::session::StatusView;
use crate::rig::{self, Exit, Failure};

/// Own the rig's port and keep its link alive, so a drive outlives the commands that set it:
/// `kapitza set`, `status`, `stop` in other terminals go through this process's control
/// socket. Prints a line whenever the rig's mode changes. Ctrl-C (or SIGTERM, SIGHUP) stops the
/// drive and exits: 0 once the rig confirmed the stop, 3 if it did not.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub rig: RigArgs,
    /// Exit after this many seconds (default: until Ctrl-C); the drive is stopped either way.
    #[arg(allow_hyphen_values = true, long, value_name = "S")]
    pub duration: Option<f64>,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let duration = args
        .duration
        .map(|d| crate::input::positive("--duration", d))
        .transpose()?;
    rig::catch_interrupt();
    let mut owner = Owner::start(args.rig.target()?, args.rig.sim_options()?)?;
    let name = owner.session().map(|s| s.name.clone()).unwrap_or_default();
    match owner.socket() {
        Some(p) => writeln!(out, "attached to {name}; control socket {}", p.display())?,
        None => writeln!(out, "attached to {name}")?,
    }
    out.flush()?;
    let start = Instant::now();
    let mut last = String::new();
    while !rig::interrupted() && !duration.is_some_and(|d| start.elapsed().as_secs_f64() >= d) {
        for e in owner.turn() {
            let line = match e {
                Event::Status(st) => {
                    let cfg = owner.session().map(|s| s.config);
                    let Some(cfg) = cfg else { continue };
                    let v = StatusView::new(&st, None, &cfg);
                    let line = format!(
                        "mode {}{}, R = {:.3}, θd target {:.1}°",
                        v.mode,
                        v.fault.map(|f| format!(" ({f})")).unwrap_or_default(),
                        v.r_target,
                        v.drive_angle_target_deg
                    );
                    if line == last {
                        continue;
                    }
                    last = line.clone();
                    line
                }
                Event::LinkLost(why) => format!("line lost: {why}; waiting for the rig to return"),
                Event::LinkBack => "line back, version checked".into(),
                Event::Relayed(_) | Event::Telemetry(_) => continue,
            };
            writeln!(out, "{line}")?;
            out.flush()?;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    if owner.shutdown() {
        writeln!(out, "detached; the rig confirmed the stop")?;
    } else {
        return Err(Failure::new(
            Exit::NoRig,
            "detached; the rig did not confirm the stop: it stops by itself once the line has \
             been silent for its link timeout (link_timeout_ms, 1 s unless configured)",
        )
        .into());
    }
    Ok(())
}
