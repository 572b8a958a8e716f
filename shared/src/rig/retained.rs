//! What survives a reset in RAM that is not initialised at boot (the firmware's `.uninit`): the
//! last θd commanded to the servo and the last fault (the rig record, written by the control
//! task), and what made the firmware fail (the crash record, written once by a fault handler
//! just before it resets the chip); with the chip's reset flags they give the reset's cause.
//!
//! ```text
//!         rig record                                 crash record
//! word 0  magic "KPZR"                               magic "KPZC"
//! word 1  θd (degrees, f32 bits)                     what failed (1 panic, 2 hard fault, 3 stack overflow)
//! word 2  the last fault latched (0: none;           the PC it failed at (0: not known)
//!         1 + the fault's index)
//! word 3  CRC-32C over words 0..3 (little-endian bytes; the link's CRC), for each record
//! ```
//! Two records, not one: a fault handler never rewrites the rig record, so a fault taken while
//! the control task is halfway through storing it cannot leave both torn, and the rig record's
//! format is the one older firmware left (it still decodes). The crash record is read once at
//! boot and cleared, so only the reset right after a crash reports it.
//!
//! At power-up SRAM holds noise, which [`decode`] and [`decode_crash`] refuse (the CRC); after
//! a watchdog or software reset it holds the records as last written. Their contents are
//! advice, never trusted blindly: θd is range-checked again ([`super::servo::power_up_deg`]).

use super::bridge::Line;
use super::safety::Fault;
use crate::checksum::CRC;

/// "KPZR", little-endian.
pub const MAGIC: u32 = u32::from_le_bytes(*b"KPZR");
/// "KPZC", little-endian: the crash record's.
pub const CRASH_MAGIC: u32 = u32::from_le_bytes(*b"KPZC");

/// The retained state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Retained {
    pub theta_d_deg: f32,
    pub last_fault: Option<Fault>,
}

/// Every fault, in the order of their retained numbers (append only: the numbers are stored).
const FAULTS: [Fault; 10] = [
    Fault::EStop,
    Fault::OverCurrent,
    Fault::Stall,
    Fault::Sensor,
    Fault::WrongDirection,
    Fault::PhaseLockLost,
    Fault::OverCurrentRms,
    Fault::DutyCeiling,
    Fault::Bridge(Line::NFault),
    Fault::Bridge(Line::Break),
];

fn crc(words: &[u32; 3]) -> u32 {
    let mut b = [0u8; 12];
    for (i, w) in words.iter().enumerate() {
        b[4 * i..4 * i + 4].copy_from_slice(&w.to_le_bytes());
    }
    CRC.checksum(&b)
}

/// The four words to keep.
pub fn encode(r: &Retained) -> [u32; 4] {
    let fault = r
        .last_fault
        .and_then(|f| FAULTS.iter().position(|&x| x == f))
        .map_or(0, |i| i as u32 + 1);
    let w = [MAGIC, r.theta_d_deg.to_bits(), fault];
    [w[0], w[1], w[2], crc(&w)]
}

/// The record in `words`, if it is one.
pub fn decode(words: [u32; 4]) -> Option<Retained> {
    let w = [words[0], words[1], words[2]];
    if w[0] != MAGIC || crc(&w) != words[3] {
        return None;
    }
    let last_fault = match w[2] {
        0 => None,
        n => Some(*FAULTS.get(n as usize - 1)?),
    };
    Some(Retained {
        theta_d_deg: f32::from_bits(w[1]),
        last_fault,
    })
}

/// What made the firmware fail.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CrashKind {
    Panic,
    /// A HardFault, a MemManage fault outside the stack guard, or an unexpected NMI.
    HardFault,
    /// The stack reached the guard region below it.
    StackOverflow,
}

/// The crash record: what failed, and where when that is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Crash {
    pub kind: CrashKind,
    /// The program counter of the faulting instruction, from the exception frame.
    pub pc: Option<u32>,
}

const CRASH_KINDS: [CrashKind; 3] = [
    CrashKind::Panic,
    CrashKind::HardFault,
    CrashKind::StackOverflow,
];

/// The four words of a crash record. A PC of 0 is stored for "not known": no code runs at 0
/// (the vector table's stack pointer is there).
pub fn encode_crash(c: &Crash) -> [u32; 4] {
    let kind = CRASH_KINDS.iter().position(|&k| k == c.kind).unwrap_or(0) as u32 + 1;
    let w = [CRASH_MAGIC, kind, c.pc.unwrap_or(0)];
    [w[0], w[1], w[2], crc(&w)]
}

