//! Closed-loop R: once the pendulum has settled, trim ω so that the R the estimator measures in
//! situ equals the R asked for. Open loop, R is only as right as the configured stroke and
//! length (R = A²ω²/(2gℓ)); the settled angle does not depend on either.
//!
//! ```text
//! R measured: the estimator's in-situ R (estimator::settle), from the settled angle alone,
//!             R = −2 sin φ0 / sin 2(φ0 − θd), or from ωp where that is singular (θd = 0°, 180°)
//! the drive's R_cmd (ω = ωc √R_cmd, ωc from the configuration) is what the rig believes it
//! sets; the true R is k·R_cmd with k the unknown (A_true/A)²(ℓ/ℓ_true), so one measurement
//! gives k = R_meas/R_cmd and the R_cmd that would give R_asked:  R_cmd' = R_asked · R_cmd/R_meas
//! applied only when |R_meas − R_asked| > band;
//! rate:  |R_cmd' − R_cmd| ≤ rate_max · (time since the last trim)
//! range: R_cmd' within [R_asked/(1 + MAX_TRIM), R_asked·(1 + MAX_TRIM)], and ω' ≤ ω_max
//! ```
//! A trim changes ω, the drive ramps, the estimator restarts its slow history, and the next
//! trim waits for the pendulum to settle again (two quiet seconds by default): the loop
//! measures, steps, and waits, never chasing a pendulum in motion. A new `SetDrive`, a stop, a
//! fault, or switching the loop off returns to the open-loop ω of the R asked for.

use super::closed_loop::ClosedLoopR;
use crate::math;

/// The farthest the trim may move R_cmd from R asked (relative): a wrong in-situ reading (the
/// pendulum knocked off its equilibrium) must not run the drive away.
pub const MAX_TRIM: f64 = 0.25;

/// The trim's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RTrim {
    settings: ClosedLoopR,
    /// ωc = √(2gℓ)/A from the configuration (rad/s), and the drive's ω limit.
    omega_c: f64,
    omega_max: f64,
    /// R asked for and the R_cmd the drive runs at (both 0 while not driving).
    asked: f64,
    cmd: f64,
    /// When R_cmd last changed (µs, wrapping); `None` until the first tick after a request.
    since_us: Option<u32>,
}

impl RTrim {
    pub fn new(settings: ClosedLoopR, omega_c: f64, omega_max: f64) -> Self {
        Self {
            settings,
            omega_c,
            omega_max,
            asked: 0.0,
            cmd: 0.0,
            since_us: None,
        }
    }

    /// A drive strength asked for (0: stopped): the drive starts at its open-loop ω, and the
    /// rate limit counts from the next tick.
    pub fn asked(&mut self, r: f64) {
        self.asked = r;
        self.cmd = r;
        self.since_us = None;
    }

    /// Switches the loop on or off (band and rate as given). Off: the ω to return to, the
    /// open-loop ω of the R asked for, if a trim had moved it.
    pub fn set(&mut self, settings: ClosedLoopR, now_us: u32) -> Option<f64> {
        self.settings = settings;
        if settings.enabled || self.cmd == self.asked || self.asked <= 0.0 {
            return None;
        }
        self.cmd = self.asked;
        self.since_us = Some(now_us);
        Some(self.omega(self.asked))
    }

    /// R_cmd now: the R the drive's ω stands for under the configuration.
    pub fn commanded(&self) -> f64 {
        self.cmd
    }

    pub fn settings(&self) -> ClosedLoopR {
        self.settings
    }

    /// One control tick: `settled_r` is the in-situ R while the drive is steady and the
    /// pendulum settled (else `None`). Returns the new ω (rad/s) when a trim is due.
    pub fn update(&mut self, now_us: u32, settled_r: Option<f64>) -> Option<f64> {
        let s = self.settings;
        let since = *self.since_us.get_or_insert(now_us);
        let measured = settled_r?;
        if !s.enabled || self.asked <= 0.0 || measured.is_nan() || measured <= 0.0 {
            return None;
        }
        if (measured - self.asked).abs() <= s.band {
            return None;
        }
        let dt = f64::from(now_us.wrapping_sub(since)) * 1e-6;
        let step = s.rate_max * dt;
        let want = (self.asked * self.cmd / measured)
            .clamp(self.asked / (1.0 + MAX_TRIM), self.asked * (1.0 + MAX_TRIM));
        let r_limit = (self.omega_max / self.omega_c) * (self.omega_max / self.omega_c);
        let next = want.clamp(self.cmd - step, self.cmd + step).min(r_limit);
        if next == self.cmd {
            return None;
        }
        self.cmd = next;
        self.since_us = Some(now_us);
        Some(self.omega(next))
    }

    fn omega(&self, r: f64) -> f64 {
        (self.omega_c * math::sqrt(r)).min(self.omega_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ON: ClosedLoopR = ClosedLoopR {
        enabled: true,
        band: 0.01,
        rate_max: 0.1,
    };

    #[test]
    fn steps_toward_the_asked_r_within_rate_band_and_limits() {
        // ωc = 100: R_cmd 1.75 is ω = 132.29. The rig truly gives 1.032 × R_cmd (a stroke typed
        // 1.6 % short), so the R_cmd that gives 1.75 is 1.75/1.032 (closed form).
        let mut t = RTrim::new(ON, 100.0, 420.0);
        t.asked(1.75);
        assert_eq!(t.update(0, None), None);
        // 0.1 s after the start: at most 0.01 of R.
        let w = t.update(100_000, Some(1.75 * 1.032)).unwrap();
        assert!((t.commanded() - 1.74).abs() < 1e-12);
        assert!((w - 100.0 * 1.74f64.sqrt()).abs() < 1e-9);
        // 10 s later: the whole way.
        t.update(10_100_000, Some(1.74 * 1.032)).unwrap();
        assert!((t.commanded() - 1.75 / 1.032).abs() < 1e-12);
        // Inside the band: nothing.
        assert_eq!(t.update(20_000_000, Some(1.755)), None);
        // Not settled: nothing.
        assert_eq!(t.update(30_000_000, None), None);
        // Off: back to the open-loop ω of 1.75.
        let back = t
            .set(
                ClosedLoopR {
                    enabled: false,
                    ..ON
                },
                31_000_000,
            )
            .unwrap();
        assert!((back - 100.0 * 1.75f64.sqrt()).abs() < 1e-9);
        assert_eq!(t.update(40_000_000, Some(2.0)), None);
    }

    #[test]
    fn never_past_the_limits() {
        // A reading far off (the pendulum knocked): at most 25 % of R.
        let mut t = RTrim::new(ON, 100.0, 420.0);
        t.asked(2.0);
        assert_eq!(t.update(0, None), None);
        t.update(100_000_000, Some(0.5)).unwrap();
        assert!((t.commanded() - 2.5).abs() < 1e-12);
        // ω_max = 150: R_cmd stops at (150/100)² = 2.25, ω at 150.
        let mut t = RTrim::new(ON, 100.0, 150.0);
        t.asked(2.0);
        assert_eq!(t.update(0, None), None);
        let w = t.update(100_000_000, Some(1.0)).unwrap();
        assert!((t.commanded() - 2.25).abs() < 1e-12 && w <= 150.0);
        // Off by default: nothing ever.
        let mut t = RTrim::new(
            ClosedLoopR {
                enabled: false,
                ..ON
            },
            100.0,
            420.0,
        );
        t.asked(2.0);
        assert_eq!(t.update(0, None), None);
        assert_eq!(t.update(100_000_000, Some(1.0)), None);
    }
}
