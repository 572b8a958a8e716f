//! The tilt servo's map, from jog-to-mark pairs: the operator jogs the mount until its blade
//! sits on a marked angle (0°, 90°, 180° on the frame) and the pulse width is recorded.
//!
//! ```text
//! least squares:  θ = θ_mid + s·(pulse − p_mid),  p_mid = (p_min + p_max)/2
//! ServoMap:       range = s·(p_max − p_min),  centre = θ_mid  (rig::servo's pulse formula inverted)
//! travel:         θ(p_min) … θ(p_max) must cover the configured drive angles
//! ```
//! Refused with fewer than two distinct pulses, a mark missed by more than [`MAX_RESIDUAL_DEG`]
//! (a misread mark, or a servo that is not linear), or a travel short of the limits.

use super::error::CalibError;
use crate::rig::servo::ServoMap;

/// The largest miss of a mark the fit accepts (degrees).
pub const MAX_RESIDUAL_DEG: f64 = 1.0;

/// One jog-to-mark pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mark {
    pub pulse_us: f64,
    pub deg: f64,
}

/// The servo map through `marks`, for a servo driven between `min_us` and `max_us`, checked to
/// reach the drive angles `need_deg` (min, max).
pub fn fit(
    marks: &[Mark],
    min_us: u32,
    max_us: u32,
    need_deg: (f64, f64),
) -> Result<ServoMap, CalibError> {
    let n = marks.len() as f64;
    let distinct = marks
        .iter()
        .enumerate()
        .filter(|(i, m)| marks[..*i].iter().all(|o| o.pulse_us != m.pulse_us))
        .count();
    if distinct < 2 {
        return Err(CalibError::TooFewMarks {
            found: distinct,
            needed: 2,
        });
    }
    let mid = (f64::from(min_us) + f64::from(max_us)) / 2.0;
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for m in marks {
        let x = m.pulse_us - mid;
        sx += x;
        sy += m.deg;
        sxx += x * x;
        sxy += x * m.deg;
    }
    let slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    let centre = (sy - slope * sx) / n;
    let worst = marks
        .iter()
        .map(|m| (centre + slope * (m.pulse_us - mid) - m.deg).abs())
        .fold(0.0, f64::max);
    if worst.is_nan() || worst > MAX_RESIDUAL_DEG {
        return Err(CalibError::ServoFitPoor {
            residual_deg: worst,
            max_deg: MAX_RESIDUAL_DEG,
        });
    }
    let span = slope * (f64::from(max_us) - f64::from(min_us));
    let (lo, hi) = (centre - span.abs() / 2.0, centre + span.abs() / 2.0);
    if lo > need_deg.0 || hi < need_deg.1 {
        return Err(CalibError::ServoTravelShort {
            min_deg: lo,
            max_deg: hi,
        });
    }
    Ok(ServoMap {
        min_us,
        max_us,
        range_deg: span,
        centre_deg: centre,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_line_and_refuses_bad_marks() {
        // A servo 500–2500 µs over 210°, centred at 92° (a mount 2° off): the marks at 0°, 90°,
        // 180° sit at pulses 1500 + (θ − 92)·2000/210.
        let m = |deg: f64| Mark {
            pulse_us: 1500.0 + (deg - 92.0) * 2000.0 / 210.0,
            deg,
        };
        let map = fit(&[m(0.0), m(90.0), m(180.0)], 500, 2500, (-10.0, 190.0)).unwrap();
        assert!((map.range_deg - 210.0).abs() < 1e-9 && (map.centre_deg - 92.0).abs() < 1e-9);
        // The map's pulse for 90° is the mark's pulse.
        assert_eq!(map.pulse_us(90.0), 1481);
        let bad = Mark {
            deg: 95.0,
            ..m(90.0)
        };
        assert!(matches!(
            fit(&[m(0.0), bad, m(180.0)], 500, 2500, (-10.0, 190.0)),
            Err(CalibError::ServoFitPoor { .. })
        ));
        assert!(matches!(
            fit(&[m(0.0), m(0.0)], 500, 2500, (-10.0, 190.0)),
            Err(CalibError::TooFewMarks { found: 1, .. })
        ));
        assert!(matches!(
            fit(&[m(0.0), m(180.0)], 1000, 2000, (-10.0, 190.0)),
            Err(CalibError::ServoTravelShort { .. })
        ));
    }
}
