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
mod tasks;

use defmt::{info, unwrap, warn};
use embassy_executor::{InterruptExecutor, Spawner};
use kapitza_core::persist::ConfigOrigin;
use {defmt_rtt as _, panic_probe as _};

/// Firmware version, from this crate's Cargo.toml.
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The executor of the time-critical tasks, run from `board::CONTROL_IRQ`.
pub static CONTROL_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_stm32::init(board::chip_config());
    info!("kapitza firmware v{=str} on {=str}", VERSION, board::NAME);
    let mut b = board::split(p);

    let (cfg, origin) = tasks::persist::load(&mut b.flash);
    match origin {
        ConfigOrigin::Stored => info!("configuration: stored"),
        other => warn!("configuration: safe defaults ({})", other),
    }
    // The first e-stop reading and the sample rate, before any task can ask for them.
    channels::ESTOP.sender().send(b.safety.estop_active());
    channels::SAMPLE_HZ.sender().send(cfg.sample_hz);

    let control = CONTROL_EXECUTOR.start(board::CONTROL_IRQ);
    control.spawn(unwrap!(tasks::pendulum::run(b.pendulum, cfg.sample_hz)));
    control.spawn(unwrap!(tasks::control::run(b.drive, cfg, origin)));

    spawner.spawn(unwrap!(tasks::tilt::run(b.tilt)));
    spawner.spawn(unwrap!(tasks::safety::run(b.safety)));
    spawner.spawn(unwrap!(tasks::link::run(b.uart)));
    spawner.spawn(unwrap!(tasks::persist::run(b.flash)));
}
