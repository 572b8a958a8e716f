//! `kapitza demo`: the lecture demo, scripted, ending with measured against predicted.

use std::io::{IsTerminal, Write};

use anyhow::{bail, Result};
use serde::Serialize;

use crate::cmd::monitor::open_feed;
use crate::cmd::rig_args::RigArgs;
use crate::demo::{Outcome, Script, STEPS};
use crate::monitor::{self, Options, Plain};
use crate::rig::port::Target;

/// Run the lecture demo: the rod hanging at rest; R = 1.75 at θd = 90°, where it settles near
/// 55°; R = 2.2 with θd slewed to 180°, carrying it over the top; R = 1.75, where it stays
/// upside down. Each step waits until the rod has settled, and the demo ends with a table of
/// φ0, ωp and R measured against predicted.
///
/// By default on the simulated demo rod (L = 0.25 m, A = 12.7 mm) in this process, shown in
/// the monitor on a terminal.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// The rig to run it on (a device path, or `auto` for the one ST-LINK attached). Default:
    /// the simulated demo rod in this process.
    #[arg(long, value_name = "P")]
    pub port: Option<String>,
    /// The simulated rig's pace: X times real time (0: as fast as the demo reads).
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "X",
        default_value_t = 1.0
    )]
    pub speed: f64,
    /// Progress lines and the table instead of the dashboard.
    #[arg(long, conflicts_with = "json")]
    pub plain: bool,
    /// One JSON object at the end, with a `steps` array.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct Report<'a> {
    pub steps: &'a [Outcome],
    /// Why the demo ended early, if it did.
    pub aborted: Option<&'a str>,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let rig = RigArgs {
        port: Some(args.port.clone().unwrap_or_else(|| "sim".into())),
        sim: None,
        speed: args.speed,
    };
    let target: Target = rig.target()?;
    crate::signals::catch();
    let mut feed = open_feed(&target, &rig.sim_options()?)?;
    let mut script = Script::new();
    let opts = Options::default();
    if args.json {
        monitor::run_plain(feed.as_mut(), Some(&mut script), &opts, Plain::Nothing, out)?;
        monitor::close(feed.as_mut())?;
        let signal = crate::signals::caught().map(|s| s.name());
        let report = Report {
            steps: &script.outcomes,
            aborted: script.aborted.as_deref().or(signal),
        };
        serde_json::to_writer_pretty(&mut *out, &report)?;
        writeln!(out)?;
    } else {
        if args.plain || !std::io::stdout().is_terminal() {
            monitor::run_plain(feed.as_mut(), Some(&mut script), &opts, Plain::Log, out)?;
        } else {
            monitor::run_tui(feed.as_mut(), Some(&mut script), &opts, true)?;
        }
        monitor::close(feed.as_mut())?;
        print_table(&script.outcomes, out)?;
    }
    if let Some(sig) = crate::signals::caught() {
        return Err(sig.failure("the demo was stopped before its end; the drive is stopped"));
    }
    if let Some(why) = &script.aborted {
        bail!("the demo stopped early: {why}");
    }
    if script.outcomes.iter().any(|o| !o.settled) {
        bail!("a step did not settle");
    }
    if script.outcomes.len() != STEPS.len() + 1 {
        bail!("the demo was left before its end");
    }
    Ok(())
}

fn print_table(rows: &[Outcome], out: &mut dyn Write) -> Result<()> {
    for line in crate::demo::table(rows) {
        writeln!(out, "{line}")?;
    }
    Ok(())
}
