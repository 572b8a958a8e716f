//! The e-stop line as the supervisor sees it: debounced at the control tick, unknown = pressed.
//!
//! ```text
//! reading at each control tick   state
//! None (unknown)                 pressed, at once
//! pressed  × PRESS_TICKS         pressed          (a brushed motor's spikes last µs, so a few
//! released × RELEASE_TICKS       released          ms of agreement rejects them; contact bounce
//!                                                  of a mushroom switch settles within ≈ 20 ms)
//! the first reading after power-up is taken as it is
//! ```
//! The e-stop's second contact cuts the H-bridge supply in hardware (docs/hardware.md), so the
//! few milliseconds of agreement delay only the fault report, never the motor stopping.

/// Consecutive "pressed" readings before the line counts as pressed (3 ms at 1 kHz).
pub const PRESS_TICKS: u8 = 3;
/// Consecutive "released" readings before it counts as released again (50 ms at 1 kHz).
pub const RELEASE_TICKS: u8 = 50;

/// The debounced line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EStop {
    state: Option<bool>,
    /// Readings in a row that disagree with `state`.
    against: u8,
}

impl EStop {
    pub const fn new() -> Self {
        Self {
            state: None,
            against: 0,
        }
    }

    /// One reading (`None`: the line could not be read); returns whether it counts as pressed.
    pub fn update(&mut self, reading: Option<bool>) -> bool {
        let Some(pressed) = reading else {
            self.state = Some(true);
            self.against = 0;
            return true;
        };
        match self.state {
            None => self.state = Some(pressed),
            Some(s) if s == pressed => self.against = 0,
            Some(_) => {
                self.against += 1;
                let need = if pressed { PRESS_TICKS } else { RELEASE_TICKS };
                if self.against >= need {
                    self.state = Some(pressed);
                    self.against = 0;
                }
            }
        }
        self.state.unwrap_or(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_is_pressed_and_spikes_are_ignored() {
        let mut e = EStop::new();
        assert!(e.update(None));
        // From pressed, a release needs RELEASE_TICKS readings in a row.
        for _ in 1..RELEASE_TICKS {
            assert!(e.update(Some(false)));
        }
        assert!(!e.update(Some(false)));
        // A spike shorter than PRESS_TICKS is ignored; PRESS_TICKS in a row is a press.
        for _ in 1..PRESS_TICKS {
            assert!(!e.update(Some(true)));
        }
        assert!(!e.update(Some(false)));
        for _ in 1..PRESS_TICKS {
            assert!(!e.update(Some(true)));
        }
        assert!(e.update(Some(true)));
        // Bounce on release restarts the count.
        for _ in 0..10 {
            assert!(e.update(Some(false)));
        }
        assert!(e.update(Some(true)));
        for _ in 1..RELEASE_TICKS {
            assert!(e.update(Some(false)));
        }
        assert!(!e.update(Some(false)));
    }

    #[test]
    fn the_first_reading_is_taken_as_it_is() {
        assert!(!EStop::new().update(Some(false)));
        assert!(EStop::new().update(Some(true)));
    }
}
