//! `kapitza rig serve`: a simulated rig on a pseudo-terminal, for any serial client.
//!
//! The rig loop is the firmware's (`kapitza_core::station`), the physics `kapitza_core::simrig`
//! from a rig file. The first line on stdout, flushed at once, is the device path; `--link`
//! also publishes it as a stable symlink, so a restarted rig is found at the same name. The pty's
//! other end stays open here, so a client may come and go.

use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;

use super::rig_args::RigArgs;
use crate::files;
use crate::rig::simhost;
use crate::rig::{self as rigmod};

mod pty;

#[derive(Debug, clap::Subcommand)]
pub enum Action {
    /// Serve a simulated rig on a pseudo-terminal (Unix): prints the device path, then runs
    /// until Ctrl-C (or SIGTERM, SIGHUP) or --duration; then removes --link and prints its
    /// summary.
    Serve(ServeArgs),
}

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub action: Action,
}

#[derive(Debug, clap::Args)]
pub struct ServeArgs {
    /// The simulated rig's file (default: the demo rod, rigs/demo.toml).
    #[arg(long, value_name = "FILE")]
    pub sim: Option<PathBuf>,
    /// Rig seconds per wall second (the link-silence timeout stays on wall time).
    #[arg(
        allow_hyphen_values = true,
        long,
        default_value_t = 1.0,
        value_name = "X"
    )]
    pub speed: f64,
    /// Also publish the device as this symlink (an existing symlink there is replaced).
    #[arg(long, value_name = "PATH")]
    pub link: Option<PathBuf>,
    /// Write every setting the rig applied to this file, one JSON line each (an existing file
    /// is refused unless --force or --append).
    #[arg(long, value_name = "FILE")]
    pub truth: Option<PathBuf>,
    /// Replace an existing --truth file.
    #[arg(long, requires = "truth", conflicts_with = "append")]
    pub force: bool,
    /// Add to the end of an existing --truth file.
    #[arg(long, requires = "truth")]
    pub append: bool,
    /// Stop after this many wall seconds (default: run until a signal).
    #[arg(allow_hyphen_values = true, long, value_name = "S")]
    pub duration: Option<f64>,
    /// Speak this link protocol version instead of this tool's (for tests of version skew).
    #[arg(long, hide = true)]
    pub protocol: Option<u8>,
    /// Power up as with the e-stop held: on the safe defaults (status `config` =
    /// "defaults_by_estop"), the rig file's configuration unused; the e-stop is released after.
    #[arg(long)]
    pub estop_at_power_up: bool,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let Action::Serve(a) = &args.action;
    let existing = files::Existing::from_flags(a.force, a.append);
    if let Some(p) = &a.truth {
        files::check_output("--truth", p, existing)?;
    }
    let rig = RigArgs {
        port: None,
        sim: a.sim.clone(),
        speed: a.speed,
    };
    let mut opts = rig.sim_options()?;
    opts.protocol = a.protocol;
    opts.estop_at_power_up = a.estop_at_power_up;
    let duration = a
        .duration
        .map(|d| crate::input::positive("--duration", d))
        .transpose()?;
    let (mut line, path) = pty::open()?;
    let mut truth = match &a.truth {
        Some(p) => Some(BufWriter::new(files::create_output(
            "--truth", p, existing,
        )?)),
        None => None,
    };
    // Before the link is published: a signal from then on still removes it.
    rigmod::catch_interrupt();
    if let Some(link) = &a.link {
        pty::publish(link, &path)?;
    }
    writeln!(out, "{path}")?;
    out.flush()?;
    let start = Instant::now();
    let stop =
        || rigmod::interrupted() || duration.is_some_and(|d| start.elapsed().as_secs_f64() >= d);
    let cpu0 = crate::timing::thread_cpu();
    let summary = simhost::run(
        opts.build(),
        opts.speed,
        &mut line,
        &stop,
        truth.as_mut().map(|w| w as &mut dyn Write),
    );
    drop(line);
    if let Some(link) = &a.link {
        let _ = std::fs::remove_file(link);
    }
    let s = summary?;
    let cpu = crate::timing::thread_cpu() - cpu0;
    eprintln!(
        "rig serve: {:.1} rig seconds in {:.1} s ({:.1}× real time), {:.1} % of one core",
        s.rig_seconds,
        s.wall_seconds,
        s.rig_seconds / s.wall_seconds.max(1e-9),
        100.0 * cpu / s.wall_seconds.max(1e-9)
    );
    Ok(())
}
