//! The independent watchdog (its own 32 kHz oscillator): it resets the chip if the control loop
//! stops ticking, and is fed only when a control tick arrives. Its timeout is
//! `kapitza_core::rig::watchdog::TIMEOUT_US` (72.9 ms): at least three control periods and the
//! longest step this executor can block for (a 2 KiB flash page erased and programmed), for
//! the slowest control rate any accepted configuration can have, so a `SetConfig` never needs
//! to reprogram it. After a reset the bridge's inputs are pulled low (off) until the firmware
//! is up, and the rig starts idle.
//! It is frozen while a debugger halts the core (main.rs sets DBGMCU), as is TIM1, whose
//! outputs are then disabled as if MOE were cleared (RM0440, TIM1 "Debug mode").
//!
//! The e-stop is read by the control task at every control tick and debounced there
//! (`kapitza_core::rig::estop`); its second contact cuts the bridge supply in hardware.

use embassy_stm32::wdg::IndependentWatchdog;
use kapitza_core::rig::watchdog::TIMEOUT_US;

use crate::board::SafetyIo;
use crate::channels::HEARTBEAT;

#[embassy_executor::task]
pub async fn run(io: SafetyIo) {
    let mut wdg = IndependentWatchdog::new(io.iwdg, TIMEOUT_US);
    wdg.unleash();
    loop {
        HEARTBEAT.wait().await;
        wdg.pet();
    }
}
