//! What the chip does when the firmware itself fails: a panic, a HardFault, a MemManage fault
//! (the stack guard below), or an NMI that is not the flash's double-ECC error on the
//! configuration page at boot (that one is expected after a power loss during a configuration
//! write and is handled by `tasks::persist::load`).
//!
//! Every handler first makes the drive's outputs safe by writing the registers directly
//! (whatever state the drivers were left in): the bridge's nSLEEP (PA10) low, TIM1's main
//! output enable (MOE) off so the PWM pin goes to its idle level (low). On the first entry it
//! then records what failed, and where, in the retained RAM's crash record (the next boot's
//! status reports it as `reset_cause` with `fault_pc`) and logs it; then it resets the chip at
//! once (`SCB::sys_reset`). A second entry — a fault inside a handler, or defmt's "taken
//! reentrantly" panic when the failing code held the logger — skips the record and the log
//! and resets. A fault inside the HardFault handler itself locks the core up: SYSCFG_CFGR2.CLL
//! (set at boot) turns the lock-up into TIM1's break, which clears MOE in hardware, and the
//! watchdog resets the chip.
//!
//! HardFault and MemManage enter through a few instructions of assembly that read the stacked
//! PC and move the stack pointer back to the top of the stack before any Rust code runs: after
//! an overflow it points into the guard region, where every push would fault again. The old
//! stack is not needed; the chip resets.

use core::panic::PanicInfo;
use core::ptr::addr_of;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::peripheral::{MPU, SCB};
use cortex_m_rt::exception;
use embassy_stm32::pac;
use kapitza_core::rig::retained::{Crash, CrashKind, FaultStatus};

use crate::retained;

/// Set by the first fault handler entered.
static FAILING: AtomicBool = AtomicBool::new(false);

/// Bridge asleep, drive PWM off: nothing here can fail or wait.
pub fn outputs_off() {
    // PA10 = nSLEEP: reset its output bit (BSRR's upper half).
    pac::GPIOA.bsrr().write(|w| w.set_br(10, true));
    pac::TIM1.bdtr().modify(|w| w.set_moe(false));
}

/// Outputs off; whether this is the first handler entered.
fn enter() -> bool {
    outputs_off();
    !FAILING.swap(true, Ordering::Relaxed)
}

/// Keeps `c` for the next boot's status.
fn record(c: Crash) {
    retained::store_crash(&c);
}

/// Gives a probe reading the log (RTT, polled every few ms) 10 ms at 170 MHz to collect the
/// handler's line before the reset re-initialises the log buffer, then resets. The outputs are
/// already off and the crash recorded, so the wait costs nothing but its 10 ms.
fn reset_after_log() -> ! {
    cortex_m::asm::delay(1_700_000);
    SCB::sys_reset()
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    if !enter() {
        SCB::sys_reset()
    }
    record(Crash {
        kind: CrashKind::Panic,
        pc: None,
    });
    defmt::error!("panic: {}", defmt::Display2Format(info));
    reset_after_log()
}

// HardFault and MemManage: r1 = which; r0 = the stacked PC, read from the stack the exception
// was taken on (EXC_RETURN bit 2) after switching the MPU off (MPU_CTRL = 0), so the frame can
// be read even when it lies in the guard; then MSP = the top of the stack, and on to Rust.
core::arch::global_asm!(
    ".section .text.kapitza_fault_entry, \"ax\"",
    ".global HardFault",
    ".type HardFault, %function",
    ".thumb_func",
    "HardFault:",
    "    movs r1, #0",
    "    b 1f",
    ".global MemoryManagement",
    ".type MemoryManagement, %function",
    ".thumb_func",
    "MemoryManagement:",
    "    movs r1, #1",
    "1:",
    "    tst lr, #4",
    "    ite eq",
    "    mrseq r0, msp",
    "    mrsne r0, psp",
    "    ldr r2, =0xE000ED94",
    "    movs r3, #0",
    "    str r3, [r2]",
    "    dsb",
    "    isb",
    "    ldr r0, [r0, #24]",
    "    ldr r2, =_stack_start",
    "    msr msp, r2",
    "    b {entry}",
    ".ltorg",
    entry = sym fault_entry,
);

