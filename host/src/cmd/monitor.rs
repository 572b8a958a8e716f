//! `kapitza monitor`: the live dashboard, or one JSON record per frame off a terminal.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;

use anyhow::{bail, Result};

use crate::input;
use crate::monitor::{self, simfeed, Feed, Options, Plain};

/// Watch a rig live: link and mode, faults and events, the drive's set point against actual,
/// the slow angle φ against the model's φ0, ωp and R measured against predicted, and a chart
/// of φ over time. Keys: s stops the drive, c clears a fault, q quits.
///
/// Off a terminal (or with --plain) it prints one JSON object per telemetry frame instead.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// The rig: `sim` for the simulated demo rig in this process. Default: $KAPITZA_PORT,
    /// else `sim`.
    #[arg(long, value_name = "P")]
    pub port: Option<String>,
    /// Log every telemetry frame to this CSV file (with a header).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// End after S seconds of the rig's clock.
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// One JSON record per telemetry frame instead of the dashboard.
    #[arg(long)]
    pub plain: bool,
    /// The simulated rig's pace: X times real time (0: as fast as the machine goes).
    #[arg(long, value_name = "X", default_value_t = 1.0)]
    pub speed: f64,
}

/// The port named by `--port`, else `KAPITZA_PORT`, else the simulated rig.
pub fn port_name(port: &Option<String>) -> String {
    port.clone()
        .or_else(|| std::env::var("KAPITZA_PORT").ok())
        .unwrap_or_else(|| "sim".into())
}

/// The feed for `port`: `sim` is the simulated demo rig at `speed` × real time.
pub fn open_feed(port: &str, speed: f64) -> Result<Box<dyn Feed>> {
    let speed = input::non_negative("--speed", speed)?;
    if port == "sim" {
        return Ok(Box::new(simfeed::sim_feed(speed)));
    }
    bail!("cannot open {port}: serial ports are not connected to the monitor yet; use --port sim")
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    if let Some(d) = args.duration {
        input::positive("--duration", d)?;
    }
    let mut feed = open_feed(&port_name(&args.port), args.speed)?;
    let opts = Options {
        duration: args.duration,
        csv: args.csv.clone(),
    };
    if args.plain || !std::io::stdout().is_terminal() {
        monitor::run_plain(feed.as_mut(), None, &opts, Plain::Records, out)?;
    } else {
        monitor::run_tui(feed.as_mut(), None, &opts, false)?;
    }
    Ok(())
}
