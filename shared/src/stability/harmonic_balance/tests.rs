//! Checks of the derivations themselves: the determinants' coefficients against their hand
//! expansions, and — independently of any hand algebra — that the trial series built from a
//! null vector really balances every retained harmonic of x'' + (k − m cos τ)x.

use super::*;

/// Solves the singular n×n system A x = 0 with x₀ = 1 (Gaussian elimination with partial
/// pivoting on rows 1.. and columns 1..).
fn null_vector<const N: usize>(a: &[[f64; N]; N]) -> [f64; N] {
    let mut m = [[0.0; N]; N]; // augmented: columns 1..N of rows 1..N, rhs in column 0
    for i in 1..N {
        m[i][0] = -a[i][0];
        m[i][1..N].copy_from_slice(&a[i][1..N]);
    }
    for c in 1..N {
        let piv = (c..N)
            .max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))
            .unwrap();
        m.swap(c, piv);
        for r in 1..N {
            if r != c {
                let f = m[r][c] / m[c][c];
                let pivot_row = m[c];
                for (x, p) in m[r].iter_mut().zip(pivot_row) {
                    *x -= f * p;
                }
            }
        }
    }
    let mut x = [1.0; N];
    for i in 1..N {
        x[i] = m[i][0] / m[i][i];
    }
    x
}

/// Projection of r(τ) = x'' + (k − m cos τ) x onto `basis(q τ / n)` over one period 2πn, where
/// x = Σ A_i basis(p_i τ / n); trapezoid rule on 64n points is exact for these trig polynomials.
fn residual(
    k: f64,
    m: f64,
    n: f64,
    ps: &[f64],
    amps: &[f64],
    basis: fn(f64) -> f64,
    q: f64,
) -> f64 {
    let samples = 64 * n as usize;
    let h = math::TAU * n / samples as f64;
    let mut sum = 0.0;
    for s in 0..samples {
        let t = s as f64 * h;
        let (mut x, mut xdd) = (0.0, 0.0);
        for (&p, &a) in ps.iter().zip(amps) {
            x += a * basis(p * t / n);
            xdd -= a * (p / n) * (p / n) * basis(p * t / n);
        }
        sum += (xdd + (k - m * math::cos(t)) * x) * basis(q * t / n);
    }
    sum * h / (math::PI * n)
}

#[test]
fn lower_boundary_closed_form_is_the_determinant_root() {
    // det of the (A0, A1, A2) cos system, expanded here, vanishes at improved_lower.
    for k in [-0.05, -0.3, -0.5, -1.0] {
        let l = Poly::linear;
        let a = [
            [l(k, 0.0), l(0.0, -0.5), Poly::ZERO],
            [l(0.0, -1.0), l(k - 1.0, 0.0), l(0.0, -0.5)],
            [Poly::ZERO, l(0.0, -0.5), l(k - 4.0, 0.0)],
        ];
        let d = poly::det(&a).unwrap();
        // Closed form: det = k(k−1)(k−4) − m²(3k−8)/4.
        let want = [k * (k - 1.0) * (k - 4.0), 0.0, -(3.0 * k - 8.0) / 4.0];
        for (g, w) in d.coeffs().iter().zip(want) {
            assert!((g - w).abs() < 1e-14, "{:?}", d.coeffs());
        }
        let m = improved_lower(k).unwrap();
        assert!(d.eval(m).abs() < 1e-13);
        // The balanced series: x = A0 + A1 cos τ + A2 cos 2τ (cos(pτ) = cos(pτ·1/1)).
        let num: [[f64; 3]; 3] =
            core::array::from_fn(|i| core::array::from_fn(|j| a[i][j].eval(m)));
        let v = null_vector(&num);
        for q in [0.0, 1.0, 2.0] {
            let r = residual(k, m, 1.0, &[0.0, 1.0, 2.0], &v, math::cos, q);
            let r = if q == 0.0 { r / 2.0 } else { r }; // the constant's projection counts twice
            assert!(r.abs() < 1e-12, "k={k} harmonic {q}: {r:e}");
        }
        // The dropped harmonic cos 3τ carries the truncation error: −(m/2)A2.
        let r3 = residual(k, m, 1.0, &[0.0, 1.0, 2.0], &v, math::cos, 3.0);
        assert!((r3 + 0.5 * m * v[2]).abs() < 1e-12);
    }
}

#[test]
fn flutter_cubic_coefficients_and_balance() {
    for k in [-0.5, -0.3, 0.0, 0.1] {
        let d = flutter_determinant(k).unwrap();
        // Hand expansion: D = (4k−1)P − 2P m − (32k − 104) m² + 8 m³, P = (4k−9)(4k−25).
        let p = (4.0 * k - 9.0) * (4.0 * k - 25.0);
        let want = [(4.0 * k - 1.0) * p, -2.0 * p, -(32.0 * k - 104.0), 8.0];
        for (g, w) in d.coeffs().iter().zip(want) {
            assert!(
                (g - w).abs() < 1e-12 * w.abs().max(1.0),
                "k={k}: {:?}",
                d.coeffs()
            );
        }
        // At the root of D the cos-type series A1 cos(τ/2) + A3 cos(3τ/2) + A5 cos(5τ/2)
        // balances its three harmonics; at minus that root the sine-type series does (m → −m;
        // its matrix is the cos-type one conjugated by diag(1, −1, 1), so B = (A1, −A3, A5)).
        let m = flutter_upper(k).unwrap();
        let root = if d.eval(m).abs() < d.eval(-m).abs() {
            m
        } else {
            -m
        };
        let l = Poly::linear;
        let a = [
            [l(4.0 * k - 1.0, -2.0), l(0.0, -2.0), Poly::ZERO],
            [l(0.0, -2.0), l(4.0 * k - 9.0, 0.0), l(0.0, -2.0)],
            [Poly::ZERO, l(0.0, -2.0), l(4.0 * k - 25.0, 0.0)],
        ];
        let num: [[f64; 3]; 3] =
            core::array::from_fn(|i| core::array::from_fn(|j| a[i][j].eval(root)));
        let v = null_vector(&num);
        for q in [1.0, 3.0, 5.0] {
            let r = residual(k, root, 2.0, &[1.0, 3.0, 5.0], &v, math::cos, q);
            assert!(r.abs() < 1e-11, "k={k} cos harmonic {q}/2: {r:e}");
            let r = residual(
                k,
                -root,
                2.0,
                &[1.0, 3.0, 5.0],
                &[v[0], -v[1], v[2]],
                math::sin,
                q,
            );
            assert!(r.abs() < 1e-11, "k={k} sin harmonic {q}/2: {r:e}");
        }
        assert!(residual(k, root, 2.0, &[1.0, 3.0, 5.0], &v, math::cos, 7.0).abs() > 1e-6);
    }
}

