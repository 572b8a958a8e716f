//! HC09 for the model: geometry, drive, groups, equilibria, R inferred.

use kapitza_core::math;
use kapitza_core::model::drive::MAX_ANGLE_DEG;
use kapitza_core::model::equilibria::{averaged_energy, effective_potential, margin};
use kapitza_core::model::groups::omega_for_r;
use kapitza_core::model::{equilibria, infer_r, Drive, DriveAngle, Geometry, Groups};
use proptest::prelude::*;

use super::*;

proptest! {
    #![proptest_config(cases(512))]

    #[test]
    fn hc09_geometry_rejects_bad_lengths(
        length in or_good(0.01..2.0),
        (i, m, z) in (or_good(1e-4..1.0), or_good(0.01..1.0), or_good(0.01..0.5)),
    ) {
        for (kind, g) in [("rod", Geometry::rod(length)), ("point", Geometry::point_mass(length))] {
            match g {
                Err(e) => names(&e, &["length"])?,
                Ok(g) => {
                    let ell = g.equivalent_length();
                    prop_assert!(ell.is_finite() && ell > 0.0, "{kind} {length}: ℓ = {ell}");
                }
            }
        }
        match Geometry::general(i, m, z) {
            Err(e) => names(&e, &["inertia", "mass", "com", "length"])?,
            Ok(g) => {
                let ell = g.equivalent_length();
                prop_assert!(ell.is_finite() && ell > 0.0, "general {i} {m} {z}: ℓ = {ell}");
            }
        }
    }

    #[test]
    fn hc09_drive_angle_and_drive(deg in bad(), a in or_good(0.0..0.05), w in or_good(1.0..500.0)) {
        // Degrees beyond ±MAX_ANGLE_DEG are refused too: there the f64 angle no longer holds
        // its position within a turn to any useful precision.
        for (angle, limit) in [
            (DriveAngle::from_deg(deg), MAX_ANGLE_DEG),
            (DriveAngle::from_rad(deg), f64::INFINITY),
        ] {
            match angle {
                Err(e) => {
                    prop_assert!(!deg.is_finite() || deg.abs() > limit, "{deg} refused (limit {limit})");
                    names(&e, &["drive angle"])?;
                }
                Ok(d) => {
                    finite("drive angle", &[d.rad(), d.sin(), d.cos(), d.deg()])?;
                    prop_assert!(d.rad() > -math::PI && d.rad() <= math::PI, "{deg} → {}", d.rad());
                }
            }
        }
        let angle = DriveAngle::from_deg(90.0).unwrap();
        match Drive::new(a, w, angle) {
            Err(e) => names(&e, &["amplitude", "omega"])?,
            Ok(d) => {
                finite("drive", &[d.amplitude, d.omega])?;
                prop_assert!(d.amplitude >= 0.0 && d.omega > 0.0);
            }
        }
    }

    #[test]
    fn hc09_groups_are_finite_or_refused(
        ell in or_good(0.05..1.0),
        g in or_good(1.0..20.0),
        a in or_good(1e-4..0.05),
        w in or_good(1.0..500.0),
        c in or_good(0.0..2.0),
        r in or_good(0.0..10.0),
    ) {
        match Groups::new(ell, g, a, w, c) {
            Err(e) => names(&e, &["equivalent length", "gravity", "amplitude", "omega", "damping",
                                  "R", "k", "m ="])?,
            Ok(gr) => finite("groups", &[gr.omega0, gr.r, gr.omega_c, gr.m, gr.k_abs, gr.c,
                                         gr.omega(), gr.delta()])?,
        }
        match omega_for_r(r, ell, g, a) {
            Err(e) => names(&e, &["R", "equivalent length", "gravity", "amplitude", "omega"])?,
            Ok(w) => prop_assert!(w.is_finite() && w > 0.0, "ω = {w}"),
        }
    }

    #[test]
    fn hc09_equilibria_finite_or_refused(r in or_good(0.0..5.0), deg in -360.0..360.0f64,
                                         phi in or_good(-4.0..4.0)) {
        let d = DriveAngle::from_deg(deg).unwrap();
        match equilibria(r, d) {
            Err(e) => names(&e, &["R"])?,
            Ok(eq) => {
                prop_assert!((2..=4).contains(&eq.len()) || r == 0.0, "{} equilibria", eq.len());
                for e in eq.as_slice() {
                    let mut xs = vec![e.angle, e.margin];
                    xs.extend(e.omega_p_over_omega0);
                    finite("equilibrium", &xs)?;
                }
                // The infallible helpers: finite for every R the API accepts and finite φ.
                if phi.is_finite() {
                    finite("helpers", &[margin(r, d, phi), effective_potential(r, d, phi),
                                        averaged_energy(r, d, 7.7, phi, 1.0)])?;
                }
            }
        }
    }

    #[test]
    fn hc09_infer_r_finite_or_refused(deg in -200.0..200.0f64, phi in or_good(-4.0..4.0),
                                      wp in proptest::option::of(or_good(0.1..3.0))) {
        let d = DriveAngle::from_deg(deg).unwrap();
        match infer_r(d, phi, wp) {
            Err(e) => {
                let msg = e.to_string();
                prop_assert!(!msg.is_empty());
                if !phi.is_finite() {
                    names(&e, &["settled angle"])?;
                }
            }
            Ok(x) => {
                finite("inferred R", &[x.r, x.dr_dphi])?;
                prop_assert!(x.r >= 0.0);
            }
        }
    }
}