/// The crash record in `words`, if it is one.
pub fn decode_crash(words: [u32; 4]) -> Option<Crash> {
    let w = [words[0], words[1], words[2]];
    if w[0] != CRASH_MAGIC || crc(&w) != words[3] {
        return None;
    }
    let kind = *CRASH_KINDS.get((w[1] as usize).checked_sub(1)?)?;
    Some(Crash {
        kind,
        pc: (w[2] != 0).then_some(w[2]),
    })
}

/// The Cortex-M4's configurable fault status (SCB CFSR) and MemManage address (MMFAR) as a
/// fault handler reads them, with the stack guard's address range (ARMv7-M ARM B3.2.15).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultStatus {
    pub cfsr: u32,
    pub mmfar: u32,
    /// The guard region, `[start, end)`.
    pub guard: (u32, u32),
}

/// CFSR bits (MMFSR in bits 0..8, BFSR in 8..16).
const DACCVIOL: u32 = 1 << 1;
const MSTKERR: u32 = 1 << 4;
const MLSPERR: u32 = 1 << 5;
const MMARVALID: u32 = 1 << 7;
const BSTKERR: u32 = 1 << 12;

impl FaultStatus {
    /// What a HardFault or MemManage fault with this status was, and its PC. The MPU's only
    /// region is the stack guard, so a MemManage stacking error (the exception frame or the
    /// FPU's lazy state pushed into the guard), or a data access whose valid address is in the
    /// guard, is the stack overflowing. The stacked PC is kept only when the frame was stacked
    /// intact (no MemManage or BusFault stacking error).
    pub fn crash(&self, stacked_pc: u32) -> Crash {
        let c = self.cfsr;
        let in_guard = self.mmfar >= self.guard.0 && self.mmfar < self.guard.1;
        let overflow = c & (MSTKERR | MLSPERR) != 0
            || (c & (DACCVIOL | MMARVALID) == DACCVIOL | MMARVALID && in_guard);
        let stacked = c & (MSTKERR | BSTKERR) == 0;
        Crash {
            kind: if overflow {
                CrashKind::StackOverflow
            } else {
                CrashKind::HardFault
            },
            pc: (stacked && stacked_pc != 0).then_some(stacked_pc),
        }
    }
}

/// The chip's reset flags (STM32G474 RCC_CSR, RM0440), as read at boot before clearing them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ResetFlags {
    pub independent_watchdog: bool,
    pub window_watchdog: bool,
    pub software: bool,
    pub low_power: bool,
    pub option_load: bool,
    pub brown_out: bool,
    pub pin: bool,
}

/// Why the chip reset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cause {
    /// Power-on or brown-out: nothing survived.
    PowerOn,
    Pin,
    Watchdog,
    Software,
    Other,
    /// A fault handler recorded this and reset the chip.
    Crash(Crash),
}

