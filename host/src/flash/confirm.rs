//! After flashing: the board's virtual COM port, and the link's version exchange with the new
//! firmware, retried while it boots.

use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use crate::link::{Client, Error, LineError};
use crate::rig::file::RigFile;
use crate::rig::port::{self, PortInfo, Target};
use crate::rig::session::{self, line_failure, Session};
use crate::rig::simhost::SimOptions;
use crate::rig::{Exit, Failure};

/// How long the firmware has to answer after its reset (it answers within a second; the rest
/// is slack for a slow USB stack).
pub const BOOT_WAIT: Duration = Duration::from_secs(10);

/// The virtual COM port of the ST-LINK with this serial number, or, without one (or none of
/// that serial listed), `--port auto`'s choice.
pub fn vcp_for(probe_serial: Option<&str>) -> Result<Target> {
    let ports: Vec<PortInfo> = port::list()?;
    if let Some(serial) = probe_serial {
        if let Some(p) = ports
            .iter()
            .find(|p| p.stlink && p.serial_number.as_deref() == Some(serial))
        {
            return Ok(Target::Serial {
                path: p.path.clone(),
            });
        }
    }
    port::resolve(Some("auto"))
}

/// Opens `path` and waits up to `wait` for the rig's version answer; a rig that answers with
/// another protocol version fails at once (the image written is not this tool's firmware).
/// Returns the checked session.
pub fn confirm(path: &str, wait: Duration) -> Result<Session> {
    let deadline = Instant::now() + wait;
    loop {
        let answer = port::open_serial(path).map(|p| {
            Client::new(p)
                .with_timeout(Duration::from_millis(300))
                .version()
        });
        let last = match answer {
            Ok(Ok(v)) => {
                session::check_version(&v, path).context(MISMATCH)?;
                break;
            }
            Ok(Err(e @ Error::Line(LineError::VersionMismatch(_)))) => {
                return Err(line_failure(path, e).context(MISMATCH));
            }
            Ok(Err(e)) => line_failure(path, e),
            Err(e) => e,
        };
        if Instant::now() >= deadline {
            let why = format!("{last:#}");
            return Err(Failure::new(
                Exit::NoRig,
                format!(
                    "flashed, but the firmware {SILENT} on {path} within {} s ({why}). Is \
                     that the board's port? Press its reset button and try `kapitza status \
                     --port {path}`",
                    wait.as_secs()
                ),
            )
            .into());
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    let target = Target::Serial { path: path.into() };
    session::open(&target, &SimOptions::new(RigFile::demo(), 1.0))
}

/// In the message of a board that stayed silent ([`is_silent`]).
const SILENT: &str = "did not answer";

/// Whether `e` is [`confirm`]'s timeout: the board never answered (as opposed to answering
/// with another protocol, or no port).
pub fn is_silent(e: &anyhow::Error) -> bool {
    e.downcast_ref::<Failure>()
        .is_some_and(|f| f.exit == Exit::NoRig && f.message.contains(SILENT))
}

const MISMATCH: &str = "after flashing: the image written is not the firmware of this host tool \
    (flash without an ELF to build the firmware from this checkout)";
