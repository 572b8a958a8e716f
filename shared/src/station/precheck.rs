//! The pre-run check: before a start from idle is carried out, the rig looks at its own
//! sensors and gives the crank one short, weak pulse, the way a shaker controller runs a loop
//! check before a test. A bench wired wrong is refused with the reason before it runs at
//! full speed.
//!
//! ```text
//! phase   control ticks   bridge   duty        looks at
//! rest    REST_MS         asleep   0           sensor: good angles, diagnostics ready, magnet
//!                                              current: |mean| ≤ OFFSET_FRACTION · current_max
//! pulse   PULSE_MS        awake    +PULSE_DUTY crank speed over its last MEASURE_MS against
//!                                  (≤ duty_max) K = PULSE_DUTY · omega_per_duty:
//!                                              ≤ −SPEED_LOW·K reversed, < SPEED_LOW·K stalled,
//!                                              > SPEED_HIGH·K too fast
//! coast   COAST_MS        awake    0           (braking: the crank comes to rest)
//! ```
//! 600 ms in all, well inside the link-silence timeout. The crank speed is the crank angle's
//! travel (the sum of wrapped per-tick differences, after the calibrated sign) over the
//! window; the motor's lag (τ ≈ 50–60 ms) has settled by then, so the speed is the steady
//! one the configured gain predicts, within the gain error a real motor has.
//!
//! The supervisor keeps running meanwhile (the rig is idle to it): an e-stop or an
//! over-current aborts the check with the fault.

use crate::link::convert::to_q16;
use crate::link::message::Verdict;
use crate::rig::as5047::Diagnostics;
use crate::rig::config::RigConfig;
use crate::rig::fixed::{Amps, Angle, Duty};

/// The phases' lengths (ms).
pub const REST_MS: u32 = 100;
pub const PULSE_MS: u32 = 300;
pub const MEASURE_MS: u32 = 100;
pub const COAST_MS: u32 = 200;
/// The test pulse's duty (capped at the configured `duty_max`): a tenth of full speed.
pub const PULSE_DUTY: f64 = 0.1;
/// The largest |current| at rest, as a fraction of `current_max`: a healthy sense reads a few
/// counts; a tenth of the trip level is an offset that hides or fakes over-current.
pub const OFFSET_FRACTION: f64 = 0.1;
/// The plausible crank speed under the pulse, as fractions of what the configured gain
/// predicts.
pub const SPEED_LOW: f64 = 0.3;
pub const SPEED_HIGH: f64 = 3.0;
/// At least this fraction of the rest phase's samples must carry an angle.
pub const GOOD_FRACTION: f64 = 0.5;

/// What the check asks of the hardware for this tick, or its verdict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    Drive { bridge: bool, duty: Duty },
    Done(Result<(), Verdict>),
}

/// The pendulum sensor as the samples since the last tick saw it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SensorView {
    pub diagnostics: Option<Diagnostics>,
    pub failed: bool,
}

/// One check in progress.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreCheck {
    ticks: u32,
    rest: u32,
    pulse: u32,
    measure: u32,
    coast: u32,
    good: u32,
    bad: u32,
    current_sum: i64,
    last_crank: Option<Angle>,
    travel: i64,
    duty: Duty,
    expected: f64,
    offset_max: f64,
    control_hz: u32,
}

fn ticks(ms: u32, hz: u32) -> u32 {
    (u64::from(ms) * u64::from(hz)).div_ceil(1000).max(1) as u32
}

impl PreCheck {
    /// A check for a rig on `cfg` (validated).
    pub fn new(cfg: &RigConfig) -> Self {
        let hz = cfg.control_hz.max(1);
        let duty = PULSE_DUTY.min(cfg.limits.duty_max);
        Self {
            ticks: 0,
            rest: ticks(REST_MS, hz),
            pulse: ticks(PULSE_MS, hz),
            measure: ticks(MEASURE_MS, hz),
            coast: ticks(COAST_MS, hz),
            good: 0,
            bad: 0,
            current_sum: 0,
            last_crank: None,
            travel: 0,
            duty: Duty::saturating_from_num(duty),
            expected: duty * cfg.motor.omega_per_duty,
            offset_max: OFFSET_FRACTION * cfg.limits.current_max,
            control_hz: hz,
        }
    }

    /// One pendulum sample (`failed`: no angle), counted during the rest phase.
    pub fn sample(&mut self, failed: bool) {
        if self.ticks < self.rest {
            if failed {
                self.bad += 1;
            } else {
                self.good += 1;
            }
        }
    }

