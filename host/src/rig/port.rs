//! Which rig to talk to, and opening its port.
//!
//! ```text
//! --port PATH      that serial device (a board's virtual COM port, or `kapitza rig serve`'s pty)
//! --port auto      the one ST-LINK virtual COM port attached (several: they are listed, no prompt)
//! --port sim       a simulated rig in this process (`--sim FILE` for its physics)
//! (none)           KAPITZA_PORT if set, else `auto`; nothing found: a hint at `--port sim`
//! ```
//! serialport locks a port it opens, so one process owns a rig at a time.

use std::io::{Read, Write};
use std::time::Duration;

use anyhow::Result;
use kapitza_core::link::BAUD;
use serde::Serialize;

use super::{Exit, Failure};

/// The environment variable that names the port when `--port` is not given.
pub const PORT_ENV: &str = "KAPITZA_PORT";

/// ST-LINK probes with a virtual COM port (vendor 0x0483): V2-1 (0x374B, 0x3752), V3 (0x374E,
/// the NUCLEO-G474RE's V3E; 0x374F, 0x3753, 0x3754, 0x3757).
pub const STLINK_IDS: [(u16, u16); 7] = [
    (0x0483, 0x374B),
    (0x0483, 0x3752),
    (0x0483, 0x374E),
    (0x0483, 0x374F),
    (0x0483, 0x3753),
    (0x0483, 0x3754),
    (0x0483, 0x3757),
];

/// What `--port` asked for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    Serial { path: String },
    Sim,
}

impl Target {
    pub fn describe(&self) -> String {
        match self {
            Self::Serial { path } => path.clone(),
            Self::Sim => "the simulated rig (in-process)".into(),
        }
    }
}

/// One serial port as `kapitza ports` shows it.
#[derive(Debug, Clone, Serialize)]
pub struct PortInfo {
    pub path: String,
    /// `"usb"`, `"pci"`, `"bluetooth"` or `"unknown"`.
    pub kind: &'static str,
    pub vid: Option<u16>,
    pub pid: Option<u16>,
    pub serial_number: Option<String>,
    pub product: Option<String>,
    /// An ST-LINK's virtual COM port: a rig's board.
    pub stlink: bool,
}

/// Every serial port the system lists.
pub fn list() -> Result<Vec<PortInfo>> {
    let ports = serialport::available_ports().unwrap_or_default();
    Ok(ports
        .into_iter()
        .map(|p| {
            let (kind, usb) = match p.port_type {
                serialport::SerialPortType::UsbPort(u) => ("usb", Some(u)),
                serialport::SerialPortType::PciPort => ("pci", None),
                serialport::SerialPortType::BluetoothPort => ("bluetooth", None),
                serialport::SerialPortType::Unknown => ("unknown", None),
            };
            let stlink = usb
                .as_ref()
                .is_some_and(|u| STLINK_IDS.contains(&(u.vid, u.pid)));
            PortInfo {
                path: p.port_name,
                kind,
                vid: usb.as_ref().map(|u| u.vid),
                pid: usb.as_ref().map(|u| u.pid),
                serial_number: usb.as_ref().and_then(|u| u.serial_number.clone()),
                product: usb.and_then(|u| u.product),
                stlink,
            }
        })
        .collect())
}

/// Resolves `--port` (or `KAPITZA_PORT`, or auto-detection) to a target.
pub fn resolve(port: Option<&str>) -> Result<Target> {
    let env = std::env::var(PORT_ENV).ok().filter(|s| !s.is_empty());
    match port.map(str::to_string).or(env).as_deref() {
        Some("sim") => Ok(Target::Sim),
        Some("auto") => auto(true),
        Some(path) => Ok(Target::Serial { path: path.into() }),
        None => auto(false),
    }
}

