//! The Floquet level on its own: convergence in the step count, the window search (damping,
//! scan limits), subharmonics and the work it reports. Liouville's det M and the narrow window at
//! k = −0.5 are hard cases HC08 and HC04 (tests/hard_cases/).

use kapitza_core::math;
use kapitza_core::stability::floquet::{self, Floquet};
use kapitza_core::stability::End;

fn value(e: End) -> f64 {
    e.value().unwrap_or_else(|| panic!("missing: {e:?}"))
}

#[test]
fn boundaries_converge_in_the_step_count() {
    // Converged-reference check: quadrupling the steps (1000 → 4000) moves the boundaries by
    // (measured) ≤ 8e-12 at k = −0.3, ≤ 1.2e-11 at −0.5, 3e-12 at 0, and 1.5e-10 at k = 0.6
    // (window end at m ≈ 1.03: larger k + m, faster local oscillation). Tolerances 5e-11 and,
    // for k = 0.6, 3e-10.
    for (k, tol) in [(-0.5, 5e-11), (-0.3, 5e-11), (0.0, 5e-11), (0.6, 3e-10)] {
        let w = |steps| {
            Floquet::new(steps)
                .unwrap()
                .window(k, 0.0, 1e-13)
                .unwrap()
                .value
        };
        let (a, b) = (w(1000), w(4000));
        for (x, y) in [(a.lower, b.lower), (a.upper, b.upper)] {
            assert!((value(x) - value(y)).abs() < tol, "k={k}: {x:?} vs {y:?}");
        }
    }
    // Fourth order: halving h cuts the boundary error ≈ 16× (measured at k = −0.5, lower end:
    // 125 → 250 → 500 steps). Accept 12–20.
    let lower = |steps| {
        value(
            Floquet::new(steps)
                .unwrap()
                .window(-0.5, 0.0, 1e-14)
                .unwrap()
                .value
                .lower,
        )
    };
    let reference = lower(4000);
    let ratio = (lower(125) - reference) / (lower(250) - reference);
    assert!((12.0..20.0).contains(&ratio), "ratio {ratio}");
}

#[test]
fn damping_widens_and_raises_the_window() {
    // Measured, k = −0.3 (δ = 0 / 0.01 / 0.1): lower 0.8680942 / 0.8681222 / 0.8708918,
    // upper 0.9286766 / 0.9287289 / 0.9338937. Damping raises both ends; at each end the
    // damped criterion |tr M| < 1 + e^{−2πδ} is marginal.
    let mut prev = (0.0, 0.0);
    for delta in [0.0, 0.01, 0.1] {
        let w = floquet::window(-0.3, delta, 1e-12).unwrap().value;
        let (l, u) = (value(w.lower), value(w.upper));
        assert!(l > prev.0 && u > prev.1);
        prev = (l, u);
        for m in [l, u] {
            let margin = floquet::margin(-0.3, delta, m).unwrap();
            assert!(margin.abs() < 1e-9, "δ={delta} m={m}: margin {margin:e}");
        }
    }
    close(prev.0, 0.8708918, 1e-7);
    close(prev.1, 0.9338937, 1e-7);
}

fn close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b}");
}

#[test]
fn subharmonics_sit_inside_the_window_in_order() {
    // Order n at tr M = 2cos(2π/n): the trace falls monotonically across the window (checked
    // on 60 points), so the thresholds are unique and decrease with n toward the lower end;
    // n = 2 is the upper end itself.
    let k = -0.3;
    let w = floquet::window(k, 0.0, 1e-12).unwrap().value;
    let (l, u) = (value(w.lower), value(w.upper));
    let trace = |m| floquet::monodromy(k, 0.0, m, 1000).unwrap().trace;
    let mut prev = f64::INFINITY;
    for i in 0..=60 {
        let t = trace(l + (u - l) * f64::from(i) / 60.0);
        assert!(t < prev);
        prev = t;
    }
    assert_eq!(
        floquet::subharmonic_m(k, 2, 1e-12).unwrap().value,
        End::Value(u)
    );
    let mut prev = u;
    for n in 3..=10 {
        let s = value(floquet::subharmonic_m(k, n, 1e-12).unwrap().value);
        assert!(s > l && s < prev, "n={n}");
        let target = 2.0 * math::cos(math::TAU / f64::from(n));
        assert!((trace(s) - target).abs() < 1e-9, "n={n}");
        prev = s;
    }
    // Hanging, 0 < k < 1/4: tr M starts at 2cos(2π√k) < 2, so low orders whose target lies
    // above it are never reached inside the window.
    let r = floquet::subharmonic_m(0.2, 20, 1e-10).unwrap().value;
    assert_eq!(r, End::Missing(floquet::TRACE_NOT_REACHED));
}

