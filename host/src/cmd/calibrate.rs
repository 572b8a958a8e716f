//! `kapitza calibrate`: measure the bench and write what it is into the rig's configuration.
//!
//! The steps (`--step NAME` reruns one) and their formulas are in `crate::calibrate` and
//! docs/calibration.md. Before anything is written, the configuration the rig had is saved to a
//! file (`--backup FILE`, never over an existing one unless `--force`; default a new file in the
//! backup folder, [`backup_dir`]), as `kapitza config get` prints it; `kapitza config set FILE`
//! restores it.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use serde::Serialize;

use super::progress::progress_writer;
use super::rig_args::RigArgs;
use crate::calibrate::operator::Operator;
use crate::calibrate::steps::Calibrator;
use crate::calibrate::{Step, StepReport};
use crate::files;
use crate::rig;

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
    let dir = backup_dir()?;
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create the backup folder {}", dir.display()))?;
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    for n in 0..100 {
        let name = match n {
            0 => format!("config-before-calibrate-{t}.toml"),
            n => format!("config-before-calibrate-{t}-{n}.toml"),
        };
        let path = dir.join(name);
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Ok(f) => return Ok((f, path)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e).with_context(|| format!("cannot create {}", path.display())),
        }
    }
    anyhow::bail!(
        "{}: no free backup name; give one with --backup FILE",
        dir.display()
    )
}

#[derive(Serialize)]
struct Summary<'a> {
    rig: &'a str,
    backup: String,
    restore: String,
    steps: &'a [StepReport],
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let existing = files::Existing::from_flags(args.force, false);
    if let Some(p) = &args.backup {
        files::check_output("--backup", p, existing)?;
    } else {
        backup_dir()?;
    }
    rig::catch_interrupt();
    let s = args.rig.connect()?;
    let name = s.name.clone();
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
    let op = Operator {
        yes: args.yes,
        plain: args.plain,
        out: &mut *progress,
    };
    let mut cal = Calibrator::new(s, op);
    let steps: Vec<Step> = match args.step {
        Some(s) => vec![s],
        None => Step::ALL.to_vec(),
    };
    let mut reports = Vec::new();
    for step in steps {
        if rig::interrupted() {
            anyhow::bail!("interrupted; the steps before were written");
        }
        let r = cal.run(step)?;
        cal.write()?;
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
