//! `kapitza ports`: the serial ports this machine has, ST-LINK virtual COM ports marked.

use std::io::Write;

use anyhow::Result;

use crate::rig::port;

/// List the serial ports; ST-LINK virtual COM ports (a rig's board) are marked with their
/// serial numbers. `--port auto` picks the ST-LINK port when there is exactly one.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// One JSON array of {path, kind, vid, pid, serial_number, product, stlink}.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let ports = port::list()?;
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&ports)?)?;
        return Ok(());
    }
    if ports.is_empty() {
        writeln!(
            out,
            "no serial ports found. Without hardware: `kapitza rig serve` makes a simulated rig \
             on a pseudo-terminal, or use --port sim"
        )?;
    }
    for p in &ports {
        let usb = match (p.vid, p.pid) {
            (Some(v), Some(d)) => format!("  {v:04x}:{d:04x}"),
            _ => String::new(),
        };
        let mark = if p.stlink {
            format!(
                "  ST-LINK (a rig's board), serial {}",
                p.serial_number.as_deref().unwrap_or("unknown")
            )
        } else {
            String::new()
        };
        writeln!(
            out,
            "{}  {}{usb}{}{mark}",
            p.path,
            p.kind,
            p.product
                .as_deref()
                .map(|s| format!("  {s}"))
                .unwrap_or_default()
        )?;
    }
    Ok(())
}
