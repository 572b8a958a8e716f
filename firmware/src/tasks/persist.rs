//! The stored configuration: read once at power-up, written when the link's `SetConfig` is
//! accepted. The record format, its checksum and the fallback are `kapitza_core::persist`;
//! this task only moves bytes.
//!
//! The record lives in the last 2 KiB page of flash (bank 2 in the G474's dual-bank mode),
//! `board::CONFIG_PAGE_OFFSET`. `persist.x` makes the link fail if the program image ever
//! reaches it. Writing erases that page and programs the record (64-bit words), then reads it
//! back; bank 2 is erased while the program runs from bank 1 (read-while-write), so the control
//! loop keeps running; the link task waits (≈ 25 ms) with its bytes in the UART buffer.

use core::sync::atomic::Ordering;

use defmt::{info, warn};
use embassy_stm32::flash::{Blocking, Flash};
use kapitza_core::persist::{self, ConfigOrigin, RECORD_MAX};
use kapitza_core::rig::config::RigConfig;

use crate::board::{CONFIG_PAGE_OFFSET, CONFIG_PAGE_SIZE};
use crate::channels::{CONFIG_SAVED, SAVE_CONFIG};
use crate::fail_safe::{ECC_ERROR, READING_CONFIG};

/// The configuration to start with, and where it came from (never fails: see
/// `kapitza_core::persist::load`).
///
/// A double ECC error in the page (a power loss mid-write) raises an NMI, which
/// `fail_safe::NonMaskableInt` clears while this read runs: the record then counts as corrupt.
pub fn load(flash: &mut Flash<'static, Blocking>) -> (RigConfig, ConfigOrigin) {
    let mut buf = [0u8; RECORD_MAX];
    READING_CONFIG.store(true, Ordering::SeqCst);
    let read = flash.blocking_read(CONFIG_PAGE_OFFSET, &mut buf);
    READING_CONFIG.store(false, Ordering::SeqCst);
    if ECC_ERROR.load(Ordering::SeqCst) {
        warn!("persist: double ECC error in the configuration page (power lost mid-write?)");
        return (
            RigConfig::REFERENCE,
            ConfigOrigin::Defaults(persist::Fallback::Corrupt),
        );
    }
    match read {
        Ok(()) => persist::load(&buf),
        Err(e) => {
            warn!("persist: flash read failed: {}", e);
            (
                RigConfig::REFERENCE,
                ConfigOrigin::Defaults(persist::Fallback::Corrupt),
            )
        }
    }
}

fn store(flash: &mut Flash<'static, Blocking>, cfg: &RigConfig) -> bool {
    let mut buf = [0u8; RECORD_MAX];
    let n = persist::encode(cfg, &mut buf);
    let end = CONFIG_PAGE_OFFSET + CONFIG_PAGE_SIZE;
    if let Err(e) = flash.blocking_erase(CONFIG_PAGE_OFFSET, end) {
        warn!("persist: erase failed: {}", e);
        return false;
    }
    if let Err(e) = flash.blocking_write(CONFIG_PAGE_OFFSET, &buf[..n]) {
        warn!("persist: write failed: {}", e);
        return false;
    }
    let mut back = [0u8; RECORD_MAX];
    let ok = flash.blocking_read(CONFIG_PAGE_OFFSET, &mut back).is_ok()
        && persist::decode(&back) == Ok(*cfg);
    if !ok {
        warn!("persist: read-back mismatch");
    }
    ok
}

#[embassy_executor::task]
pub async fn run(mut flash: Flash<'static, Blocking>) {
    loop {
        let cfg = SAVE_CONFIG.wait().await;
        let ok = store(&mut flash, &cfg);
        info!("persist: configuration stored: {}", ok);
        CONFIG_SAVED.signal(ok);
    }
}
