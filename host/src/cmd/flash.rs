//! `kapitza flash`: check the firmware image, back up the board's stored configuration, check
//! its option bytes, write the image through the debug probe, reset, and confirm the link's
//! version on the board's virtual COM port; a board that stays silent is asked, through the
//! probe, where its core waits.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Result;
use probe_rs::probe::list::Lister;
use serde::Serialize;

use super::monitor;
use super::rig_args::RigArgs;
use crate::flash::backup::{self, Backup};
use crate::flash::board::ProbeBoard;
use crate::flash::chip::{self, DEFAULT_CHIP};
use crate::flash::confirm::{self, BOOT_WAIT};
use crate::flash::diagnose::{self, Diagnosis};
use crate::flash::image::{self, Plan};
use crate::flash::memory_map::{MemoryMap, Region};
use crate::flash::option_bytes::OptionBytes;
use crate::flash::{firmware_build, probes, program};
use crate::rig::port::{self, Target};
use crate::rig::{Exit, Failure};

/// Flash the firmware onto the board through its debug probe (the NUCLEO's on-board ST-LINK),
/// verify it, reset the board and check that it answers with this tool's link protocol.
///
/// Before touching the board it checks the ELF: a 32-bit ARM Cortex-M image whose segments fit
/// the flash and RAM of memory.x and leave the configuration area at the end of flash free
/// (the rig's stored configuration survives flashing). Once attached it refuses a chip with
/// read-out protection or in single-bank mode, and saves the configuration area to a new file
/// in the data folder's kapitza/backups/ before anything is written. Exit status: 0 flashed,
/// 1 the image or chip was refused (nothing written), 3 no probe, no backup, or no answer from
/// the board.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// The firmware ELF to write. Without it: `cargo build --release` in firmware/, and its
    /// image.
    pub elf: Option<PathBuf>,
    /// The debug probe as `kapitza probes` lists it: VID:PID or VID:PID:SERIAL (hexadecimal
    /// IDs). Needed when several are attached.
    #[arg(long, value_name = "VID:PID[:SERIAL]")]
    pub probe: Option<String>,
    /// The microcontroller, as probe-rs names it.
    #[arg(long, default_value = DEFAULT_CHIP, value_name = "NAME")]
    pub chip: String,
    /// Do not reset after flashing: the new firmware starts at the next reset, and the version
    /// is not checked.
    #[arg(long)]
    pub no_reset: bool,
    /// After flashing, watch the rig (`kapitza monitor` on the board's port).
    #[arg(long, conflicts_with_all = ["no_reset", "dry_run"])]
    pub monitor: bool,
    /// Check the image and print what would be written, backed up and erased; no probe is
    /// touched.
    #[arg(long)]
    pub dry_run: bool,
    /// One JSON object on stdout instead of the report. With --dry-run: {elf, chip, entry,
    /// writes, flash, ram, config_page, backup_dir, erase_config, restore_config}; flashing:
    /// {elf, chip, probe, under_reset, option_bytes, backup, config_erased, config_restored,
    /// written, reset, port, firmware, protocol}.
    #[arg(long, conflicts_with = "monitor")]
    pub json: bool,
    /// Flash even when the configuration area cannot be read through the probe (no backup).
    #[arg(long)]
    pub no_backup: bool,
    /// Erase the configuration area (after the backup): the firmware starts from its
    /// defaults. Without it flashing never touches the area.
    #[arg(long)]
    pub erase_config: bool,
    /// After flashing, write this backup (a file `kapitza flash` saved) back into the
    /// configuration area.
    #[arg(long, value_name = "FILE", conflicts_with = "erase_config")]
    pub restore_config: Option<PathBuf>,
    /// The board's virtual COM port for the version check (default: the one of the ST-LINK
    /// flashed through, else the one ST-LINK port attached).
    #[arg(long, value_name = "PORT")]
    pub port: Option<String>,
}

