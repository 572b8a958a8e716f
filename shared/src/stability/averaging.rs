//! Level 1: averaging (Kapitza; Landau & Lifshitz, *Mechanics*, §30).
//!
//! Splitting the motion into a slow part and a fast wobble at the drive frequency and averaging
//! over the wobble gives an effective potential (physics §3). About the inverted position
//! (θd = 180°, vertical drive) its curvature is ω0²(R − 1), so
//!
//! ```text
//! inverted stable  ⇔  R = m² / (2|k|) > 1  ⇔  m > √(−2k)          (k < 0)
//! hanging stable for every m ≥ 0                                   (k > 0: curvature ω0²(1 + R))
//! ```
//!
//! Averaging knows nothing of parametric resonance, so it predicts no upper end: the flutter
//! instability and the resonance tongues of the hanging position are invisible to it. Valid for
//! a fast drive, ω ≫ ω0 (|k| ≪ 1), and a small amplitude, m = A/ℓ ≪ 1; damping does not move
//! the threshold. It is the cheapest level: one square root.

use super::{check_k, End, Window};
use crate::error::ParamError;
use crate::math;

/// Reason given for the upper end.
pub const NO_UPPER: &str = "averaging predicts no upper end";

/// Validity note attached to every window of this level.
pub const VALIDITY: &str = "averaging: valid for a fast drive, |k| << 1, and m << 1";

/// The averaging threshold √(−2k) for the inverted position (k < 0); 0 for k ≥ 0.
pub fn lower(k: f64) -> Result<f64, ParamError> {
    let k = check_k(k)?;
    Ok(if k < 0.0 { math::sqrt(-2.0 * k) } else { 0.0 })
}

/// The stability window predicted by averaging.
///
/// ```
/// use kapitza_core::stability::{averaging, End};
/// let w = averaging::window(-0.3).unwrap();
/// assert!((w.lower.value().unwrap() - 0.6f64.sqrt()).abs() < 1e-15);
/// assert_eq!(w.upper, End::Missing(averaging::NO_UPPER));
/// ```
pub fn window(k: f64) -> Result<Window, ParamError> {
    Ok(Window {
        lower: End::Value(lower(k)?),
        upper: End::Missing(NO_UPPER),
        note: Some(VALIDITY),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_table_values() {
        // physics §4.5, k = −0.3: √(−2k) = √0.6 = 0.7746, printed 0.775 (3 decimals).
        let c = crate::cases::K_MINUS_0_3;
        let printed = c.conventional_lower.unwrap();
        assert!((lower(c.k).unwrap() - printed.value).abs() < printed.half_ulp);
        // physics §4.5, Landau row: g = 9.81, l = 1 m, ω = 9 rad/s: k = −g/(lω²), and the
        // bound on the amplitude a = m·l is √(2g/(lω²)) = 0.4922, printed 0.492.
        let l = crate::cases::LANDAU;
        let k = -l.gravity / (l.length * l.omega * l.omega);
        let a = lower(k).unwrap() * l.length;
        assert!((a - l.lower_amplitude.value).abs() < l.lower_amplitude.half_ulp);
        assert_eq!(lower(0.2).unwrap(), 0.0);
    }

    #[test]
    fn rejects_bad_k() {
        assert!(window(f64::NAN).is_err());
        assert!(window(f64::INFINITY).is_err());
        assert!(window(-1e3).is_err());
    }
}