#[test]
fn hc09_model_examples() {
    // A zero-length rod, a negative point mass, NaN parts of a general body.
    assert_eq!(Geometry::rod(0.0).unwrap_err().name, "length");
    assert_eq!(Geometry::point_mass(-0.3).unwrap_err().name, "length");
    assert_eq!(
        Geometry::general(f64::NAN, 1.0, 0.1).unwrap_err().name,
        "inertia"
    );
    // A rod so long that ℓ = 2L/3 overflows, and a body whose ℓ = I/(m z) does.
    assert_eq!(
        Geometry::rod(f64::MAX).unwrap_err().name,
        "equivalent length"
    );
    assert_eq!(
        Geometry::general(1e300, 1e-300, 1e-10).unwrap_err().name,
        "equivalent length"
    );
    // Zero frequency, a negative amplitude, NaN gravity.
    let ell = 0.2;
    assert_eq!(
        Groups::new(ell, 9.81, 0.01, 0.0, 0.0).unwrap_err().name,
        "omega"
    );
    assert_eq!(
        Groups::new(ell, 9.81, -0.01, 300.0, 0.0).unwrap_err().name,
        "amplitude"
    );
    assert_eq!(
        Groups::new(ell, f64::NAN, 0.01, 300.0, 0.0)
            .unwrap_err()
            .name,
        "gravity"
    );
    // An absurd drive: R = A²ω²/(2gℓ) overflows; ωc = √(2gℓ)/A overflows for a subnormal A.
    assert_eq!(
        Groups::new(ell, 9.81, 1e200, 1e200, 0.0).unwrap_err().name,
        "R"
    );
    assert_eq!(
        Groups::new(ell, 9.81, 5e-324, 300.0, 0.0).unwrap_err().name,
        "R"
    );
    assert_eq!(
        omega_for_r(1e300, 1e300, 1e300, 1e-300).unwrap_err().name,
        "omega"
    );
    // R = NaN or negative has no equilibria; an absurd R must not give an infinite margin.
    let d = DriveAngle::from_deg(135.0).unwrap();
    assert_eq!(equilibria(-1.0, d).unwrap_err().name, "R");
    assert_eq!(equilibria(f64::NAN, d).unwrap_err().name, "R");
    assert_eq!(equilibria(f64::MAX, d).unwrap_err().name, "R");
    // ωp/ω0 so large that R = (ωp/ω0)² overflows.
    let d = DriveAngle::from_deg(180.0).unwrap();
    assert!(infer_r(d, math::PI, Some(1e300)).is_err());
    assert!(infer_r(d, f64::INFINITY, Some(1.0)).is_err());
}
