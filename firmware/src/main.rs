//! Firmware for the kapitza pendulum shaker rig (reference board: NUCLEO-G474RE).
//!
//! This file only wires: chip clocks and peripherals (`board`), the stored configuration
//! (`tasks::persist::load`), two executors, and one task per job (`tasks`), which talk through
//! `channels`. The rig logic itself is `kapitza_core::rig`, the link protocol
//! `kapitza_core::link`; both are tested on the host.
//!
//! ```text
//! control executor (UART4 interrupt, priority 6): pendulum sampling, control loop
//! thread executor (main):                          tilt servo, safety/watchdog, link, persist
//! time driver: TIM2 (the drive's PWM is TIM1)
//! ```

#![no_std]
#![no_main]

mod board;
mod channels;
mod fail_safe;
mod retained;
mod tasks;

use defmt::{info, unwrap, warn};
use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, Spawner};
use embassy_stm32::pac;
use embassy_time::Timer;
use kapitza_core::link::message::{ResetCause, ResetInfo};
use kapitza_core::persist::{self, ConfigOrigin};
use kapitza_core::rig::servo;

/// Firmware version, from this crate's Cargo.toml.
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The executor of the time-critical tasks, run from `board::CONTROL_IRQ`.
pub static CONTROL_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_stm32::init(board::chip_config());
    info!("kapitza firmware v{=str} on {=str}", VERSION, board::NAME);
    // A debugger halting the core freezes the watchdog (so a breakpoint does not reset the
    // chip) and TIM1 (whose outputs are then disabled, as if MOE were cleared).
    pac::DBGMCU.apb1lfzr().modify(|w| w.set_iwdg(true));
    pac::DBGMCU.apb2fzr().modify(|w| w.set_tim1(true));
    let cause = reset_cause();
    info!("reset cause: {}", cause);
    let kept = retained::load();
    if let Some(k) = kept {
        info!(
            "before the reset: theta_d = {=f32} deg, last fault {}",
            k.theta_d_deg, k.last_fault
        );
    }
    let b = board::split(p);

    // The e-stop held at power-up boots on the safe defaults, the stored configuration left
    // alone (kapitza_core::persist::store::boot). The first reading 1 ms after the pull-up is on.
    let mut estop = [false; persist::store::ESTOP_BOOT_READINGS];
    for r in &mut estop {
        Timer::after_millis(1).await;
        *r = b.drive.estop_active();
    }
    let mut flash = tasks::persist::Guarded(b.flash);
    let (cfg, origin) = tasks::persist::load(&mut flash, persist::store::estop_held(estop));
    match origin {
        ConfigOrigin::Stored => info!("configuration: stored"),
        ConfigOrigin::Repaired { defaulted } => warn!(
            "configuration: stored, fields out of range at their defaults ({=u64:#x})",
            defaulted.0
        ),
        other => warn!("configuration: safe defaults ({})", other),
    }
    // The sample rate, before any task can ask for it.
    channels::SAMPLE_HZ.sender().send(cfg.sample_hz);
    // θd at power-up: the one commanded before a reset, else the park angle.
    let theta_d0 = servo::power_up_deg(kept.map(|k| f64::from(k.theta_d_deg)), &cfg);

    let control = CONTROL_EXECUTOR.start(board::CONTROL_IRQ);
    control.spawn(unwrap!(tasks::pendulum::run(b.pendulum, cfg.sample_hz)));
    let reset = ResetInfo {
        cause,
        last_fault: kept.and_then(|k| k.last_fault).map(Into::into),
    };
    control.spawn(unwrap!(tasks::control::run(
        b.drive, cfg, origin, theta_d0, kept, reset
    )));

    spawner.spawn(unwrap!(tasks::tilt::run(b.tilt)));
    spawner.spawn(unwrap!(tasks::safety::run(b.safety)));
    spawner.spawn(unwrap!(tasks::link::run(b.uart)));
    spawner.spawn(unwrap!(tasks::persist::run(flash)));
}

/// Why the chip last reset (RCC_CSR's flags, cleared here so the next reset reports its own).
/// A power-on sets BORRSTF and PINRSTF together (RM0440, "RCC_CSR"): brown-out is checked
/// before the pin.
fn reset_cause() -> ResetCause {
    let csr = pac::RCC.csr().read();
    pac::RCC.csr().modify(|w| w.set_rmvf(true));
    if csr.iwdgrstf() {
        ResetCause::Watchdog
    } else if csr.sftrstf() {
        ResetCause::Software
    } else if csr.wwdgrstf() || csr.lpwrrstf() || csr.oblrstf() {
        ResetCause::Other
    } else if csr.borrstf() {
        ResetCause::PowerOn
    } else if csr.pinrstf() {
        ResetCause::Pin
    } else {
        ResetCause::Other
    }
}
