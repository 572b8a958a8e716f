//! `kapitza flash`: check the firmware image, write it through the debug probe, reset, and
//! confirm the link's version on the board's virtual COM port.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use probe_rs::probe::list::Lister;
use serde::Serialize;

use super::monitor;
use super::rig_args::RigArgs;
use crate::flash::chip::{self, DEFAULT_CHIP};
use crate::flash::confirm::{self, BOOT_WAIT};
use crate::flash::image::{self, Plan};
use crate::flash::memory_map::MemoryMap;
use crate::flash::{firmware_build, probes, program};
use crate::rig::port::{self, Target};
use crate::rig::{Exit, Failure};

/// Flash the firmware onto the board through its debug probe (the NUCLEO's on-board ST-LINK),
/// verify it, reset the board and check that it answers with this tool's link protocol.
///
/// Before touching the board it checks the ELF: a 32-bit ARM Cortex-M image whose segments fit
/// the flash and RAM of memory.x and leave the configuration page at the end of flash free
/// (the rig's stored configuration survives flashing). Exit status: 0 flashed, 1 the image or
/// chip was refused (nothing written), 3 no probe or no answer from the board.
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
    /// Check the image and print what would be written where; no probe is touched.
    #[arg(long)]
    pub dry_run: bool,
    /// With --dry-run: one JSON object {elf, chip, entry, writes, flash, ram, config_page}.
    #[arg(long, requires = "dry_run")]
    pub json: bool,
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
    let elf = elf.strip_prefix(&cwd).unwrap_or(&elf).to_path_buf();
    if args.dry_run {
        if args.json {
            let report = DryRun {
                elf: elf.display().to_string(),
                chip: &args.chip,
                plan: &plan,
            };
            writeln!(out, "{}", serde_json::to_string_pretty(&report)?)?;
        } else {
            writeln!(
                out,
                "image  {}\nchip   {}\n{}\nnothing written (--dry-run)",
                elf.display(),
                args.chip,
                plan.text()
            )?;
        }
        return Ok(());
    }

    let info = probes::select(lister, selector.as_ref())?;
    writeln!(
        out,
        "flashing {} onto {} through {} ({:04x}:{:04x})",
        elf.display(),
        args.chip,
        info.identifier,
        info.vendor_id,
        info.product_id
    )?;
    program::program(&info, &args.chip, &elf, !args.no_reset)?;
    writeln!(
        out,
        "written and verified: {:.1} KiB; the configuration page was left as it was",
        plan.flash.used as f64 / 1024.0
    )?;
    if args.no_reset {
        writeln!(
            out,
            "not reset (--no-reset): the new firmware starts at the next reset (the board's \
             black button, B2)"
        )?;
        return Ok(());
    }

    let path = board_port(args.port.as_deref(), info.serial_number.as_deref())?;
    let session = confirm::confirm(&path, BOOT_WAIT)?;
    let v = session.version;
    writeln!(
        out,
        "{path}: firmware {}.{}.{} answers, link protocol v{}",
        v.firmware[0], v.firmware[1], v.firmware[2], v.protocol
    )?;
    drop(session);
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
