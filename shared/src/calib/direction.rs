//! Directions, which must come out exactly right (a wrong sign is not a small error).
//!
//! ```text
//! sensor: the operator holds the pendulum counter-clockwise (physics §2's positive sense) and lets
//!         go; sign = sign(reading held − reading at the centre of the ring-down)
//! crank:  a short pulse of small positive duty; sign = sign(Σ wrapped Δcounts), the successive
//!         differences of the crank encoder taken modulo one turn into (−½, ½] turn
//! ```
//! Both refuse when the movement is too small to be more than noise.

use super::error::CalibError;
use crate::math;

/// The smallest nudge read (rad): 3°, far above the sensor's noise and a swing's asymmetry.
pub const MIN_NUDGE: f64 = 0.052_359_877_559_829_89;

/// +1 when the sensor counts counter-clockwise, −1 when it counts the other way, from its
/// reading while held counter-clockwise and its reading at rest (both rad).
pub fn sensor_sign(held: f64, rest: f64) -> Result<f64, CalibError> {
    let moved = math::wrap_pi(held - rest);
    if moved.abs() < MIN_NUDGE {
        return Err(CalibError::NudgeTooSmall {
            moved: moved.abs(),
            needed: MIN_NUDGE,
        });
    }
    Ok(if moved > 0.0 { 1.0 } else { -1.0 })
}

/// +1 when positive duty makes the crank encoder count up, −1 when down, from its readings
/// (`counts`, each in 0..`per_turn`, read often enough that the crank turns less than half a
/// turn between two) during a positive-duty pulse; at least `needed` counts of movement.
pub fn crank_sign(counts: &[u32], per_turn: u32, needed: i64) -> Result<f64, CalibError> {
    let per = i64::from(per_turn.max(2));
    let moved: i64 = counts
        .windows(2)
        .map(|w| {
            let d = (i64::from(w[1]) - i64::from(w[0])).rem_euclid(per);
            if d > per / 2 {
                d - per
            } else {
                d
            }
        })
        .sum();
    if moved.abs() < needed {
        return Err(CalibError::CrankDidNotTurn {
            counts: moved,
            needed,
        });
    }
    Ok(if moved > 0 { 1.0 } else { -1.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signs_across_the_wrap_and_refusals() {
        assert_eq!(sensor_sign(0.4, 0.02), Ok(1.0));
        assert_eq!(sensor_sign(-0.4, 0.02), Ok(-1.0));
        // Across the sensor's wrap: 359° held, 1° at rest is 2° clockwise: too small; 340° is −21°.
        let deg = math::to_rad;
        assert!(sensor_sign(deg(359.0), deg(1.0)).is_err());
        assert_eq!(sensor_sign(deg(340.0), deg(1.0)), Ok(-1.0));
        // Counting down through 0 (4096 counts a turn): −300 counts in all.
        assert_eq!(crank_sign(&[100, 0, 3996, 3896], 4096, 50), Ok(-1.0));
        assert_eq!(crank_sign(&[4000, 50, 150], 4096, 50), Ok(1.0));
        assert_eq!(
            crank_sign(&[10, 12, 11], 4096, 50),
            Err(CalibError::CrankDidNotTurn {
                counts: 1,
                needed: 50
            })
        );
    }
}
