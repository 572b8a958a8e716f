//! The words kept in RAM across a reset (`.uninit`, which the startup code leaves alone); their
//! format and check are `kapitza_core::rig::retained`. Written only by the control task, read
//! once at boot before any task runs. SRAM1 keeps its contents through a system reset (RM0440,
//! "SRAM1"), and SRAM parity checking is off by default (option bit SRAM_PE), so reading these
//! words before they are written is harmless: at power-up they are noise and fail the CRC.

use core::mem::MaybeUninit;
use core::ptr::{addr_of, addr_of_mut};

use kapitza_core::rig::retained::{self, Retained};

#[link_section = ".uninit.kapitza_retained"]
static mut WORDS: MaybeUninit<[u32; 4]> = MaybeUninit::uninit();

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
