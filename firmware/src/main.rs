//! Firmware for the kapitza pendulum shaker rig on a NUCLEO-G474RE (STM32G474RE).
//!
//! For now it only brings the chip up: clocks at 170 MHz, the embassy executor and time driver,
//! defmt logging over RTT, a check that `kapitza-core` links, and a 1 Hz heartbeat on the user
//! LED LD2. The rig logic (drive, sensing, control) comes later.

#![no_std]
#![no_main]

use defmt::info;
use embassy_executor::Spawner;
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::rcc;
use embassy_stm32::Config;
use embassy_time::Timer;
use {defmt_rtt as _, panic_probe as _};

/// Firmware version, from this crate's Cargo.toml.
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Chip configuration: SYSCLK = 170 MHz (the G474's maximum) from the internal 16 MHz HSI.
///
/// PLL: 16 MHz / 4 = 4 MHz input (allowed 2.66..16 MHz), × 85 = 340 MHz VCO (allowed
/// 96..344 MHz), / 2 on the R output = 170 MHz SYSCLK. Above 150 MHz the core regulator must be in
/// range 1 boost mode. AHB and both APBs run undivided at 170 MHz (all allow up to 170 MHz).
/// The HSI is used rather than the board's HSE so the firmware does not depend on the NUCLEO's
/// crystal/solder-bridge configuration.
fn chip_config() -> Config {
    let mut config = Config::default();
    config.rcc.hsi = true;
    config.rcc.pll = Some(rcc::Pll {
        source: rcc::PllSource::HSI,
        prediv: rcc::PllPreDiv::DIV4,
        mul: rcc::PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(rcc::PllRDiv::DIV2),
    });
    config.rcc.sys = rcc::Sysclk::PLL1_R;
    config.rcc.ahb_pre = rcc::AHBPrescaler::DIV1;
    config.rcc.apb1_pre = rcc::APBPrescaler::DIV1;
    config.rcc.apb2_pre = rcc::APBPrescaler::DIV1;
    config.rcc.boost = true;
    config
}

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_stm32::init(chip_config());
    info!("kapitza firmware v{=str} up", VERSION);

    // Prove the physics crate is linked and usable on the target.
    let (s, c) = kapitza_core::math::sin_cos_deg(90.0);
    info!("kapitza-core: sin(90 deg) = {}, cos(90 deg) = {}", s, c);

    // LD2, the green user LED of the NUCLEO-64 board, is on PA5 (active high).
    let mut led = Output::new(p.PA5, Level::Low, Speed::Low);

    let mut beat: u32 = 0;
    loop {
        led.toggle();
        info!("heartbeat {}", beat);
        beat = beat.wrapping_add(1);
        Timer::after_secs(1).await;
    }
}
