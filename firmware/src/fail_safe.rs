//! What the chip does when the firmware itself fails: a panic, a HardFault, or an NMI that is
//! not the flash's double-ECC error on the configuration page at boot (that one is expected
//! after a power loss during a configuration write and is handled by `tasks::persist::load`).
//!
//! The drive's outputs are made safe first, by writing the registers directly (whatever state
//! the drivers were left in): the bridge's nSLEEP (PA10) low, TIM1's main output enable (MOE)
//! off so the PWM pin goes to its idle level (low). Then the message is logged, interrupts are
//! masked so no task can wake the bridge again, and the core waits for the independent
//! watchdog to reset it (≤ 100 ms; a panic before the watchdog starts stays in this safe
//! state until the reset button). The last θd and fault are in the retained RAM already.

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};
use embassy_stm32::pac;

/// Bridge asleep, drive PWM off: nothing here can fail or wait.
pub fn outputs_off() {
    // PA10 = nSLEEP: reset its output bit (BSRR's upper half).
    pac::GPIOA.bsrr().write(|w| w.set_br(10, true));
    pac::TIM1.bdtr().modify(|w| w.set_moe(false));
}

fn halt() -> ! {
    cortex_m::interrupt::disable();
    loop {
        cortex_m::asm::nop();
    }
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    outputs_off();
    defmt::error!("panic: {}", defmt::Display2Format(info));
    halt()
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    outputs_off();
    defmt::error!("HardFault at pc = {=u32:#x}", frame.pc());
    halt()
}

/// Set while `tasks::persist::load` reads the configuration page; the NMI handler sets
/// [`ECC_ERROR`] instead of halting when a double ECC error hits during that read.
pub static READING_CONFIG: AtomicBool = AtomicBool::new(false);
/// A double ECC error was detected (and cleared) while reading the configuration page.
pub static ECC_ERROR: AtomicBool = AtomicBool::new(false);

/// A flash read with two bad bits in one double word raises the NMI (RM0440, "Error code
/// correction (ECC)": ECCD set, NMI generated). A power loss while the configuration page is
/// being programmed leaves exactly that; without this handler the boot hangs in the default
/// NMI loop before the watchdog is started. During the configuration read the flag is
/// cleared (written 1) and the read carries on with whatever the word returned: the record's
/// CRC fails and the rig starts on the safe defaults, saying `Defaults(Corrupt)`.
#[exception]
unsafe fn NonMaskableInt() {
    let eccr = pac::FLASH.eccr().read();
    if eccr.eccd() && READING_CONFIG.load(Ordering::Relaxed) {
        pac::FLASH.eccr().modify(|w| w.set_eccd(true));
        ECC_ERROR.store(true, Ordering::Relaxed);
        return;
    }
    outputs_off();
    defmt::error!("NMI (flash ECCR = {=u32:#x})", eccr.0);
    halt()
}
