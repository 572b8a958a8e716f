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
use kapitza_core::link::message::ResetInfo;
use kapitza_core::persist::{self, ConfigOrigin};
use kapitza_core::rig::retained::ResetFlags;
use kapitza_core::rig::servo;

/// Firmware version, from this crate's Cargo.toml.
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The executor of the time-critical tasks, run from `board::CONTROL_IRQ`.
pub static CONTROL_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    // ---- Before the clocks: a first log line (defmt-rtt needs no clock), the stack guard,
    // and the option bytes this firmware was built for. `embassy_stm32::init` waits for the
    // crystal without a timeout: a board whose log ends at this line is waiting for its HSE.
    info!(
        "kapitza firmware v{=str} on {=str}: starting clocks (HSE 24 MHz)",
        VERSION,
        board::NAME
    );
    fail_safe::enable_stack_guard();
    check_option_bytes();
    // ----
    let p = embassy_stm32::init(board::chip_config());
    info!("clocks running");
    // A CPU lock-up (a fault inside the HardFault handler) breaks TIM1 like nFAULT does, so
    // the drive stops in hardware (SYSCFG_CFGR2.CLL, RM0440 "SYSCFG configuration register 2";
    // the bit stays set until the next reset).
    pac::RCC.apb2enr().modify(|w| w.set_syscfgen(true));
    pac::SYSCFG.cfgr2().modify(|w| w.set_cll(true));
    // A debugger halting the core freezes the watchdog (so a breakpoint does not reset the
    // chip) and TIM1 (whose outputs are then disabled, as if MOE were cleared).
    pac::DBGMCU.apb1lfzr().modify(|w| w.set_iwdg(true));
    pac::DBGMCU.apb2fzr().modify(|w| w.set_tim1(true));
    let crash = retained::take_crash();
    let cause = kapitza_core::rig::retained::cause(reset_flags(), crash);
    let kept = retained::load();
    let reset = ResetInfo::new(cause, kept.and_then(|k| k.last_fault));
    info!("reset cause: {}", reset.cause);
    if let Some(pc) = reset.fault_pc {
        warn!("the fault before this reset was taken at pc {=u32:#x}", pc);
    }
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
    control.spawn(unwrap!(tasks::control::run(
        b.drive, cfg, origin, theta_d0, kept, reset
    )));

    spawner.spawn(unwrap!(tasks::tilt::run(b.tilt)));
    spawner.spawn(unwrap!(tasks::safety::run(b.safety)));
    spawner.spawn(unwrap!(tasks::link::run(b.uart)));
    spawner.spawn(unwrap!(tasks::persist::run(flash)));
}

/// The chip's reset flags (RCC_CSR), cleared here so the next reset reports its own.
fn reset_flags() -> ResetFlags {
    let csr = pac::RCC.csr().read();
    pac::RCC.csr().modify(|w| w.set_rmvf(true));
    ResetFlags {
        independent_watchdog: csr.iwdgrstf(),
        window_watchdog: csr.wwdgrstf(),
        software: csr.sftrstf(),
        low_power: csr.lpwrrstf(),
        option_load: csr.oblrstf(),
        brown_out: csr.borrstf(),
        pin: csr.pinrstf(),
    }
}

/// Stops here, before the clocks, on a chip whose option bytes this firmware was not built
/// for, saying so in the log (RDP and DBANK of FLASH_OPTR, RM0440 "Flash option register"):
/// * DBANK = 0 (single bank, 4 KiB pages): this build addresses flash as dual bank (2 KiB
///   pages), so storing the configuration would erase the wrong 4 KiB, possibly code;
/// * RDP ≠ level 0 (0xAA): the probe can neither read the configuration page for its backup
///   nor program the chip, and the stored configuration could not be recovered.
///
/// The outputs are safe as they are: no pin has been configured, and the bridge's nSLEEP
/// has its pull-down. The watchdog is not started, so the chip stays here until the option
/// bytes are set right (`kapitza flash` names the fix) and it is reset.
fn check_option_bytes() {
    let optr = pac::FLASH.optr().read();
    let rdp = optr.rdp().to_bits();
    let dual_bank = optr.dbank();
    if dual_bank && rdp == 0xAA {
        return;
    }
    defmt::error!(
        "option bytes: DBANK = {=bool}, RDP = {=u8:#x}; this firmware needs DBANK = 1 and RDP = 0xaa: not starting",
        dual_bank,
        rdp
    );
    loop {
        cortex_m::asm::nop();
    }
}
