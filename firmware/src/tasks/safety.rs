//! The independent watchdog (its own 32 kHz oscillator): it resets the chip if the control loop
//! stops ticking for `WATCHDOG_US`, and is fed only when a control tick arrives. After a reset
//! the bridge's inputs are pulled low (off) until the firmware is up, and the rig starts idle.
//! It is frozen while a debugger halts the core (main.rs sets DBGMCU), as is TIM1, whose
//! outputs are then disabled as if MOE were cleared (RM0440, TIM1 "Debug mode").
//!
//! The e-stop is read by the control task at every control tick and debounced there
//! (`kapitza_core::rig::estop`); its second contact cuts the bridge supply in hardware.

use embassy_stm32::wdg::IndependentWatchdog;

use crate::board::SafetyIo;
use crate::channels::HEARTBEAT;

/// The watchdog's timeout: 100 control ticks at 1 kHz.
const WATCHDOG_US: u32 = 100_000;

#[embassy_executor::task]
pub async fn run(io: SafetyIo) {
    let mut wdg = IndependentWatchdog::new(io.iwdg, WATCHDOG_US);
    wdg.unleash();
    loop {
        HEARTBEAT.wait().await;
        wdg.pet();
    }
}
