//! `kapitza calibrate`: measure the bench and write what it is into the rig's configuration.
//!
//! The steps (`--step NAME` reruns one) and their formulas are in `crate::calibrate` and
//! docs/calibration.md. Before anything is written, the configuration the rig had is saved to a
//! file (`--backup FILE`, never over an existing one unless `--force`; default a new file in the
//! backup folder, [`backup_dir`]), as `kapitza config get` prints it; `kapitza config set FILE`
//! restores it.
//!
//! Without an owner of the port running, calibrate is its owner while it runs: it serves the
//! control socket, so `kapitza stop` and `status` work from another terminal (`set` and
//! `config set` are refused: calibration in progress). With an owner running it goes through
//! it. A signal (SIGINT, SIGTERM, SIGHUP) or a stop from elsewhere ends the step at once: the
//! drive is stopped, nothing from that step is written, and a signal exits 130 / 143 / 129
//! (3 when the rig did not confirm the stop).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use serde::Serialize;

use super::progress::progress_writer;
use super::rig_args::RigArgs;
use crate::calibrate::operator::Operator;
use crate::calibrate::steps::Calibrator;
use crate::calibrate::watch::{Halt, Watch};
use crate::calibrate::{Step, StepReport};
use crate::files;
use crate::rig::port::Target;
use crate::rig::served::Served;
use crate::rig::{self, Exit, Failure};

/// Calibrate the rig: pendulum sensor direction and zero, crank direction, servo map and
/// current offset, the pendulum's length and damping from a ring-down, the stroke from the fast
/// wobble. Each step says what to do and what it measured, refuses to go on when a measurement
/// is implausible, and writes its result into the rig's configuration (stored in flash).
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub rig: RigArgs,
    /// Run only this step (the others keep the rig's values).
    #[arg(long, value_enum, value_name = "NAME")]
    pub step: Option<Step>,
    /// Plain lines, no prompts' decoration (for scripts).
    #[arg(long)]
    pub plain: bool,
    /// One JSON object at the end (steps, measurements, fields written, the backup);
    /// prompts and progress go to stderr.
    #[arg(long)]
    pub json: bool,
    /// Do not wait for confirmations (nobody at the rig: a simulated rig's hand does the
    /// lifting; the servo's map is then corrected from the pendulum instead of marks).
    #[arg(long)]
    pub yes: bool,
    /// Where to save the configuration the rig had before (an existing file is refused unless
    /// --force). Default: a new file in $XDG_STATE_HOME/kapitza/backups (else
    /// ~/.local/state/kapitza/backups).
    #[arg(long, value_name = "FILE")]
    pub backup: Option<PathBuf>,
    /// Replace an existing --backup file.
    #[arg(long, requires = "backup")]
    pub force: bool,
}

/// The folder of the default backups: `$XDG_STATE_HOME/kapitza/backups`, else
/// `~/.local/state/kapitza/backups` (`%LOCALAPPDATA%\kapitza\backups` on Windows). A user's
/// state, kept apart from whatever folder the command ran in.
pub fn backup_dir() -> Result<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    let base = var("XDG_STATE_HOME")
        .or_else(|| var("HOME").map(|h| h.join(".local").join("state")))
        .or_else(|| var("LOCALAPPDATA"))
        .context(
            "no folder for the default backup (neither XDG_STATE_HOME nor HOME is set): \
             give one with --backup FILE",
        )?;
    Ok(base.join("kapitza").join("backups"))
}

/// Creates a new default backup file (never an existing one), returning it and its path.
fn new_default_backup() -> Result<(std::fs::File, PathBuf)> {
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    files::create_new_in(
        &backup_dir()?,
        &format!("config-before-calibrate-{t}"),
        "toml",
    )
}

#[derive(Serialize)]
struct Summary<'a> {
    rig: &'a str,
    backup: String,
    restore: String,
    steps: &'a [StepReport],
}

