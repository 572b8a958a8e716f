//! Properties of the equilibrium finder over the whole (R, θd) plane, and its behaviour at the
//! special and merging points of physics §3.

use kapitza_core::math;
use kapitza_core::model::equilibria::{
    effective_potential, equilibrium_poly, saddle_node_r, MERGE_RAD,
};
use kapitza_core::model::{equilibria, DriveAngle, Stability};
use proptest::prelude::*;

fn drive(deg: f64) -> DriveAngle {
    DriveAngle::from_deg(deg).unwrap()
}

/// v''(φ) by a central second difference of the effective potential: an independent route to the
/// curvature (the finder uses the analytic derivative). Truncation error h²/12·|v''''| ≲ 1e-9·(1+R),
/// rounding 4·ε·(1+R)/h² ≈ 1e-7·(1+R).
fn curvature(r: f64, d: DriveAngle, phi: f64) -> f64 {
    let h = 1e-4;
    (effective_potential(r, d, phi + h) - 2.0 * effective_potential(r, d, phi)
        + effective_potential(r, d, phi - h))
        / (h * h)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn every_equilibrium_is_one(r in 0.0f64..12.0, deg in -180.0f64..180.0) {
        let d = drive(deg);
        let f = equilibrium_poly(r, d);
        let eqs = equilibria(r, d).unwrap();
        for e in eqs.as_slice() {
            // f(φ0) = 0 to rounding: |f| ≤ 1e-12·(1 + R) (f has scale 1 + R/2).
            prop_assert!(f.eval(e.angle).abs() <= 1e-12 * (1.0 + r), "f({}) = {}", e.angle, f.eval(e.angle));
            // Stability agrees with the sign of the effective potential's curvature
            // (v'' = s; compare only where s is clear of the difference quotient's error).
            let v2 = curvature(r, d, e.angle);
            if e.margin.abs() > 1e-5 * (1.0 + r) {
                prop_assert_eq!(e.stability == Stability::Stable, v2 > 0.0, "φ0 {} s {} v'' {}", e.angle, e.margin, v2);
                prop_assert!((v2 - e.margin).abs() < 1e-5 * (1.0 + r));
            }
        }
    }

    #[test]
    fn counts_follow_the_saddle_node_curve(r in 0.0f64..12.0, deg in -180.0f64..180.0) {
        let d = drive(deg);
        let rsn = saddle_node_r(d);
        prop_assume!((r - rsn).abs() > 1e-6 * rsn);
        let eqs = equilibria(r, d).unwrap();
        // Below R_sn two equilibria (one min, one max of v); above it four (two of each).
        let want = if r < rsn { 2 } else { 4 };
        prop_assert_eq!(eqs.len(), want, "R {} θd {} R_sn {}", r, deg, rsn);
        prop_assert_eq!(eqs.stable().count(), want / 2);
        // Each once: no two closer than the merge radius (cyclically).
        let a: Vec<f64> = eqs.as_slice().map(|e| e.angle).collect();
        for i in 0..a.len() {
            for j in i + 1..a.len() {
                prop_assert!(math::wrap_pi(a[i] - a[j]).abs() >= MERGE_RAD);
            }
        }
    }

    #[test]
    fn agrees_with_dense_sampling(r in 0.0f64..8.0, deg in -180.0f64..180.0) {
        // Sign changes of f on a 20 000-point grid count the simple roots, provided no two roots
        // share a grid cell; keep away from the saddle-node curve so that holds.
        let d = drive(deg);
        prop_assume!((r - saddle_node_r(d)).abs() > 0.05);
        let f = equilibrium_poly(r, d);
        let n = 20_000;
        let mut changes = 0;
        let mut prev = f.eval(0.0);
        for i in 1..=n {
            let x = math::TAU * i as f64 / n as f64;
            let v = f.eval(x);
            if (v < 0.0) != (prev < 0.0) { changes += 1; }
            prev = v;
        }
        prop_assert_eq!(equilibria(r, d).unwrap().len(), changes);
    }

    #[test]
    fn strong_drive_always_reaches_a_stable_tilt(r in 2.0f64..20.0, deg in -180.0f64..180.0) {
        // physics §4.5: for R > 2 a stable φ0 within 90° of θd exists at every θd.
        prop_assume!(r > 2.0 + 1e-9);
        let eqs = equilibria(r, drive(deg)).unwrap();
        prop_assert!(eqs.stable().any(|e| e.within_90_of_drive));
    }
}
