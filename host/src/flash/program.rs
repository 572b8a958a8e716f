//! Writing the image through the probe: confirm the chip's device ID, erase, program and
//! verify with a progress bar, then reset (unless asked not to). Only the pages the image
//! covers are erased, never the whole chip, so the configuration area keeps its record.

use std::path::Path;

use anyhow::Result;
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use probe_rs::flashing::{
    download_file_with_options, DownloadOptions, ElfLoader, ElfOptions, FlashProgress,
    ProgressEvent, ProgressOperation,
};
use probe_rs::MemoryInterface;

use super::board::ProbeBoard;
use super::chip::{self, DBGMCU_IDCODE};

/// Flashes `elf` onto the attached board, verifies it, and resets the core unless `reset` is
/// false (then the new image runs from the next reset).
pub fn program(board: &mut ProbeBoard, elf: &Path, reset: bool) -> Result<()> {
    let mut bars = Bars::new();
    let mut options = DownloadOptions::default();
    options.verify = true;
    options.progress = FlashProgress::new(|e| bars.event(&e));
    download_file_with_options(
        &mut board.session,
        elf,
        ElfLoader(ElfOptions::default()),
        options,
    )
    .map_err(|e| anyhow::anyhow!("flashing failed: {e}"))?;
    if reset {
        board.session.core(0)?.reset()?;
    }
    Ok(())
}

/// Refuses a board whose device ID is not `chip`'s.
pub fn check_chip(board: &mut ProbeBoard, chip: &str) -> Result<()> {
    let idcode = board.session.core(0)?.read_word_32(DBGMCU_IDCODE)?;
    chip::check_dev_id(chip, idcode)
}

/// One progress bar per flashing step (erase, program, verify), on stderr.
struct Bars {
    multi: MultiProgress,
    bars: [Option<ProgressBar>; 4],
}

impl Bars {
    fn new() -> Self {
        Self {
            multi: MultiProgress::new(),
            bars: Default::default(),
        }
    }

    fn event(&mut self, e: &ProgressEvent) {
        match e {
            ProgressEvent::AddProgressBar { operation, total } => {
                let bar = self.multi.add(ProgressBar::new(total.unwrap_or(0)));
                bar.set_style(
                    ProgressStyle::with_template(
                        "{prefix:>8} [{bar:40}] {bytes:>10}/{total_bytes:<10} {bytes_per_sec}",
                    )
                    .expect("template")
                    .progress_chars("=> "),
                );
                bar.set_prefix(name(*operation));
                self.bars[index(*operation)] = Some(bar);
            }
            ProgressEvent::Started(op) => {
                if let Some(b) = &self.bars[index(*op)] {
                    b.reset_elapsed();
                }
            }
            ProgressEvent::Progress {
                operation, size, ..
            } => {
                if let Some(b) = &self.bars[index(*operation)] {
                    b.inc(*size);
                }
            }
            ProgressEvent::Finished(op) => {
                if let Some(b) = &self.bars[index(*op)] {
                    b.finish();
                }
            }
            ProgressEvent::Failed(op) => {
                if let Some(b) = &self.bars[index(*op)] {
                    b.abandon_with_message("failed");
                }
            }
            ProgressEvent::FlashLayoutReady { .. } | ProgressEvent::DiagnosticMessage { .. } => {}
        }
    }
}

fn index(op: ProgressOperation) -> usize {
    match op {
        ProgressOperation::Fill => 0,
        ProgressOperation::Erase => 1,
        ProgressOperation::Program => 2,
        ProgressOperation::Verify => 3,
    }
}

fn name(op: ProgressOperation) -> &'static str {
    match op {
        ProgressOperation::Fill => "read",
        ProgressOperation::Erase => "erase",
        ProgressOperation::Program => "program",
        ProgressOperation::Verify => "verify",
    }
}

#[cfg(test)]
mod tests {
    use super::super::board::denied;
    use probe_rs::probe::{DebugProbeError, ProbeCreationError};
    use std::io::{Error, ErrorKind};

    /// nusb reports a USB node the user may not open as an I/O error, wrapped once or twice.
    #[test]
    fn permission_is_found_in_the_error_chain() {
        let usb = DebugProbeError::Usb(Error::from(ErrorKind::PermissionDenied));
        assert!(denied(&usb));
        let nested = DebugProbeError::ProbeCouldNotBeCreated(ProbeCreationError::Usb(Error::from(
            ErrorKind::PermissionDenied,
        )));
        assert!(denied(&nested));
        let other = DebugProbeError::Usb(Error::from(ErrorKind::TimedOut));
        assert!(!denied(&other));
    }
}