/// The cause of a reset from its flags and the crash record found at boot. A crash record
/// names the cause whatever reset followed it — its handler's software reset, or the watchdog
/// or the button after a handler that locked up — except after a power-on or brown-out, whose
/// RAM is not the one the record was written to. A power-on sets BORRSTF and PINRSTF together
/// (RM0440, "RCC_CSR"): brown-out is checked before the pin.
pub fn cause(f: ResetFlags, crash: Option<Crash>) -> Cause {
    match crash {
        Some(c) if !f.brown_out => Cause::Crash(c),
        _ if f.independent_watchdog => Cause::Watchdog,
        _ if f.software => Cause::Software,
        _ if f.window_watchdog || f.low_power || f.option_load => Cause::Other,
        _ if f.brown_out => Cause::PowerOn,
        _ if f.pin => Cause::Pin,
        _ => Cause::Other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_noise_refused() {
        for f in [None].into_iter().chain(FAULTS.map(Some)) {
            let r = Retained {
                theta_d_deg: 123.5,
                last_fault: f,
            };
            assert_eq!(decode(encode(&r)), Some(r));
        }
        let good = encode(&Retained {
            theta_d_deg: 10.0,
            last_fault: Some(Fault::Sensor),
        });
        // Any one flipped bit is refused (CRC-32C detects every 1-bit error).
        for i in 0..128 {
            let mut w = good;
            w[i / 32] ^= 1 << (i % 32);
            assert_eq!(decode(w), None, "bit {i}");
        }
        assert_eq!(decode([0; 4]), None);
        assert_eq!(decode([0xFFFF_FFFF; 4]), None);
    }

    /// The rig record's words are the format firmware before the crash record wrote: built
    /// here by hand from the layout in the module doc (magic, f32 bits, 1 + fault index, CRC
    /// over the first 12 bytes), not by `encode`.
    #[test]
    fn rig_record_keeps_its_format() {
        let w = [MAGIC, 45.0f32.to_bits(), 3];
        let mut b = [0u8; 12];
        for (i, x) in w.iter().enumerate() {
            b[4 * i..4 * i + 4].copy_from_slice(&x.to_le_bytes());
        }
        let words = [w[0], w[1], w[2], CRC.checksum(&b)];
        // Index 2 of the fault table is the stall.
        let want = Retained {
            theta_d_deg: 45.0,
            last_fault: Some(Fault::Stall),
        };
        assert_eq!(decode(words), Some(want));
        assert_eq!(encode(&want), words);
    }

    #[test]
    fn crash_round_trip_and_refusals() {
        for kind in CRASH_KINDS {
            for pc in [None, Some(0x0800_1234), Some(0x0807_F7FE)] {
                let c = Crash { kind, pc };
                assert_eq!(decode_crash(encode_crash(&c)), Some(c));
            }
        }
        let good = encode_crash(&Crash {
            kind: CrashKind::HardFault,
            pc: Some(0x0800_1234),
        });
        for i in 0..128 {
            let mut w = good;
            w[i / 32] ^= 1 << (i % 32);
            assert_eq!(decode_crash(w), None, "bit {i}");
        }
        // Neither record passes for the other (different magic), nor do cleared words.
        assert_eq!(decode(good), None);
        let rig = encode(&Retained {
            theta_d_deg: 1.0,
            last_fault: None,
        });
        assert_eq!(decode_crash(rig), None);
        assert_eq!(decode_crash([0; 4]), None);
        // A kind this firmware does not know (4), with a valid CRC, is refused.
        let w = [CRASH_MAGIC, 4, 0];
        assert_eq!(decode_crash([w[0], w[1], w[2], crc(&w)]), None);
    }

    const GUARD: (u32, u32) = (0x2001_0000, 0x2001_0100);

    #[test]
    fn fault_status_classified() {
        let st = |cfsr, mmfar| FaultStatus {
            cfsr,
            mmfar,
            guard: GUARD,
        };
        let pc = 0x0800_4000;
        // A push into the guard, then the frame stacked into it too: overflow, PC unknown.
        let c = st(DACCVIOL | MMARVALID | MSTKERR, 0x2001_00F8).crash(pc);
        assert_eq!((c.kind, c.pc), (CrashKind::StackOverflow, None));
        // A store into the guard with the frame stacked above it: overflow, PC known.
        let c = st(DACCVIOL | MMARVALID, 0x2001_0000).crash(pc);
        assert_eq!((c.kind, c.pc), (CrashKind::StackOverflow, Some(pc)));
        // The address just above the guard is not the guard.
        let c = st(DACCVIOL | MMARVALID, 0x2001_0100).crash(pc);
        assert_eq!(c.kind, CrashKind::HardFault);
        // An address in the guard that the core did not mark valid says nothing.
        let c = st(DACCVIOL, 0x2001_0010).crash(pc);
        assert_eq!(c.kind, CrashKind::HardFault);
        // A plain HardFault (no MemManage bits), and one whose BusFault stacking failed.
        assert_eq!(
            st(0, 0).crash(pc),
            Crash {
                kind: CrashKind::HardFault,
                pc: Some(pc)
            }
        );
        assert_eq!(st(BSTKERR, 0).crash(pc).pc, None);
        // Lazy FP state pushed into the guard: overflow.
        assert_eq!(st(MLSPERR, 0).crash(pc).kind, CrashKind::StackOverflow);
    }

    #[test]
    fn reset_cause_from_flags_and_crash() {
        let crash = Crash {
            kind: CrashKind::Panic,
            pc: None,
        };
        let flags = |f: fn(&mut ResetFlags)| {
            let mut r = ResetFlags::default();
            f(&mut r);
            r
        };
        let sw = flags(|f| f.software = true);
        let wd = flags(|f| f.independent_watchdog = true);
        let pin = flags(|f| f.pin = true);
        let por = flags(|f| {
            f.brown_out = true;
            f.pin = true
        });
        assert_eq!(cause(sw, Some(crash)), Cause::Crash(crash));
        assert_eq!(cause(wd, Some(crash)), Cause::Crash(crash));
        assert_eq!(cause(pin, Some(crash)), Cause::Crash(crash));
        assert_eq!(cause(por, Some(crash)), Cause::PowerOn);
        assert_eq!(cause(sw, None), Cause::Software);
        assert_eq!(cause(wd, None), Cause::Watchdog);
        assert_eq!(cause(pin, None), Cause::Pin);
        assert_eq!(cause(por, None), Cause::PowerOn);
        assert_eq!(cause(flags(|f| f.option_load = true), None), Cause::Other);
        assert_eq!(cause(ResetFlags::default(), None), Cause::Other);
    }
}