/// `--dry-run --json`.
#[derive(Debug, Serialize)]
struct DryRun<'a> {
    elf: String,
    chip: &'a str,
    #[serde(flatten)]
    plan: &'a Plan,
    backup_dir: Option<PathBuf>,
    erase_config: bool,
    restore_config: Option<&'a Path>,
}

/// `--json` after flashing.
#[derive(Debug, Serialize)]
struct Flashed<'a> {
    elf: String,
    chip: &'a str,
    probe: String,
    /// The normal attach failed and the probe connected with the reset line held.
    under_reset: bool,
    option_bytes: OptionBytes,
    backup: Backup,
    config_erased: bool,
    config_restored: Option<PathBuf>,
    /// Bytes of the image written to flash.
    written: u64,
    reset: bool,
    port: Option<String>,
    firmware: Option<String>,
    protocol: Option<u32>,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    run_with(args, &Lister::new(), out)
}

/// [`run`] with the probes `lister` finds.
pub fn run_with(args: &Args, lister: &Lister, out: &mut dyn Write) -> Result<()> {
    let selector = args
        .probe
        .as_deref()
        .map(probes::parse_selector)
        .transpose()?;
    let map = MemoryMap::firmware();
    chip::check_memory(&chip::resolve(&args.chip)?, &map)?;
    let elf = match &args.elf {
        Some(p) => p.clone(),
        None => firmware_build::build(&firmware_build::firmware_dir()?)?,
    };
    let plan = image::check_file(&elf, &map)?;
    let cwd = std::env::current_dir()?;
    let elf_path = elf.clone();
    let elf = elf.strip_prefix(&cwd).unwrap_or(&elf).to_path_buf();
    let area = map.config_page;
    if args.dry_run {
        return dry_run(args, &elf, &plan, area, out);
    }

    let mut opts = backup::Options {
        area,
        dir: backup::backup_dir()?,
        board: String::new(),
        no_backup: args.no_backup,
        erase: args.erase_config,
        restore: args.restore_config.clone(),
    };
    let info = probes::select(lister, selector.as_ref())?;
    opts.board = info.serial_number.clone().unwrap_or_default();
    let mut text = |line: String| -> Result<()> {
        if !args.json {
            writeln!(out, "{line}")?;
        }
        Ok(())
    };
    text(format!(
        "flashing {} onto {} through {} ({:04x}:{:04x})",
        elf.display(),
        args.chip,
        info.identifier,
        info.vendor_id,
        info.product_id
    ))?;
    let mut board = ProbeBoard::attach(&info, &args.chip)?;
    if board.under_reset {
        text("the normal attach failed: connected under reset (the probe held NRST)".into())?;
    }
    program::check_chip(&mut board, &args.chip)?;
    let prepared = backup::prepare(&mut board, &opts)?;
    text(prepared.option_bytes.text())?;
    text(prepared.backup.text())?;
    program::program(&mut board, &elf_path, !args.no_reset)?;
    let restored = backup::restore(&mut board, &opts)?;
    let kept = match (&restored, prepared.erased) {
        (Some(p), _) => format!("the configuration area was restored from {}", p.display()),
        (None, true) => "the configuration area was erased (--erase-config)".into(),
        (None, false) => "the configuration area was left as it was".into(),
    };
    text(format!(
        "written and verified: {:.1} KiB; {kept}",
        plan.flash.used as f64 / 1024.0
    ))?;
    let mut report = Flashed {
        elf: elf.display().to_string(),
        chip: &args.chip,
        probe: info.identifier.clone(),
        under_reset: board.under_reset,
        option_bytes: prepared.option_bytes,
        backup: prepared.backup,
        config_erased: prepared.erased,
        config_restored: restored,
        written: plan.flash.used,
        reset: !args.no_reset,
        port: None,
        firmware: None,
        protocol: None,
    };
    if args.no_reset {
        text(
            "not reset (--no-reset): the new firmware starts at the next reset (the board's \
             black button, B2)"
                .into(),
        )?;
        return json_report(args, &report, out);
    }

    let path = board_port(args.port.as_deref(), info.serial_number.as_deref())?;
    let session = match confirm::confirm(&path, BOOT_WAIT) {
        Ok(s) => s,
        Err(e) if confirm::is_silent(&e) => return Err(silent(e, &mut board, &elf_path)),
        Err(e) => return Err(e),
    };
    drop(board);
    let v = session.version;
    let firmware = format!("{}.{}.{}", v.firmware[0], v.firmware[1], v.firmware[2]);
    text(format!(
        "{path}: firmware {firmware} answers, link protocol v{}",
        v.protocol
    ))?;
    drop(session);
    report.port = Some(path.clone());
    report.firmware = Some(firmware);
    report.protocol = Some(v.protocol.into());
    if args.json {
        return json_report(args, &report, out);
    }
    if args.monitor {
        let m = monitor::Args {
            rig: RigArgs {
                port: Some(path),
                sim: None,
                speed: 1.0,
            },
            csv: None,
            force: false,
            append: false,
            duration: None,
            plain: false,
        };
        monitor::run(&m, out)?;
    } else {
        writeln!(
            out,
            "next: `kapitza calibrate`, then `kapitza demo --port auto`"
        )?;
    }
    Ok(())
}

