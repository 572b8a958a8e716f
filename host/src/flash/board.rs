//! The seam between `kapitza flash` and the debug probe: the few operations the backup, the
//! option-byte check and the silent-board diagnosis need, so host tests drive a fake target.

use std::time::Duration;

use anyhow::Result;
use probe_rs::flashing::{self, DownloadOptions, FlashProgress};
use probe_rs::probe::DebugProbeInfo;
use probe_rs::{MemoryInterface, Permissions, Session};

use super::memory_map::Region;
use super::probes::permission_denied;
use crate::rig::{Exit, Failure};

/// A board attached through a debug probe.
pub trait Board {
    /// Fills `buf` from memory at `address` (flash reads work while the core runs).
    fn read(&mut self, address: u64, buf: &mut [u8]) -> Result<()>;
    /// One 32-bit word at `address` (a register or an option byte).
    fn read_word(&mut self, address: u64) -> Result<u32>;
    /// Halts the core and returns its program counter.
    fn halt_pc(&mut self) -> Result<u64>;
    /// Lets a halted core run on.
    fn resume(&mut self) -> Result<()>;
    /// Erases the flash pages of `region`.
    fn erase(&mut self, region: Region) -> Result<()>;
    /// Writes `data` to flash at `address` (its pages erased first).
    fn write_flash(&mut self, address: u64, data: &[u8]) -> Result<()>;
}

/// How long a running core has to stop when asked (it halts within microseconds).
const HALT_WAIT: Duration = Duration::from_millis(500);

/// A probe-rs session on core 0.
pub struct ProbeBoard {
    pub session: Session,
    /// Attached with the reset line held (the normal attach failed).
    pub under_reset: bool,
}

impl ProbeBoard {
    /// Opens the probe `info` names and attaches to `chip`; when that fails, opens it again and
    /// attaches under reset (probe-rs asserts NRST while it connects), which reaches a core
    /// whose firmware disabled the debug port, slept it, or faulted at once.
    pub fn attach(info: &DebugProbeInfo, chip: &str) -> Result<Self> {
        let first = match open(info)?.attach(chip, Permissions::default()) {
            Ok(session) => {
                return Ok(Self {
                    session,
                    under_reset: false,
                })
            }
            Err(e) => e,
        };
        match open(info)?.attach_under_reset(chip, Permissions::default()) {
            Ok(session) => Ok(Self {
                session,
                under_reset: true,
            }),
            Err(again) => Err(Failure::new(
                Exit::NoRig,
                format!(
                    "cannot attach to {chip} through {}: {first}; under reset too: {again}. Is \
                     the board powered, and is its chip {chip} (--chip)?",
                    info.identifier
                ),
            )
            .into()),
        }
    }
}

fn open(info: &DebugProbeInfo) -> Result<probe_rs::probe::Probe> {
    info.open().map_err(|e| {
        if denied(&e) {
            permission_denied(info)
        } else {
            Failure::new(
                Exit::NoRig,
                format!("cannot open the debug probe {}: {e}", info.identifier),
            )
            .into()
        }
    })
}

/// Whether an open error comes down to the OS refusing access to the USB device.
pub(crate) fn denied(e: &(dyn std::error::Error + 'static)) -> bool {
    let mut cur = Some(e);
    while let Some(err) = cur {
        if err
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::PermissionDenied)
        {
            return true;
        }
        cur = err.source();
    }
    false
}

impl Board for ProbeBoard {
    fn read(&mut self, address: u64, buf: &mut [u8]) -> Result<()> {
        Ok(self.session.core(0)?.read(address, buf)?)
    }

    fn read_word(&mut self, address: u64) -> Result<u32> {
        Ok(self.session.core(0)?.read_word_32(address)?)
    }

    fn halt_pc(&mut self) -> Result<u64> {
        Ok(self.session.core(0)?.halt(HALT_WAIT)?.pc)
    }

    fn resume(&mut self) -> Result<()> {
        Ok(self.session.core(0)?.run()?)
    }

    fn erase(&mut self, region: Region) -> Result<()> {
        flashing::erase(
            &mut self.session,
            &mut FlashProgress::empty(),
            region.start,
            region.end,
            false,
        )?;
        Ok(())
    }

    fn write_flash(&mut self, address: u64, data: &[u8]) -> Result<()> {
        let mut loader = self.session.target().flash_loader();
        loader.add_data(address, data)?;
        let mut options = DownloadOptions::default();
        options.verify = true;
        loader.commit(&mut self.session, options)?;
        Ok(())
    }
}