/// The Rust side of HardFault (`exception` 0) and MemManage (1), on a fresh stack.
extern "C" fn fault_entry(stacked_pc: u32, exception: u32) -> ! {
    if !enter() {
        SCB::sys_reset()
    }
    // SAFETY: reads of the fault status registers (SCB CFSR, MMFAR).
    let (cfsr, mmfar) = unsafe { ((*SCB::PTR).cfsr.read(), (*SCB::PTR).mmfar.read()) };
    let crash = FaultStatus {
        cfsr,
        mmfar,
        guard: guard_range(),
    }
    .crash(stacked_pc);
    record(crash);
    // Numbers only (the next boot logs the record too): exception 0 HardFault, 1 MemManage.
    defmt::error!(
        "fault: exception {=u32}, stacked pc {=u32:#x}, CFSR {=u32:#x}, MMFAR {=u32:#x}",
        exception,
        stacked_pc,
        cfsr,
        mmfar
    );
    reset_after_log()
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
/// CRC fails and the rig starts on the safe defaults, saying `Defaults(Corrupt)`. Any other
/// NMI is a failure, recorded as a hard fault with no PC.
#[exception]
unsafe fn NonMaskableInt() {
    let eccr = pac::FLASH.eccr().read();
    if eccr.eccd() && READING_CONFIG.load(Ordering::Relaxed) {
        pac::FLASH.eccr().modify(|w| w.set_eccd(true));
        ECC_ERROR.store(true, Ordering::Relaxed);
        return;
    }
    if !enter() {
        SCB::sys_reset()
    }
    record(Crash {
        kind: CrashKind::HardFault,
        pc: None,
    });
    defmt::error!("NMI (flash ECCR = {=u32:#x})", eccr.0);
    reset_after_log()
}

/// The stack guard's size (bytes). The stack grows down from the end of RAM (`_stack_start`)
/// towards the end of the static data (`_stack_end`, cortex-m-rt: the end of `.uninit`); the
/// guard is the first `GUARD_SIZE`-aligned block at or above `_stack_end` (an ARMv7-M MPU
/// region is a power of two ≥ 32 bytes, aligned to its size: ARMv7-M ARM B3.5.8), so it sits
/// between the stack and the retained records. 1 KiB, not the minimum 32 bytes: a function
/// whose frame is larger than the guard could step over it into the static data; 1 KiB is
/// more than any frame in this firmware, and of the ~120 KiB stack it costs under 2 KiB.
const GUARD_SIZE: u32 = 1024;
/// RASR.SIZE for it: the region is 2^(SIZE + 1) bytes.
const GUARD_SIZE_FIELD: u32 = GUARD_SIZE.trailing_zeros() - 1;

/// The guard region, `[start, end)`.
pub fn guard_range() -> (u32, u32) {
    extern "C" {
        static _stack_end: u32;
    }
    // Only the linker symbol's address is taken, never its value.
    let end = addr_of!(_stack_end) as u32;
    let start = end.next_multiple_of(GUARD_SIZE);
    (start, start + GUARD_SIZE)
}

/// The stack guard: MPU region 0 over [`guard_range`], no access, never executable; the rest
/// of the memory map as without an MPU (PRIVDEFENA; the firmware runs privileged); the MPU off
/// in HardFault and NMI (HFNMIENA = 0), so their handlers can read a frame stacked into the
/// guard. MemManage enabled, so an overflow enters its handler rather than HardFault's.
/// Needs nothing installed on a user's machine (unlike `flip-link`). Called once at boot,
/// before any task but `main` runs.
pub fn enable_stack_guard() {
    let (start, _) = guard_range();
    const XN: u32 = 1 << 28;
    const AP_NONE: u32 = 0b000 << 24;
    // Normal memory, shareable, write-through (TEX 000, S 1, C 1, B 0): SRAM's attributes;
    // they matter little for a region nothing may touch.
    const NORMAL: u32 = (1 << 18) | (1 << 17);
    const ENABLE: u32 = 1;
    const PRIVDEFENA: u32 = 1 << 2;
    const MEMFAULTENA: u32 = 1 << 16;
    // SAFETY: region 0 is this firmware's only MPU region; the guard lies below every byte
    // the stack uses at this point (it is near its top), so enabling it faults nothing.
    unsafe {
        let mpu = &*MPU::PTR;
        mpu.rnr.write(0);
        mpu.rbar.write(start);
        mpu.rasr
            .write(XN | AP_NONE | NORMAL | (GUARD_SIZE_FIELD << 1) | ENABLE);
        mpu.ctrl.write(PRIVDEFENA | ENABLE);
        (*SCB::PTR).shcsr.modify(|r| r | MEMFAULTENA);
    }
    cortex_m::asm::dsb();
    cortex_m::asm::isb();
}
