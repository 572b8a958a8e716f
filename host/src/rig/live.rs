//! Which of the estimator's numbers describe the pendulum now. The rig keeps its last slow
//! angle, ωp and R in situ when it stops averaging; they are shown only while they are current,
//! from what the telemetry already carries:
//!
//! ```text
//! slow angle φ   while the drive runs (mode running): φ0 once settled, else the latest period's φ̄
//! ωp, R in situ  while the drive runs and the estimator has them (it forgets them whenever
//!                the drive changes, and has them again only after new swings / a new settle)
//! measured       the slow angle, once the drive is steady (at its set ω and θd): what a
//!                prediction is set beside
//! ```
//! Otherwise (idle, checking, stopping, faulted) they are `None` and the live angle θ stands in.

use kapitza_core::link::convert::from_q16;
use kapitza_core::link::message::Mode;
use kapitza_core::link::Telemetry;

use super::names::turns_deg;

/// The current readings of one telemetry frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Live {
    /// The latest pendulum sample θ (degrees).
    pub theta_deg: f64,
    pub slow_angle_deg: Option<f64>,
    pub omega_p: Option<f64>,
    pub r_estimate: Option<f64>,
    /// The slow angle a prediction is set beside, once the drive is steady.
    pub measured_deg: Option<f64>,
}

impl Live {
    /// The readings of `t` while the rig is in `mode` (the latest of status and telemetry).
    pub fn of(mode: Mode, t: &Telemetry) -> Self {
        let running = mode == Mode::Running && t.mode == Mode::Running;
        let slow = running.then(|| match (t.settled, t.equilibrium) {
            (true, Some(e)) => turns_deg(e),
            _ => turns_deg(t.phi),
        });
        Self {
            theta_deg: turns_deg(t.theta),
            slow_angle_deg: slow,
            omega_p: t.omega_p.filter(|_| running).map(from_q16),
            r_estimate: t.r.filter(|_| running).map(|(r, _)| from_q16(r)),
            measured_deg: slow.filter(|_| t.steady),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kapitza_core::link::convert::to_q16;
    use kapitza_core::link::message::{RMethod, StopReason};

    /// A fraction of a turn on the wire (2^-32 turn).
    fn turns(x: f64) -> i32 {
        (x * 4_294_967_296.0) as i64 as i32
    }

    fn frame(mode: Mode) -> Telemetry {
        Telemetry {
            mode,
            theta: turns(0.01),
            phi: turns(0.45),
            omega_p: Some(to_q16(6.8)),
            settled: true,
            equilibrium: Some(turns(0.499)),
            r: Some((to_q16(1.7), RMethod::SlowFrequency)),
            steady: true,
            ..Telemetry::default()
        }
    }

    #[test]
    fn idle_frozen_values_are_not_shown() {
        // The rig's last values from before the stop (an inverted rod's 179.6° with its ωp and
        // R), in a frame taken while idle: none of them describes the pendulum now.
        let l = Live::of(Mode::Idle, &frame(Mode::Idle));
        assert_eq!(
            (l.slow_angle_deg, l.omega_p, l.r_estimate, l.measured_deg),
            (None, None, None, None)
        );
        assert!((l.theta_deg - 3.6).abs() < 1e-6);
        for m in [Mode::Checking, Mode::Stopping(StopReason::Requested)] {
            assert_eq!(Live::of(m, &frame(m)).slow_angle_deg, None);
        }
        // The status already says idle while the last frame still says running: idle.
        assert_eq!(
            Live::of(Mode::Idle, &frame(Mode::Running)).slow_angle_deg,
            None
        );
    }

    #[test]
    fn running_shows_the_settled_angle_and_measures_once_steady() {
        let l = Live::of(Mode::Running, &frame(Mode::Running));
        // 0.499 turn = 179.64°: the settled equilibrium, not the period's φ̄ (162°).
        assert!((l.slow_angle_deg.unwrap() - 179.64).abs() < 1e-6);
        assert_eq!(l.measured_deg, l.slow_angle_deg);
        assert!((l.omega_p.unwrap() - 6.8).abs() < 1e-4);
        let mut t = frame(Mode::Running);
        t.steady = false;
        t.settled = false;
        let l = Live::of(Mode::Running, &t);
        assert!(l.slow_angle_deg.is_some() && l.measured_deg.is_none());
    }
}
