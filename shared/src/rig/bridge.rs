//! The H-bridge's fault lines as the rig reads them at every control tick: the DRV8874's nFAULT
//! and TIM1's break flag (BIF), which nFAULT sets through TIM1's break input.
//!
//! ```text
//! nSLEEP (as driven)      nFAULT low              BIF set, nFAULT high    the rig loop
//! low (asleep)            ignored                 ignored                 re-arms (clear BIF,
//! high, < WAKE_IGNORE_US  ignored (waking up)     ignored                 set MOE) unless a
//!                                                                         fault is latched
//! high, awake             Fault::Bridge(NFault)   Fault::Bridge(Break)    latches the fault
//! ClearFault accepted     refused (nFAULT low)    re-arms
//! ```
//! The break input clears MOE in hardware whenever nFAULT is low, awake or not, and nothing but
//! software sets it again (AOE = 0). A break the loop ignores is undone once nFAULT reads high,
//! so an ignored line never leaves the drive dead; one seen while awake is a latched fault that
//! only [`super::safety::Request::ClearFault`] re-arms, and only while nFAULT reads high. BIF
//! with nFAULT high while awake is a fault that came and went between two ticks (the DRV8874
//! retries by itself after an over-current). The first tick listened to after a wake-up still
//! takes a break with nFAULT high for the wake-up's: it may have come in the last moment of it.

use super::fixed::elapsed_us;

/// The DRV8874's wake-up time: nSLEEP high to the outputs active, at most 1 ms (DRV8874
/// datasheet SLVSF66, "Electrical Characteristics", tWAKE; the DRV8876 of the same family,
/// SLVSDS7B, gives the same 1 ms maximum).
pub const T_WAKE_US: u32 = 1_000;
/// How long nFAULT is ignored after the loop wakes the bridge (µs): tWAKE, doubled because the
/// pin rises after the tick that decided it (by up to a control period's work) and so that a
/// wake-up that just makes its maximum is not taken for a fault.
pub const WAKE_IGNORE_US: u32 = 2 * T_WAKE_US;

/// Which line showed a bridge fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Line {
    /// nFAULT low: under-voltage on VM (the e-stop's relay, a sagging supply), over-current or
    /// over-temperature, as it happens.
    NFault,
    /// TIM1's break flag with nFAULT high again: a fault that came and went between ticks.
    Break,
}

/// The two lines as read at a control tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Lines {
    /// nFAULT (PA6) reads low.
    pub nfault_low: bool,
    /// TIM1_SR.BIF is set: the break input cut the outputs (MOE cleared).
    pub break_flag: bool,
}

/// What a tick's lines mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Seen {
    /// A bridge fault to latch now.
    pub fault: Option<Line>,
    /// An ignored break to undo: clear BIF and set MOE.
    pub rearm: bool,
}

/// When the bridge was last woken, to ignore nFAULT while it sleeps and wakes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Watch {
    /// When nSLEEP went high (µs on the rig's clock); `None` while it is low.
    awake_since: Option<u32>,
    /// The last tick was listened to (awake, past the wake-up).
    listened: bool,
}

impl Watch {
    /// The bridge asleep, as at reset (nSLEEP's pull-down).
    pub const fn new() -> Self {
        Self {
            awake_since: None,
            listened: false,
        }
    }

    /// nSLEEP as driven from the tick at `now_us` on: high (`awake`) or low.
    pub fn drive(&mut self, awake: bool, now_us: u32) {
        self.awake_since = match (awake, self.awake_since) {
            (false, _) => None,
            (true, None) => Some(now_us),
            (true, kept) => kept,
        };
    }

    /// The bridge is awake and past its wake-up at `now_us`: nFAULT means what it says.
    pub fn listening(&self, now_us: u32) -> bool {
        self.awake_since
            .is_some_and(|t| elapsed_us(t, now_us) >= WAKE_IGNORE_US)
    }

    /// The lines read at the tick at `now_us`. The first tick listened to after a wake-up
    /// takes BIF with nFAULT high for the wake-up's (the break came while the loop ignored
    /// nFAULT, and no later than that tick's read) and re-arms; nFAULT still low is a fault.
    pub fn check(&mut self, now_us: u32, lines: Lines) -> Seen {
        let listening = self.listening(now_us);
        let first = listening && !self.listened;
        self.listened = listening;
        if lines.nfault_low && listening {
            return Seen {
                fault: Some(Line::NFault),
                rearm: false,
            };
        }
        if lines.break_flag && listening && !first {
            return Seen {
                fault: Some(Line::Break),
                rearm: false,
            };
        }
        Seen {
            fault: None,
            rearm: lines.break_flag && !lines.nfault_low,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOW: Lines = Lines {
        nfault_low: true,
        break_flag: true,
    };
    const PULSE: Lines = Lines {
        nfault_low: false,
        break_flag: true,
    };
    const QUIET: Lines = Lines {
        nfault_low: false,
        break_flag: false,
    };

    #[test]
    fn ignored_asleep_and_waking_seen_awake() {
        let mut w = Watch::new();
        // Asleep: nFAULT low is no fault; a break with nFAULT high again is undone.
        assert_eq!(w.check(0, LOW), Seen::default());
        assert_eq!(
            w.check(0, PULSE),
            Seen {
                fault: None,
                rearm: true
            }
        );
        // Woken at t = 10 000 µs: ignored up to 2 × tWAKE = 2 000 µs later, seen from then on.
        w.drive(true, 10_000);
        assert_eq!(w.check(11_999, LOW).fault, None);
        assert_eq!(w.check(12_000, LOW).fault, Some(Line::NFault));
        assert_eq!(w.check(12_000, PULSE).fault, Some(Line::Break));
        assert_eq!(w.check(12_000, QUIET), Seen::default());
        // A break first seen at the first tick listened to came from the wake-up: re-armed.
        let mut w = Watch::new();
        w.drive(true, 0);
        assert_eq!(w.check(1_000, LOW).fault, None);
        assert_eq!(
            w.check(2_000, PULSE),
            Seen {
                fault: None,
                rearm: true
            }
        );
        assert_eq!(w.check(3_000, PULSE).fault, Some(Line::Break));
        // Staying awake keeps the first wake's time; sleeping forgets it.
        w.drive(true, 13_000);
        assert!(w.listening(13_000));
        w.drive(false, 14_000);
        assert!(!w.listening(20_000));
        // Across the clock's wrap.
        w.drive(true, u32::MAX - 500);
        assert!(!w.listening(1_000));
        assert!(w.listening(1_500));
    }
}
