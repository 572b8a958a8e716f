use super::*;
use crate::stability::floquet::Floquet;

/// The Floquet boundary a* at fixed q for `curve`: tr M = +2 on a0, b2 (period π in z) and
/// −2 on b1, a1 (period 2π in z), bisected in a = 4k to 1e-12 within a bracket around the
/// series value.
fn floquet_boundary(curve: Curve, q: f64) -> f64 {
    let fl = Floquet::default();
    let target = match curve {
        Curve::A0 | Curve::B2 => 2.0,
        Curve::B1 | Curve::A1 => -2.0,
    };
    let g = |a: f64| fl.monodromy(a / 4.0, 0.0, q / 2.0).unwrap().trace - target;
    let s = curve.value(q).unwrap();
    let w = (0.25 * q * q).min(0.5);
    // a2 − b2 ≈ q²/2: keep the bracket above b2 short of a2.
    let w_hi = if curve == Curve::B2 { 0.2 * q * q } else { w };
    let (mut lo, mut hi) = (s - w, s + w_hi);
    let glo = g(lo);
    assert!(
        (glo > 0.0) != (g(hi) > 0.0),
        "{curve:?} q={q}: no sign change in bracket"
    );
    while hi - lo > 1e-12 {
        let mid = 0.5 * (lo + hi);
        if (g(mid) > 0.0) == (glo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Floquet-minus-series errors are all measured in a at fixed q.
fn err(curve: Curve, q: f64) -> f64 {
    (curve.value(q).unwrap() - floquet_boundary(curve, q)).abs()
}

#[test]
fn series_agree_with_floquet_at_small_q() {
    // Converged Floquet reference (1000 steps; measured: the boundary in a moves ≤ 2e-11 with
    // 4× the steps, except b2 near its narrow tongue tip: 4e-10 at q = 0.1, 1.4e-10 at 0.3). Measured |series − Floquet| at q = 0.3: a0 2.3e-7, b1 5.9e-8, a1 6.2e-8,
    // b2 2.5e-9 — each matching the first omitted term of A&S 20.2.25 (a0: 68687q⁸/18874368
    // = 2.4e-7; b1: 49q⁶/589824 = 6.1e-8). Tolerance 1e-6 (the brief's "≈ 1e-6" agreement).
    for curve in [Curve::A0, Curve::B1, Curve::A1, Curve::B2] {
        let e = err(curve, 0.3);
        assert!(e < 1e-6, "{curve:?} at q = 0.3: {e:e}");
    }
    // q = 0.1: measured ≤ 8.5e-11 for a0, b1, a1 (omitted terms ≈ 4e-11, 8e-11); b2 3.8e-10,
    // which is Floquet's own step error there (above). Tolerance 1e-9.
    for curve in [Curve::A0, Curve::B1, Curve::A1, Curve::B2] {
        let e = err(curve, 0.1);
        assert!(e < 1e-9, "{curve:?} at q = 0.1: {e:e}");
    }
}

#[test]
fn validity_threshold_is_where_the_error_reaches_a_few_thousandths() {
    // Measured at q = Q_VALID = 1: a0 2.76e-3, b1 7.6e-5, a1 8.6e-5, b2 3.6e-6.
    assert!(err(Curve::A0, Q_VALID) < 3e-3);
    for curve in [Curve::B1, Curve::A1, Curve::B2] {
        assert!(err(curve, Q_VALID) < 1e-4, "{curve:?}");
    }
    // Beyond it a0 degrades fast: measured 5.5e-2 at q = 1.5.
    assert!(err(Curve::A0, 1.5) > 1e-2);
}

#[test]
fn windows_against_floquet() {
    let fl = |k: f64| {
        crate::stability::floquet::window(k, 0.0, 1e-10)
            .unwrap()
            .value
    };
    // k = 0: q ≈ 0.908 < 1, no note. Measured series 0.4540052 vs Floquet 0.4540232:
    // difference 1.8e-5; tolerance 3e-5.
    let w = window(0.0).unwrap();
    assert_eq!(w.note, None);
    assert_eq!(w.lower, End::Value(0.0));
    let d = w.upper.value().unwrap() - fl(0.0).upper.value().unwrap();
    assert!(d.abs() < 3e-5, "{d:e}");
    // k = 0.1: q ≈ 0.56. Measured difference 1.1e-6; tolerance 3e-6.
    let d = window(0.1).unwrap().upper.value().unwrap() - fl(0.1).upper.value().unwrap();
    assert!(d.abs() < 3e-6, "{d:e}");
    // k = −0.3: both ends at q > 1, flagged. Measured: lower 0.82188 vs Floquet 0.86809
    // (−0.046), upper 0.92763 vs 0.92868 (−0.0011).
    let w = window(-0.3).unwrap();
    let f = fl(-0.3);
    assert_eq!(w.note, Some(OUTSIDE_RANGE));
    let dl = w.lower.value().unwrap() - f.lower.value().unwrap();
    let du = w.upper.value().unwrap() - f.upper.value().unwrap();
    assert!((dl + 0.0462).abs() < 1e-3, "{dl}");
    assert!((du + 0.00105).abs() < 1e-4, "{du}");
}

#[test]
fn tongue_tips_and_regions() {
    // a = 1 (k = 1/4) and a = 4 (k = 1) are tongue tips: the window closes at m = 0
    // (b1(0) = a1(0) = 1, b2(0) = a2(0) = 4; exact).
    assert_eq!(window(0.25).unwrap().upper, End::Value(0.0));
    assert_eq!(window(1.0).unwrap().upper, End::Value(0.0));
    // k = 0.3 (second region): upper where a1(q) = 1.2 (a1 ≈ 1 + q at small q: q ≈ 0.2).
    let u = window(0.3).unwrap().upper.value().unwrap();
    assert!((a1(2.0 * u).unwrap() - 1.2).abs() < 1e-12);
    assert_eq!(
        window(2.0).unwrap().upper,
        End::Missing(BEYOND_SECOND_REGION)
    );
}

#[test]
fn rejects_bad_input() {
    assert!(window(f64::NAN).is_err());
    assert!(window(-30.0).is_err());
    assert!(a0(f64::INFINITY).is_err());
    assert!(b1(51.0).is_err());
    // Odd series are in |q|.
    assert_eq!(b1(-0.5).unwrap(), b1(0.5).unwrap());
}
