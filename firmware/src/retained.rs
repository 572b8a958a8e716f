//! The words kept in RAM across a reset (`.uninit`, which the startup code leaves alone); their
//! format and check are `kapitza_core::rig::retained`. The rig record is written only by the
//! control task; the crash record only by a fault handler (`fail_safe`), just before it resets
//! the chip. Both are read once at boot before any task runs. SRAM1 keeps its contents through
//! a system reset (RM0440, "SRAM1"), and SRAM parity checking is off by default (option bit
//! SRAM_PE), so reading these words before they are written is harmless: at power-up they are
//! noise and fail the CRC.

use core::mem::MaybeUninit;
use core::ptr::{addr_of, addr_of_mut};

use kapitza_core::rig::retained::{self, Crash, Retained};

#[link_section = ".uninit.kapitza_retained"]
static mut WORDS: MaybeUninit<[u32; 4]> = MaybeUninit::uninit();

#[link_section = ".uninit.kapitza_crash"]
static mut CRASH: MaybeUninit<[u32; 4]> = MaybeUninit::uninit();

/// The record left by the firmware before the last reset, if there is one.
pub fn load() -> Option<Retained> {
    // SAFETY: read once at boot, before the control task (the only writer) is spawned; every
    // bit pattern is a valid [u32; 4].
    let w = unsafe { core::ptr::read_volatile(addr_of!(WORDS).cast::<[u32; 4]>()) };
    retained::decode(w)
}

/// Keeps `r` for after the next reset.
pub fn store(r: &Retained) {
    // SAFETY: only the control task calls this, from one executor: no concurrent access.
    unsafe {
        core::ptr::write_volatile(addr_of_mut!(WORDS).cast::<[u32; 4]>(), retained::encode(r))
    }
}

/// The crash record left before the last reset, if there is one; cleared, so that only the
/// reset right after a crash reports it.
pub fn take_crash() -> Option<Crash> {
    // SAFETY: at boot, before any task runs; the fault handlers write it only on their way
    // to a reset.
    unsafe {
        let p = addr_of_mut!(CRASH).cast::<[u32; 4]>();
        let c = retained::decode_crash(core::ptr::read_volatile(p));
        core::ptr::write_volatile(p, [0; 4]);
        c
    }
}

/// Records `c` for the next boot (called once, by the first fault handler entered).
pub fn store_crash(c: &Crash) {
    // SAFETY: the fault handlers' re-entry guard lets only the first one through; nothing
    // else writes these words after boot.
    unsafe {
        core::ptr::write_volatile(
            addr_of_mut!(CRASH).cast::<[u32; 4]>(),
            retained::encode_crash(c),
        )
    }
}