fn json_report(args: &Args, report: &Flashed, out: &mut dyn Write) -> Result<()> {
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(report)?)?;
    }
    Ok(())
}

/// `--dry-run`: the image's writes, and what would be backed up and erased.
fn dry_run(args: &Args, elf: &Path, plan: &Plan, area: Region, out: &mut dyn Write) -> Result<()> {
    let dir = backup::backup_dir().ok();
    if args.json {
        let report = DryRun {
            elf: elf.display().to_string(),
            chip: &args.chip,
            plan,
            backup_dir: dir,
            erase_config: args.erase_config,
            restore_config: args.restore_config.as_deref(),
        };
        writeln!(out, "{}", serde_json::to_string_pretty(&report)?)?;
        return Ok(());
    }
    let dir = dir.map_or("(no data folder: set XDG_DATA_HOME or HOME)".into(), |d| {
        d.display().to_string()
    });
    let what = match (&args.restore_config, args.erase_config) {
        (Some(f), _) => format!(
            "would erase it and write {} back into it after the image",
            f.display()
        ),
        (None, true) => "would erase it after the backup (--erase-config)".into(),
        (None, false) => "would leave it as it is".into(),
    };
    let backup = if args.no_backup {
        "flashing on if it cannot be read (--no-backup)"
    } else {
        "stopping if it cannot be read"
    };
    writeln!(
        out,
        "image  {}\nchip   {}\n{}\nwould check the option bytes (FLASH_OPTR: RDP level 0, \
         DBANK = 1)\nwould back up the configuration area {:#010x}..{:#010x} ({} bytes) to a new \
         file in {dir}, unless it is blank; {backup}\n{what}\nnothing written (--dry-run)",
        elf.display(),
        args.chip,
        plan.text(),
        area.start,
        area.end,
        area.len()
    )?;
    Ok(())
}

/// A board silent after flashing: where its core is, added to the timeout's message.
fn silent(e: anyhow::Error, board: &mut ProbeBoard, elf: &Path) -> anyhow::Error {
    let image = std::fs::read(elf).unwrap_or_default();
    let why = match diagnose::diagnose(board, &image) {
        Ok(d) => Diagnosis::text(&d),
        Err(err) => format!("halting the core through the probe failed too: {err:#}"),
    };
    Failure::new(Exit::NoRig, format!("{e:#}\n{why}")).into()
}

/// The serial port the flashed board answers on.
fn board_port(port: Option<&str>, probe_serial: Option<&str>) -> Result<String> {
    let target = match port {
        Some(p) => port::resolve(Some(p))?,
        None => confirm::vcp_for(probe_serial)?,
    };
    match target {
        Target::Serial { path } => Ok(path),
        Target::Sim => Err(Failure::new(
            Exit::Refused,
            "--port sim is not a board: name the board's serial port",
        )
        .into()),
    }
}
