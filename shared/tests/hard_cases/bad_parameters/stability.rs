//! HC09 for the stability criteria: averaging, Mathieu, harmonic balance, Floquet.

use kapitza_core::stability::floquet::{self, Floquet};
use kapitza_core::stability::{averaging, harmonic_balance, mathieu, End, Window};
use proptest::prelude::*;

use super::*;

fn window_floats(w: &Window) -> Vec<f64> {
    [w.lower, w.upper]
        .iter()
        .filter_map(|e| e.value())
        .collect()
}

/// A cheap Floquet set-up (60 RK4 steps, coarse scan) so that accepted inputs run fast.
fn cheap_floquet() -> Floquet {
    Floquet::new(60).unwrap().with_scan(0.05, 2.0).unwrap()
}

proptest! {
    #![proptest_config(cases(256))]

    #[test]
    fn hc09_stability_levels_refuse_bad_k_m_delta(
        k in or_good(-1.0..1.0),
        q in or_good(0.0..3.0),
        n in prop_oneof![Just(0u32), Just(1), 2..12u32, Just(u32::MAX)],
    ) {
        let k_names: &[&str] = &["k ="];
        match averaging::window(k) {
            Err(e) => names(&e, k_names)?,
            Ok(w) => finite("averaging", &window_floats(&w))?,
        }
        match mathieu::window(k) {
            Err(e) => names(&e, k_names)?,
            Ok(w) => finite("mathieu", &window_floats(&w))?,
        }
        for f in [mathieu::a0, mathieu::b1, mathieu::a1, mathieu::b2] {
            match f(q) {
                Err(e) => names(&e, &["q ="])?,
                Ok(v) => finite("mathieu curve", &[v])?,
            }
        }
        match harmonic_balance::window(k) {
            Err(e) => names(&e, k_names)?,
            Ok(w) => finite("harmonic balance", &window_floats(&w))?,
        }
        for v in [harmonic_balance::improved_lower(k), harmonic_balance::flutter_upper(k)] {
            match v {
                Err(e) => names(&e, k_names)?,
                Ok(v) => finite("harmonic balance bound", &[v])?,
            }
        }
        match harmonic_balance::truncated_upper(k) {
            Err(e) => names(&e, k_names)?,
            Ok(e) => finite("truncated", &e.value().into_iter().collect::<Vec<_>>())?,
        }
        match harmonic_balance::subharmonic_m(k, n) {
            Err(e) => names(&e, &["k =", "n ="])?,
            Ok(e) => finite("subharmonic", &e.value().into_iter().collect::<Vec<_>>())?,
        }
    }

    #[test]
    fn hc09_floquet_refuses_bad_inputs(
        k in or_good(-1.0..1.0),
        delta in or_good(0.0..0.5),
        m in or_good(0.0..3.0),
        tol in or_good(1e-8..1e-3),
        steps in prop_oneof![Just(0u32), 1..100u32],
        (step, limit) in (or_good(1e-3..0.5), or_good(0.5..20.0)),
    ) {
        match floquet::monodromy(k, delta, m, steps) {
            Err(e) => names(&e, &["k =", "delta", "m =", "steps_per_period"])?,
            Ok(mo) => {
                let [[a, b], [c, d]] = mo.matrix;
                finite("monodromy", &[a, b, c, d, mo.trace, mo.det, mo.det_exact, mo.margin()])?;
            }
        }
        if let Err(e) = Floquet::default().with_scan(step, limit) {
            names(&e, &["scan_step", "scan_limit"])?;
        }
        let fl = cheap_floquet();
        match fl.window(k, delta, tol) {
            Err(e) => names(&e, &["k =", "delta", "tol"])?,
            Ok(w) => finite("floquet window", &window_floats(&w.value))?,
        }
        match fl.subharmonic_m(k, 4, tol) {
            Err(e) => names(&e, &["k =", "tol"])?,
            Ok(e) => finite("floquet subharmonic", &e.value.value().into_iter().collect::<Vec<_>>())?,
        }
    }
}

#[test]
fn hc09_stability_examples() {
    // NaN and infinite k, negative and absurd m, negative damping, zero steps, a zero tolerance.
    assert_eq!(averaging::window(f64::NAN).unwrap_err().name, "k");
    assert_eq!(mathieu::window(f64::INFINITY).unwrap_err().name, "k");
    assert_eq!(harmonic_balance::window(-1e300).unwrap_err().name, "k");
    assert_eq!(mathieu::a0(1e6).unwrap_err().name, "q");
    assert_eq!(floquet::margin(-0.3, 0.0, -0.5).unwrap_err().name, "m");
    assert_eq!(floquet::margin(-0.3, 0.0, 1e6).unwrap_err().name, "m");
    assert_eq!(floquet::margin(-0.3, -0.1, 0.9).unwrap_err().name, "delta");
    assert_eq!(
        floquet::monodromy(-0.3, 0.0, 0.9, 0).unwrap_err().name,
        "steps_per_period"
    );
    assert_eq!(floquet::window(-0.3, 0.0, 0.0).unwrap_err().name, "tol");
    assert_eq!(floquet::subharmonic_m(-0.3, 1, 1e-6).unwrap_err().name, "n");
    assert_eq!(
        harmonic_balance::subharmonic_m(-0.3, 0).unwrap_err().name,
        "n"
    );
    // A window's missing end is a reason, never a NaN.
    let w = averaging::window(-0.3).unwrap();
    assert!(matches!(w.upper, End::Missing(_)));
}
