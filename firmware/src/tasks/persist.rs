//! The stored configuration: read once at power-up, written when the link's `SetConfig` is
//! accepted. The record format, the two-page store that survives a power cut, and the fallback
//! are `kapitza_core::persist`; this task only gives it the chip's flash.
//!
//! The area is the last 4 KiB of flash (two 2 KiB pages of bank 2 in the G474's dual-bank
//! mode), `board::CONFIG_PAGE_OFFSET`. `persist.x` makes the link fail if the program image ever
//! reaches it. A store erases one page and programs the record (64-bit words), then reads it
//! back; bank 2 is erased while the program runs from bank 1 (read-while-write), so the control
//! loop keeps running; the link task waits (≈ 25 ms) with its bytes in the UART buffer.

use core::sync::atomic::Ordering;

use defmt::{info, warn};
use embassy_stm32::flash::{Blocking, Flash};
use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use kapitza_core::persist::store::{self, Area};
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::config::RigConfig;

use crate::board::{CONFIG_PAGE_OFFSET, CONFIG_PAGE_SIZE};
use crate::channels::{CONFIG_SAVED, SAVE_CONFIG};
use crate::fail_safe::{ECC_ERROR, READING_CONFIG};

const AREA: Area = Area {
    offset: CONFIG_PAGE_OFFSET,
    size: CONFIG_PAGE_SIZE,
};

/// The chip's flash, each read guarded against a double ECC error: a power loss mid-program
/// leaves a word that raises the NMI when read, which `fail_safe::NonMaskableInt` clears while
/// [`READING_CONFIG`] is set; the read then fails, and the store counts that page as corrupt.
pub struct Guarded(pub Flash<'static, Blocking>);

#[derive(Debug, defmt::Format)]
pub enum GuardedError {
    Flash(embassy_stm32::flash::Error),
    Ecc,
}

impl NorFlashError for GuardedError {
    fn kind(&self) -> NorFlashErrorKind {
        NorFlashErrorKind::Other
    }
}

impl ErrorType for Guarded {
    type Error = GuardedError;
}

impl ReadNorFlash for Guarded {
    const READ_SIZE: usize = <Flash<'static, Blocking> as ReadNorFlash>::READ_SIZE;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), GuardedError> {
        ECC_ERROR.store(false, Ordering::SeqCst);
        READING_CONFIG.store(true, Ordering::SeqCst);
        let r = self.0.blocking_read(offset, bytes);
        READING_CONFIG.store(false, Ordering::SeqCst);
        if ECC_ERROR.load(Ordering::SeqCst) {
            warn!(
                "persist: double ECC error at {=u32:#x} (power lost mid-write?)",
                offset
            );
            return Err(GuardedError::Ecc);
        }
        r.map_err(GuardedError::Flash)
    }

    fn capacity(&self) -> usize {
        self.0.capacity()
    }
}

impl NorFlash for Guarded {
    const WRITE_SIZE: usize = <Flash<'static, Blocking> as NorFlash>::WRITE_SIZE;
    const ERASE_SIZE: usize = <Flash<'static, Blocking> as NorFlash>::ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), GuardedError> {
        self.0.blocking_erase(from, to).map_err(GuardedError::Flash)
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), GuardedError> {
        self.0
            .blocking_write(offset, bytes)
            .map_err(GuardedError::Flash)
    }
}

/// The configuration to start with, and where it came from (never fails: see
/// `kapitza_core::persist::store::boot`); `estop`: the e-stop was held at power-up.
pub fn load(flash: &mut Guarded, estop: bool) -> (RigConfig, ConfigOrigin) {
    store::boot(flash, &AREA, estop)
}

#[embassy_executor::task]
pub async fn run(mut flash: Guarded) {
    loop {
        let req = SAVE_CONFIG.wait().await;
        let ok = match store::store(&mut flash, &AREA, &req.cfg) {
            Ok(seq) => {
                info!("persist: configuration stored, sequence {=u32}", seq);
                true
            }
            Err(e) => {
                warn!("persist: store failed: {}", e);
                false
            }
        };
        CONFIG_SAVED.signal((req.tag, ok));
    }
}
