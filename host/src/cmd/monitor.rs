//! `kapitza monitor`: the live dashboard, or one JSON record per frame off a terminal.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;

use anyhow::Result;

use super::rig_args::RigArgs;
use crate::input;
use crate::monitor::owner_feed::OwnerFeed;
use crate::monitor::{self, Feed, Options, Plain};
use crate::rig::owner::Owner;
use crate::rig::port::Target;
use crate::rig::simhost::SimOptions;

/// Watch a rig live: link and mode, faults and events, the drive's set point against actual,
/// the slow angle φ against the model's φ0, ωp and R measured against predicted, and a chart
/// of φ over time. Keys: s stops the drive, c clears a fault, q quits.
///
/// Off a terminal (or with --plain) it prints one JSON object per telemetry frame instead.
///
/// While it runs it owns the port: it keeps the link alive, and `kapitza set`, `status`, `stop`
/// in other terminals go through it. Quitting (q, Ctrl-C, SIGTERM, SIGHUP) stops the drive: exit
/// 0 once the rig confirmed the stop, 3 if it did not.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub rig: RigArgs,
    /// Log every telemetry frame to this CSV file (with a header); an existing file is refused
    /// unless --force or --append.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Replace an existing --csv file.
    #[arg(long, requires = "csv", conflicts_with = "append")]
    pub force: bool,
    /// Add rows to the end of an existing --csv file (its header is kept).
    #[arg(long, requires = "csv")]
    pub append: bool,
    /// End after S seconds of the rig's clock.
    #[arg(allow_hyphen_values = true, long, value_name = "S")]
    pub duration: Option<f64>,
    /// One JSON record per telemetry frame instead of the dashboard.
    #[arg(long)]
    pub plain: bool,
}

/// The feed for `target`: this process becomes the owner of its port (keep-alive, control
/// socket, reconnects), or runs the simulated rig.
pub fn open_feed(target: &Target, sim: &SimOptions) -> Result<Box<dyn Feed>> {
    let owner = Owner::start(target.clone(), sim.clone())?;
    Ok(Box::new(OwnerFeed::spawn(owner)))
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    if let Some(d) = args.duration {
        input::positive("--duration", d)?;
    }
    let csv_existing = crate::files::Existing::from_flags(args.force, args.append);
    if let Some(p) = &args.csv {
        crate::files::check_output("--csv", p, csv_existing)?;
    }
    crate::signals::catch();
    let mut feed = open_feed(&args.rig.target()?, &args.rig.sim_options()?)?;
    let opts = Options {
        duration: args.duration,
        csv: args.csv.clone(),
        csv_existing,
    };
    if args.plain || !std::io::stdout().is_terminal() {
        monitor::run_plain(feed.as_mut(), None, &opts, Plain::Records, out)?;
    } else {
        monitor::run_tui(feed.as_mut(), None, &opts, false)?;
    }
    monitor::close(feed.as_mut())
}
