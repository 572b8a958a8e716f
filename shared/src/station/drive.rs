//! The crank drive as the hardware reads, and the same through the calibration as the rig
//! logic sees it.
//!
//! ```text
//! hardware (firmware, simulated rig)        rig logic (phase lock, supervisor, check)
//! crank_raw: encoder as wired          →    crank angle = crank_sign · raw
//! current_counts: ADC counts           →    current (A) = (counts − offset) · scale
//! set_duty                             ←    duty
//! bridge_lines: nFAULT, TIM1's BIF     →    bridge fault (rig::bridge), ignored asleep/waking
//! rearm: clear BIF, set MOE            ←    an accepted ClearFault, or an ignored break
//! ```

use crate::rig::bridge::Lines;
use crate::rig::calibration::{Calibration, CurrentSense};
use crate::rig::fixed::{Amps, Angle, Duty};
use crate::rig::phase_lock::Motor;

/// The crank motor's hardware, uncalibrated: what the firmware implements on the encoder
/// timer, the current ADC, the H-bridge PWM and its fault lines.
pub trait Drive {
    /// The crank encoder's position as wired (one turn = 2^32, wrapping), before the
    /// calibrated sign.
    fn crank_raw(&mut self) -> Angle;
    /// The current sense's ADC reading (counts).
    fn current_counts(&mut self) -> u16;
    /// H-bridge command in [−1, 1); 0 stops driving.
    fn set_duty(&mut self, duty: Duty);
    /// The H-bridge's fault lines now: nFAULT's level and TIM1's break flag (BIF).
    fn bridge_lines(&mut self) -> Lines;
    /// Clears TIM1's break flag and re-enables its outputs (MOE); the rig loop asks only while
    /// nFAULT reads high.
    fn rearm(&mut self);
}

/// A [`Drive`] seen through the calibration, with the tick's readings kept for the telemetry
/// and the pre-run check.
pub struct Calibrated<'a, D> {
    drive: &'a mut D,
    sign: Calibration,
    sense: CurrentSense,
    pub raw_crank: Angle,
    pub crank: Angle,
    pub counts: u16,
    pub current: Amps,
    pub duty: Duty,
}

impl<'a, D: Drive> Calibrated<'a, D> {
    pub fn new(drive: &'a mut D, cal: &Calibration) -> Self {
        Self {
            drive,
            sign: *cal,
            sense: cal.current_sense(),
            raw_crank: Angle::ZERO,
            crank: Angle::ZERO,
            counts: 0,
            current: Amps::ZERO,
            duty: Duty::ZERO,
        }
    }
}

impl<D: Drive> Motor for Calibrated<'_, D> {
    fn crank_angle(&mut self) -> Angle {
        self.raw_crank = self.drive.crank_raw();
        self.crank = self.sign.crank_angle(self.raw_crank);
        self.crank
    }
    fn current(&mut self) -> Amps {
        self.counts = self.drive.current_counts();
        self.current = self.sense.amps(self.counts);
        self.current
    }
    fn set_duty(&mut self, duty: Duty) {
        self.duty = duty;
        self.drive.set_duty(duty)
    }
}
