//! Safety I/O: the emergency-stop line and the independent watchdog.
//!
//! The e-stop is a normally-closed contact to ground with the input pulled up: pressed, or a
//! cut wire, reads high and stops the rig. Its second contact cuts the H-bridge supply in
//! hardware (`docs/hardware.md`); this input tells the supervisor, which latches the fault.
//! The state is published on every edge and re-read at every control tick, so a missed edge
//! costs at most one tick.
//!
//! The independent watchdog (its own 32 kHz oscillator) resets the chip if the control loop
//! stops ticking for `WATCHDOG_US`: it is fed only when a control tick arrives. After a reset
//! the bridge's inputs are pulled low (off) until the firmware is up, and the rig starts idle.

use embassy_futures::select::{select, Either};
use embassy_stm32::wdg::IndependentWatchdog;

use crate::board::SafetyIo;
use crate::channels::{ESTOP, HEARTBEAT};

/// The watchdog's timeout: 100 control ticks at 1 kHz.
const WATCHDOG_US: u32 = 100_000;

#[embassy_executor::task]
pub async fn run(io: SafetyIo) {
    let SafetyIo { mut estop, iwdg } = io;
    let mut wdg = IndependentWatchdog::new(iwdg, WATCHDOG_US);
    wdg.unleash();
    let tx = ESTOP.sender();
    let mut last = estop.is_high();
    tx.send(last);
    loop {
        let tick = select(estop.wait_for_any_edge(), HEARTBEAT.wait()).await;
        if let Either::Second(()) = tick {
            wdg.pet();
        }
        let now = estop.is_high();
        if now != last {
            last = now;
            tx.send(now);
            if now {
                defmt::warn!("e-stop pressed");
            } else {
                defmt::info!("e-stop released");
            }
        }
    }
}
