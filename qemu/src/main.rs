//! On-target test harness: runs every scenario of `kapitza_core::selftest::rig` and
//! `kapitza_core::selftest::station` (the firmware's rig loop, bytes in and out) on the emulated
//! Cortex-M4F and compares its digest with the expected one — the same digests the host tests
//! check, so a pass here means host and target compute the same bits. Prints one line per
//! scenario and `N passed, N failed`, and exits with a failure status if any failed.

#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use kapitza_core::selftest::rig::CASES;
use kapitza_core::selftest::station::CASES as LOOP_CASES;

#[entry]
fn main() -> ! {
    let mut passed = 0u32;
    let mut failed = 0u32;
    for c in CASES.iter().chain(LOOP_CASES) {
        let got = (c.run)();
        if got == c.expected {
            passed += 1;
            hprintln!("test {} ... ok (0x{:016x})", c.name, got);
        } else {
            failed += 1;
            hprintln!(
                "test {} ... FAILED: got 0x{:016x}, expected 0x{:016x}",
                c.name,
                got,
                c.expected
            );
        }
    }
    hprintln!("{} passed, {} failed", passed, failed);
    debug::exit(if failed == 0 {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::nop();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    hprintln!("0 passed, 1 failed");
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::nop();
    }
}
