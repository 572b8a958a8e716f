//! A simulated lab hand: what a person does at `kapitza calibrate`'s prompt "hold the pendulum
//! still about 20° counter-clockwise and let go", so a simulated rig can be calibrated
//! unattended.
//!
//! ```text
//! armed (the rig entered bring-up mode with the motor off):
//!   grip  wherever the pendulum is, swinging or not (θ_start)
//!   lift  θ: θ_start → release (counter-clockwise of hanging, the nearest turn), smoothly
//!         (half a cosine) over LIFT_S
//!   hold  LIFT_S … LIFT_S + HOLD_S at release (the pendulum at rest in the hand)
//!   let go; nothing until armed again
//! ```
//! Like a person, it lets go from the angle it was asked for, not from wherever a swing left
//! the pendulum: every ring-down then starts alike. The hand moves the true angle, so the
//! sensor sees it through its own zero and direction, as it would a person's hand.

use crate::math;

/// How long the lift and the hold take (s).
pub const LIFT_S: f64 = 0.5;
pub const HOLD_S: f64 = 1.0;

/// The hand's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hand {
    /// The angle it lets go from (rad from hanging, counter-clockwise positive).
    pub release: f64,
    /// Since when it holds, and from which angle (rad); `None`: hands off.
    grip: Option<(f64, f64)>,
    armed: bool,
}

impl Hand {
    pub fn new(release: f64) -> Self {
        Self {
            release,
            grip: None,
            armed: false,
        }
    }

    /// One sample at time `t` (s): `armed` says whether the rig is waiting for a release now
    /// (its rising edge starts one), `theta` the pendulum's true angle. Returns the angle the
    /// hand holds the pendulum at, or `None` when it is free.
    pub fn step(&mut self, t: f64, armed: bool, theta: f64) -> Option<f64> {
        if armed && !self.armed {
            self.grip = Some((t, theta));
        }
        self.armed = armed;
        let (t0, from) = self.grip?;
        let dt = t - t0;
        if dt >= LIFT_S + HOLD_S {
            self.grip = None;
            return None;
        }
        let lift = (1.0 - math::cos(math::PI * (dt / LIFT_S).min(1.0))) / 2.0;
        Some(from + math::wrap_pi(self.release - from) * lift)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lifts_holds_and_lets_go_once_per_arming() {
        let mut h = Hand::new(0.35);
        assert_eq!(h.step(0.0, false, 0.01), None);
        assert_eq!(h.step(1.0, true, 0.01), Some(0.01));
        // Half-way through the lift: half-way from the grip to 0.35.
        assert!((h.step(1.25, true, 0.0).unwrap() - (0.01 + 0.17)).abs() < 1e-12);
        assert!((h.step(2.0, true, 0.0).unwrap() - 0.35).abs() < 1e-12);
        assert_eq!(h.step(2.5, true, 0.3), None);
        // Still armed: no second lift until it is armed again.
        assert_eq!(h.step(5.0, true, 0.0), None);
        h.step(6.0, false, 0.0);
        // Gripped mid-swing at −0.4: it still lets go from 0.35.
        assert_eq!(h.step(7.0, true, -0.4), Some(-0.4));
        assert!((h.step(8.0, true, 0.0).unwrap() - 0.35).abs() < 1e-12);
        h.step(9.0, false, 0.0);
        // A turn past hanging (θ = 2π − 0.1): it lifts to 2π + 0.35, not back through a turn.
        let turn = math::TAU - 0.1;
        h.step(10.0, true, turn);
        assert!((h.step(11.0, true, 0.0).unwrap() - (math::TAU + 0.35)).abs() < 1e-12);
    }
}