    /// One control tick with the crank angle (calibrated), the current and the sensor.
    pub fn tick(&mut self, crank: Angle, current: Amps, sensor: SensorView) -> Step {
        let k = self.ticks;
        self.ticks += 1;
        let rest_end = self.rest;
        let pulse_end = rest_end + self.pulse;
        if k < rest_end {
            self.current_sum += i64::from(current.to_bits());
            if k + 1 == rest_end {
                if let Err(v) = self.judge_rest(sensor) {
                    return Step::Done(Err(v));
                }
            }
            return Step::Drive {
                bridge: false,
                duty: Duty::ZERO,
            };
        }
        if k < pulse_end {
            if k >= pulse_end - self.measure {
                if let Some(prev) = self.last_crank {
                    self.travel += i64::from((crank - prev).to_bits());
                }
            }
            self.last_crank = Some(crank);
            if k + 1 == pulse_end {
                if let Err(v) = self.judge_pulse() {
                    return Step::Done(Err(v));
                }
                return Step::Drive {
                    bridge: true,
                    duty: Duty::ZERO,
                };
            }
            return Step::Drive {
                bridge: true,
                duty: self.duty,
            };
        }
        if k + 1 < pulse_end + self.coast {
            Step::Drive {
                bridge: true,
                duty: Duty::ZERO,
            }
        } else {
            Step::Done(Ok(()))
        }
    }

    fn judge_rest(&self, sensor: SensorView) -> Result<(), Verdict> {
        let n = self.good + self.bad;
        if sensor.failed || (self.good as f64) < GOOD_FRACTION * n as f64 || self.good == 0 {
            return Err(Verdict::SensorSilent);
        }
        match sensor.diagnostics {
            Some(d) if d.ready && d.magnet_ok() => {}
            _ => return Err(Verdict::SensorNotReady),
        }
        let mean = self.current_sum as f64 / 65_536.0 / f64::from(self.rest);
        if libm::fabs(mean) > self.offset_max {
            return Err(Verdict::CurrentOffset { amps: to_q16(mean) });
        }
        Ok(())
    }

    fn judge_pulse(&self) -> Result<(), Verdict> {
        // `measure` tick-to-tick differences, the first from the tick before the window.
        let secs = f64::from(self.measure) / f64::from(self.control_hz);
        let speed = self.travel as f64 * crate::math::TAU / 4_294_967_296.0 / secs;
        let q = to_q16(speed);
        if speed <= -SPEED_LOW * self.expected {
            Err(Verdict::CrankReversed { speed: q })
        } else if speed < SPEED_LOW * self.expected {
            Err(Verdict::CrankStalled { speed: q })
        } else if speed > SPEED_HIGH * self.expected {
            Err(Verdict::CrankTooFast { speed: q })
        } else {
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEALTHY: SensorView = SensorView {
        diagnostics: Some(Diagnostics {
            agc: 100,
            magnet_low: false,
            magnet_high: false,
            cordic_overflow: false,
            ready: true,
        }),
        failed: false,
    };

    /// Runs a check on a crank turning at `speed` rad/s under the pulse and standing still
    /// otherwise, with `amps` at rest.
    fn run(speed: f64, amps: f64, sensor: SensorView) -> (Result<(), Verdict>, u32) {
        let cfg = RigConfig::REFERENCE;
        let mut c = PreCheck::new(&cfg);
        let mut crank = Angle::ZERO;
        for tick in 1..10_000 {
            for _ in 0..10 {
                c.sample(false);
            }
            match c.tick(crank, Amps::from_num(amps), sensor) {
                Step::Drive { duty, .. } => {
                    if duty != Duty::ZERO {
                        crank += Angle::from_rad(speed / 1000.0);
                    }
                }
                Step::Done(v) => return (v, tick),
            }
        }
        panic!("no verdict")
    }

    #[test]
    fn each_verdict_from_its_cause() {
        // Reference rig: the pulse is 0.1 · 500 rad/s = 50 rad/s.
        assert_eq!(run(45.0, 0.01, HEALTHY), (Ok(()), 600));
        assert!(matches!(
            run(-45.0, 0.0, HEALTHY).0,
            Err(Verdict::CrankReversed { .. })
        ));
        assert!(matches!(
            run(0.0, 0.0, HEALTHY).0,
            Err(Verdict::CrankStalled { .. })
        ));
        assert!(matches!(
            run(400.0, 0.0, HEALTHY).0,
            Err(Verdict::CrankTooFast { .. })
        ));
        // 0.1 · 3 A = 0.3 A at rest is the most a sense may read.
        assert_eq!(
            run(45.0, 0.5, HEALTHY).0,
            Err(Verdict::CurrentOffset { amps: to_q16(0.5) })
        );
        let mut no_magnet = HEALTHY;
        no_magnet.diagnostics = Some(Diagnostics {
            magnet_low: true,
            ..HEALTHY.diagnostics.unwrap()
        });
        assert_eq!(
            run(45.0, 0.0, no_magnet),
            (Err(Verdict::SensorNotReady), 100)
        );
        let failed = SensorView {
            failed: true,
            ..HEALTHY
        };
        assert_eq!(run(45.0, 0.0, failed).0, Err(Verdict::SensorSilent));
    }

    #[test]
    fn the_measured_speed_is_the_crank_speed() {
        // 45 rad/s over the 100-tick window: the stalled verdict carries 0, the reversed one
        // −45 rad/s (I16F16, to the rounding of the angle steps: 1e-4 rad/s).
        match run(-45.0, 0.0, HEALTHY).0 {
            Err(Verdict::CrankReversed { speed }) => {
                assert!((f64::from(speed) / 65_536.0 + 45.0).abs() < 1e-3, "{speed}")
            }
            other => panic!("{other:?}"),
        }
    }
}