/// What `set` and `config set` are told while calibrate owns the port.
pub const BUSY: &str = "calibration in progress (`kapitza calibrate` owns the port)";

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let existing = files::Existing::from_flags(args.force, false);
    if let Some(p) = &args.backup {
        files::check_output("--backup", p, existing)?;
    } else {
        backup_dir()?;
    }
    rig::catch_interrupt();
    let target = args.rig.target()?;
    let s = args.rig.connect()?;
    let name = s.name.clone();
    let served = match &target {
        Target::Serial { path } if !s.via_owner => Served::open(path, BUSY)?,
        _ => None,
    };
    let (mut file, backup) = match &args.backup {
        Some(p) => (files::create_output("--backup", p, existing)?, p.clone()),
        None => new_default_backup()?,
    };
    file.write_all(super::config::to_toml(&s.config)?.as_bytes())
        .and_then(|()| file.flush())
        .with_context(|| format!("cannot save the configuration to {}", backup.display()))?;
    drop(file);
    let restore = format!("kapitza config set {}", backup.display());
    let mut progress = progress_writer(args.json, &mut *out);
    writeln!(
        progress,
        "{name}: the configuration it had is saved to {} (restore: `{restore}`)",
        backup.display()
    )?;
    if let Some(p) = served.as_ref().map(Served::socket) {
        writeln!(
            progress,
            "{name}: owned by this calibration; `kapitza stop` and `kapitza status` work from \
             another terminal (control socket {})",
            p.display()
        )?;
    }
    let op = Operator::new(args.yes, args.plain, &mut *progress);
    let mut cal = Calibrator::new(s, op, Watch { served });
    let steps: Vec<Step> = match args.step {
        Some(s) => vec![s],
        None => Step::ALL.to_vec(),
    };
    let mut reports: Vec<StepReport> = Vec::new();
    for step in steps {
        let r = match cal
            .watch
            .tick(&mut cal.s)
            .and_then(|()| cal.run(step))
            .and_then(|r| cal.write().map(|()| r))
        {
            Ok(r) => r,
            Err(e) => return Err(ended(&mut cal, step, &reports, &restore, e)),
        };
        cal.op.say(&r.text())?;
        reports.push(r);
    }
    cal.op.say(&format!(
        "{name}: calibrated and stored; `{restore}` goes back"
    ))?;
    drop(cal);
    drop(progress);
    if args.json {
        let summary = Summary {
            rig: &name,
            backup: backup.display().to_string(),
            restore,
            steps: &reports,
        };
        writeln!(out, "{}", serde_json::to_string_pretty(&summary)?)?;
    }
    Ok(())
}

/// A step that did not finish: the drive stopped first (a stop is accepted in every mode), then
/// the error with what was stored, and the exit status a signal or an unconfirmed stop calls
/// for.
fn ended(
    cal: &mut Calibrator,
    step: Step,
    stored: &[StepReport],
    restore: &str,
    e: anyhow::Error,
) -> anyhow::Error {
    let confirmed = cal.s.client.stop().is_ok();
    let before = if stored.is_empty() {
        "nothing was stored".to_string()
    } else {
        let names: Vec<&str> = stored.iter().map(|r| r.step.label()).collect();
        format!(
            "the steps before it were stored ({}; `{restore}` goes back)",
            names.join(", ")
        )
    };
    let stop = if confirmed {
        "the drive is stopped (the rig confirmed the stop)"
    } else {
        "the rig did not confirm the stop: it stops by itself once the line has been silent \
         for its link timeout (link_timeout_ms, 1 s unless configured)"
    };
    let halt = e.downcast_ref::<Halt>().copied();
    let what = format!(
        "calibration ended in the {} step: {stop}; nothing from this step was written; {before}",
        step.label()
    );
    match halt {
        Some(Halt::Signal(sig)) if confirmed => sig.failure(what),
        Some(Halt::Signal(sig)) => {
            Failure::new(Exit::NoRig, format!("{}: {what}", sig.name())).into()
        }
        Some(Halt::StoppedElsewhere) => Failure::new(
            if confirmed {
                Exit::Refused
            } else {
                Exit::NoRig
            },
            format!(
                "the drive was stopped from elsewhere (`kapitza stop`, the monitor's s, or the \
                 rig itself): {what}"
            ),
        )
        .into(),
        None if confirmed => e,
        None => e.context(format!("{stop}; {before}")),
    }
}
