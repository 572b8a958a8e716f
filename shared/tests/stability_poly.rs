//! Unit tests of `kapitza_core::poly` (kept out of the module to keep it short): arithmetic,
//! real roots of polynomials with known roots (simple, double, triple), roots at an interval's
//! end, and exact determinants against numeric ones.

use kapitza_core::poly::{det, Poly};

/// ∏ (x − r_i) for the given roots.
fn from_roots(r: &[f64]) -> Poly {
    r.iter().fold(Poly::constant(1.0), |p, &ri| {
        p.checked_mul(&Poly::linear(-ri, 1.0)).unwrap()
    })
}

fn assert_roots(p: &Poly, expected: &[f64], tol: f64) {
    let got = p.real_roots();
    assert_eq!(
        got.len(),
        expected.len(),
        "roots {:?} expected {:?}",
        got.as_slice(),
        expected
    );
    for (g, e) in got.as_slice().iter().zip(expected) {
        assert!((g - e).abs() <= tol, "root {g} expected {e}");
    }
}

#[test]
fn arithmetic_and_horner() {
    // (1 + 2x)(3 − x) = 3 + 5x − 2x²; derivative 5 − 4x.
    let p = Poly::linear(1.0, 2.0)
        .checked_mul(&Poly::linear(3.0, -1.0))
        .unwrap();
    assert_eq!(p.coeffs(), &[3.0, 5.0, -2.0]);
    assert_eq!(p.eval(2.0), 5.0);
    assert_eq!(p.derivative().coeffs(), &[5.0, -4.0]);
    assert_eq!((p - p).degree(), 0);
    assert!((p - p).is_zero());
    assert_eq!(p.reflect().coeffs(), &[3.0, -5.0, -2.0]);
    assert!(Poly::new(&[1.0; 9]).is_none());
    assert!(Poly::new(&[f64::NAN]).is_none());
    let p7 = Poly::new(&[0.0, 0.0, 0.0, 0.0, 1.0]).unwrap();
    assert!(p7.checked_mul(&p7).is_none()); // degree 8 > MAX_DEG
}

#[test]
fn simple_roots() {
    // Known roots (constructed): tolerance a few ulp of the root scale.
    assert_roots(&from_roots(&[-3.0, 0.5, 2.0]), &[-3.0, 0.5, 2.0], 1e-14);
    assert_roots(
        &from_roots(&[-1.5, -0.2, 0.1, 1.0, 4.0, 7.0, 9.5]),
        &[-1.5, -0.2, 0.1, 1.0, 4.0, 7.0, 9.5],
        1e-12,
    );
    // x² + 1: no real roots.
    assert!(Poly::new(&[1.0, 0.0, 1.0]).unwrap().real_roots().is_empty());
    // Constants have no roots.
    assert!(Poly::constant(0.0).real_roots().is_empty());
    assert!(Poly::constant(2.0).real_roots().is_empty());
}

#[test]
fn double_and_triple_roots() {
    // (x − 1)²(x + 2) = x³ − 3x + 2: double root at 1 found as a zero critical point.
    let p = from_roots(&[1.0, 1.0, -2.0]);
    let r = p.real_roots();
    assert_eq!(r.as_slice().len(), 2, "{:?}", r);
    assert!((r.as_slice()[0] + 2.0).abs() < 1e-14);
    assert!(
        (r.as_slice()[1] - 1.0).abs() < 1e-7,
        "double root: accuracy √ε"
    );
    assert!(r.is_multiple(1) && !r.is_multiple(0));
    // Degree 5 with a double root in the middle: (x + 1)(x + 0.5)(x − 1)²(x − 3).
    let r = from_roots(&[-1.0, -0.5, 1.0, 1.0, 3.0]).real_roots();
    assert_eq!(r.len(), 4, "{:?}", r);
    for (g, e) in r.as_slice().iter().zip([-1.0, -0.5, 1.0, 3.0]) {
        assert!((g - e).abs() < 1e-7, "{g} vs {e}");
    }
    assert!(r.is_multiple(2) && !r.is_multiple(3));
    // (x − 0.5)³ (x + 1): triple root.
    let p = from_roots(&[0.5, 0.5, 0.5, -1.0]);
    let r = p.real_roots();
    assert_eq!(r.len(), 2, "{:?}", r);
    assert!(
        (r.as_slice()[1] - 0.5).abs() < 1e-5,
        "triple root: accuracy ε^(1/3)"
    );
}

#[test]
fn roots_in_interval_and_at_its_end() {
    let p = from_roots(&[0.0, 1.0, 3.0]);
    let r = p.real_roots_in(0.0, 2.0);
    assert_eq!(r.len(), 2);
    assert_eq!(r.as_slice()[0], 0.0); // p(0) = 0 exactly: the interval's end is a root
    assert!((r.as_slice()[1] - 1.0).abs() < 1e-15);
    assert!(!r.is_multiple(0));
}

#[test]
fn determinant_matches_numeric() {
    // A 3×3 matrix with linear entries: det at x equals the numeric determinant at x.
    let l = |a, b| Poly::linear(a, b);
    let a = [
        [l(1.0, 2.0), l(0.0, -2.0), Poly::ZERO],
        [l(0.0, -2.0), l(-9.0, 0.0), l(0.0, 1.5)],
        [l(0.5, 0.0), l(0.0, -2.0), l(-25.0, 1.0)],
    ];
    let d = det(&a).unwrap();
    assert_eq!(d.degree(), 3);
    for x in [-1.0, 0.0, 0.3, 2.0] {
        let n: [[f64; 3]; 3] = core::array::from_fn(|i| core::array::from_fn(|j| a[i][j].eval(x)));
        let numeric = n[0][0] * (n[1][1] * n[2][2] - n[1][2] * n[2][1])
            - n[0][1] * (n[1][0] * n[2][2] - n[1][2] * n[2][0])
            + n[0][2] * (n[1][0] * n[2][1] - n[1][1] * n[2][0]);
        assert!((d.eval(x) - numeric).abs() < 1e-12 * numeric.abs().max(1.0));
    }
}

proptest::proptest! {
    /// Any three distinct roots spread at least 0.05 apart are recovered.
    #[test]
    fn recovers_random_cubic_roots(a in -5.0f64..5.0, d1 in 0.05f64..3.0, d2 in 0.05f64..3.0, s in 0.1f64..10.0) {
        let want = [a, a + d1, a + d1 + d2];
        let p = from_roots(&want).scale(s);
        let r = p.real_roots();
        proptest::prop_assert_eq!(r.len(), 3);
        for (g, e) in r.as_slice().iter().zip(want) {
            proptest::prop_assert!((g - e).abs() < 1e-10, "{} vs {}", g, e);
        }
    }
}
