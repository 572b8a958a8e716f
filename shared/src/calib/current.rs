//! The current sensor's offset: its mean reading with the H-bridge off (no current can flow),
//! in ADC counts, with the readings' spread as the check that nothing was flowing.

use super::error::CalibError;
use crate::math;

/// What makes an offset plausible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// The plausible offset (counts): around the sensor's mid-scale.
    pub min: f64,
    pub max: f64,
    /// The largest standard deviation (counts) of readings at rest.
    pub max_spread: f64,
}

/// The offset measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Offset {
    pub counts: f64,
    /// Standard deviation of the readings (counts).
    pub spread: f64,
}

/// The mean and spread of `readings` (counts, bridge off), checked against `lim`.
pub fn offset(readings: &[f64], lim: &Limits) -> Result<Offset, CalibError> {
    const NEEDED: usize = 16;
    if readings.len() < NEEDED {
        return Err(CalibError::TooFewSwings {
            found: readings.len(),
            needed: NEEDED,
        });
    }
    let n = readings.len() as f64;
    let mean = readings.iter().sum::<f64>() / n;
    let var = readings
        .iter()
        .map(|r| (r - mean) * (r - mean))
        .sum::<f64>()
        / (n - 1.0);
    let spread = math::sqrt(var);
    if spread.is_nan() || spread > lim.max_spread {
        return Err(CalibError::CurrentNoisy {
            spread,
            max: lim.max_spread,
        });
    }
    if !(lim.min..=lim.max).contains(&mean) {
        return Err(CalibError::CurrentOffsetImplausible {
            offset: mean,
            min: lim.min,
            max: lim.max,
        });
    }
    Ok(Offset {
        counts: mean,
        spread,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIM: Limits = Limits {
        min: 1800.0,
        max: 2300.0,
        max_spread: 8.0,
    };

    #[test]
    fn mean_and_refusals() {
        let quiet: [f64; 32] =
            core::array::from_fn(|i| 2050.0 + if i % 2 == 0 { 2.0 } else { -2.0 });
        let o = offset(&quiet, &LIM).unwrap();
        assert_eq!(o.counts, 2050.0);
        let flowing: [f64; 32] = core::array::from_fn(|i| 2050.0 + 40.0 * (i % 3) as f64);
        assert!(matches!(
            offset(&flowing, &LIM),
            Err(CalibError::CurrentNoisy { .. })
        ));
        assert!(matches!(
            offset(&[100.0; 32], &LIM),
            Err(CalibError::CurrentOffsetImplausible { .. })
        ));
    }
}