fn auto(asked: bool) -> Result<Target> {
    let found: Vec<PortInfo> = list()?.into_iter().filter(|p| p.stlink).collect();
    match found.as_slice() {
        [one] => Ok(Target::Serial {
            path: one.path.clone(),
        }),
        [] => {
            let how = if asked {
                "--port auto found no ST-LINK virtual COM port"
            } else {
                "no rig given and none found (no --port, no KAPITZA_PORT, no ST-LINK virtual COM port attached)"
            };
            Err(Failure::new(
                Exit::NoRig,
                format!(
                    "{how}. Plug in the board, name its port with --port PATH (or KAPITZA_PORT), \
                     run `kapitza ports` to list the serial ports, or use --port sim for a \
                     simulated rig"
                ),
            )
            .into())
        }
        many => {
            let list: Vec<String> = many
                .iter()
                .map(|p| {
                    format!(
                        "  {}  (ST-LINK serial {})",
                        p.path,
                        p.serial_number.as_deref().unwrap_or("unknown")
                    )
                })
                .collect();
            Err(Failure::new(
                Exit::NoRig,
                format!(
                    "{} ST-LINK virtual COM ports are attached; choose one with --port PATH:\n{}",
                    many.len(),
                    list.join("\n")
                ),
            )
            .into())
        }
    }
}

/// A byte port to a rig.
pub trait ReadWrite: Read + Write + Send {}
impl<T: Read + Write + Send> ReadWrite for T {}

/// Opens a serial device at the link's speed, with a short read timeout, and drops whatever
/// was waiting in its input (frames from before this connection).
pub fn open_serial(path: &str) -> Result<Box<dyn serialport::SerialPort>> {
    not_a_terminal(path)?;
    let port = serialport::new(path, BAUD)
        .timeout(Duration::from_millis(5))
        .open()
        .map_err(|e| open_error(path, e))?;
    port.clear(serialport::ClearBuffer::Input)
        .map_err(|e| Failure::new(Exit::NoRig, format!("{path}: cannot clear its input: {e}")))?;
    Ok(port)
}

/// Refuses a path that exists and is not a terminal device (a file, a FIFO, `/dev/null`): "not
/// a serial port", before the serial layer's own words for it ("Not a typewriter"). A FIFO is
/// never opened; a device is opened without blocking or becoming the controlling terminal.
#[cfg(unix)]
fn not_a_terminal(path: &str) -> Result<()> {
    use std::os::fd::AsRawFd;
    use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(());
    };
    let what = if meta.file_type().is_char_device() {
        let f = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
            .open(path);
        match f {
            // SAFETY: isatty on a descriptor this function owns.
            Ok(f) if unsafe { libc::isatty(f.as_raw_fd()) } == 0 => {
                "a device that is not a terminal"
            }
            // A terminal, or an error the serial layer reports in its own words.
            _ => return Ok(()),
        }
    } else if meta.is_dir() {
        "a directory"
    } else if meta.file_type().is_fifo() {
        "a FIFO (named pipe)"
    } else {
        "a file"
    };
    anyhow::bail!("--port {path} is not a serial port ({what}); `kapitza ports` lists them")
}

#[cfg(not(unix))]
fn not_a_terminal(_path: &str) -> Result<()> {
    Ok(())
}

fn open_error(path: &str, e: serialport::Error) -> anyhow::Error {
    let hint = match e.kind() {
        serialport::ErrorKind::Io(std::io::ErrorKind::PermissionDenied) => {
            if cfg!(target_os = "linux") {
                ": permission denied. Serial ports belong to the group `dialout`: add yourself \
                 with `sudo usermod -aG dialout $USER`, then log out and in again"
            } else {
                ": permission denied"
            }
        }
        serialport::ErrorKind::NoDevice
        | serialport::ErrorKind::Io(std::io::ErrorKind::NotFound) => {
            ": no such device (is the board plugged in? `kapitza ports` lists the serial ports)"
        }
        _ => "",
    };
    let busy = e.to_string().contains("busy") || e.to_string().contains("lock");
    let extra = if busy {
        " (another program has it open: only one may own a rig's port)"
    } else {
        ""
    };
    Failure::new(Exit::NoRig, format!("cannot open {path}: {e}{hint}{extra}")).into()
}