#[test]
fn truncated_formula_is_the_two_by_two_root() {
    // Dropping A5: (4k−1−2m)(4k−9) − 4m² = 0 at m = −truncated_upper (cos type) for k < 1/4.
    for k in [-0.5, -0.3, 0.0, 0.2] {
        let m = -truncated_upper(k).unwrap().value().unwrap();
        let r = (4.0 * k - 1.0 - 2.0 * m) * (4.0 * k - 9.0) - 4.0 * m * m;
        assert!(r.abs() < 1e-12, "{k}: {r:e}");
    }
    // k = 0: closed form 3(√13 − 3)/4 (physics §4).
    let want = 3.0 * (math::sqrt(13.0) - 3.0) / 4.0;
    assert!((truncated_upper(0.0).unwrap().value().unwrap() - want).abs() < 1e-15);
    assert_eq!(truncated_upper(1.0).unwrap(), End::Missing(NO_REAL_ROOT));
}

#[test]
fn second_region_boundary_balances() {
    // B1 sin τ + B2 sin 2τ + B3 sin 3τ at m = √(2(k−1)(k−4)(k−9)/(k−5)).
    let k = 0.9;
    let m = second_region_upper(k);
    let a = [
        [k - 1.0, -m / 2.0, 0.0],
        [-m / 2.0, k - 4.0, -m / 2.0],
        [0.0, -m / 2.0, k - 9.0],
    ];
    let v = null_vector(&a);
    for q in [1.0, 2.0, 3.0] {
        let r = residual(k, m, 1.0, &[1.0, 2.0, 3.0], &v, math::sin, q);
        assert!(r.abs() < 1e-12, "harmonic {q}: {r:e}");
    }
}

#[test]
fn subharmonic_matrix_is_symmetric_and_balances() {
    for n in 3..=64 {
        let set = subharmonic_harmonics(n).unwrap();
        assert!(
            set.windows(2).all(|w| w[0] < w[1]),
            "harmonics distinct and ordered for n = {n}"
        );
        let a = subharmonic_matrix(-0.3, n).unwrap();
        let transposed: [[Poly; 5]; 5] =
            core::array::from_fn(|i| core::array::from_fn(|j| a[j][i]));
        assert_eq!(a, transposed, "symmetric for n = {n}");
    }
    for (k, n) in [(-0.3, 3), (-0.3, 8), (-0.5, 5), (0.0, 4)] {
        let m = subharmonic_m(k, n).unwrap().value().unwrap();
        let a = subharmonic_matrix(k, n).unwrap();
        let num: [[f64; 5]; 5] =
            core::array::from_fn(|i| core::array::from_fn(|j| a[i][j].eval(m)));
        let v = null_vector(&num);
        let ps = subharmonic_harmonics(n).unwrap().map(f64::from);
        let nf = f64::from(n);
        for &q in &ps {
            let r = residual(k, m, nf, &ps, &v, math::sin, q);
            assert!(r.abs() < 1e-10, "k={k} n={n} harmonic {q}: {r:e}");
        }
    }
}

#[test]
fn order_two_is_flutter_and_bad_orders_are_rejected() {
    assert_eq!(
        subharmonic_m(-0.3, 2).unwrap(),
        End::Value(flutter_upper(-0.3).unwrap())
    );
    // Hanging, k = 0.1: order 3 is reached inside the window (HB 0.1125352 vs Floquet
    // 0.1125352, measured); order 4 is not (tr M starts at 2cos(2π√0.1) = −0.81 < 0), and the
    // quintic's root m ≈ 3.77 lies far past the window's end 0.28.
    assert!((subharmonic_m(0.1, 3).unwrap().value().unwrap() - 0.1125352).abs() < 1e-6);
    assert_eq!(subharmonic_m(0.1, 4).unwrap(), End::Missing(OUTSIDE_WINDOW));
    // k = 0.9: the window ends on the b2 curve (1.1067) long before the flutter root (12.05).
    assert_eq!(subharmonic_m(0.9, 2).unwrap(), End::Missing(OUTSIDE_WINDOW));
    assert_eq!(window(1.0).unwrap().upper, End::Value(0.0));
    assert!(window(1.0)
        .unwrap()
        .upper
        .value()
        .unwrap()
        .is_sign_positive());
    assert!(subharmonic_m(-0.3, 1).is_err());
    assert!(subharmonic_m(-0.3, 0).is_err());
    assert!(subharmonic_m(-0.3, u32::MAX).is_err());
    assert!(subharmonic_matrix(-0.3, 2).is_err());
    assert!(improved_lower(f64::NAN).is_err());
    assert!(flutter_upper(f64::INFINITY).is_err());
    assert!(window(-26.0).is_err());
}