#[test]
fn work_is_reported() {
    // Each monodromy is steps_per_period RK4 steps of 4 right-hand sides (both columns at once).
    let fl = Floquet::new(500).unwrap();
    let mo = fl.monodromy(-0.3, 0.0, 0.9).unwrap();
    assert_eq!((mo.stats.steps, mo.stats.rhs_evals), (500, 2000));
    let w = fl.window(-0.3, 0.0, 1e-10).unwrap();
    assert_eq!(w.stats.steps, 500 * w.monodromies);
    assert_eq!(w.stats.rhs_evals, 4 * w.stats.steps);
    // The scan dominates: 0.868/0.002 ≈ 434 grid points below the window, then ~30 per bisection.
    assert!((450..600).contains(&w.monodromies), "{}", w.monodromies);
}

#[test]
fn scan_limits_give_reasons_not_numbers() {
    let short = Floquet::default().with_scan(0.01, 0.05).unwrap();
    let w = short.window(-0.3, 0.0, 1e-8).unwrap().value;
    assert_eq!(w.lower, End::Missing(floquet::NEVER_STABLE));
    assert_eq!(w.upper, End::Missing(floquet::NEVER_STABLE));
    let w = short.window(0.1, 0.0, 1e-8).unwrap().value;
    assert_eq!(
        (w.lower, w.upper),
        (End::Value(0.0), End::Missing(floquet::STABLE_TO_LIMIT))
    );
    // 1/4 < k < 1 (second region, k = 0.9): the window ends at tr M = +2 (the b2 boundary),
    // so there is no flutter (order-2) threshold on it.
    let r = floquet::subharmonic_m(0.9, 2, 1e-8).unwrap().value;
    assert_eq!(r, End::Missing(floquet::NOT_FLUTTER));
}

#[test]
fn rejects_bad_input() {
    assert!(floquet::window(f64::NAN, 0.0, 1e-8).is_err());
    assert!(floquet::window(-0.3, f64::INFINITY, 1e-8).is_err());
    assert!(floquet::window(-0.3, 0.0, 0.0).is_err());
    assert!(floquet::window(-0.3, 0.0, -1e-3).is_err());
    assert!(floquet::window(-0.3, 0.0, f64::NAN).is_err());
    assert!(floquet::subharmonic_m(-0.3, 1, 1e-8).is_err());
    assert!(floquet::subharmonic_m(-0.3, 0, 1e-8).is_err());
    assert!(floquet::margin(0.1, 0.0, f64::NAN).is_err());
    assert!(Floquet::new(0).is_err());
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
    /// Never a NaN: any accepted input gives a finite trace, det and margin.
    #[test]
    fn finite_over_the_accepted_range(k in -25.0f64..25.0, d in 0.0f64..25.0, m in 0.0f64..25.0, steps in 1u32..200) {
        let mo = floquet::monodromy(k, d, m, steps).unwrap();
        proptest::prop_assert!(mo.trace.is_finite() && mo.det.is_finite() && mo.margin().is_finite());
    }
}

#[test]
fn tongue_tips_are_resolved_to_rounding() {
    // Exact answer (Mathieu chart): at k = 1/4 and k = 1 the line a = 4k runs inside a tongue for
    // every m > 0, so the window's upper end is 0. tr M departs from ∓2 only like m² and m⁴
    // there; Floquet's ends are where that rises above rounding: measured 3.7e-8 and 1.26e-3.
    let u = value(floquet::window(0.25, 0.0, 1e-12).unwrap().value.upper);
    assert!(u < 1e-7, "{u}");
    let u = value(floquet::window(1.0, 0.0, 1e-12).unwrap().value.upper);
    assert!(u < 2e-3, "{u}");
}
