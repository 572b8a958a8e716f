//! How far each cheaper level is from the Floquet reference (physics §4: "report how far each
//! cheaper criterion is from it"). Every tolerance is the difference measured when the test was
//! written (1000 RK4 steps per period, ends bisected to 1e-12; Floquet's own error ≤ 1.5e-10),
//! rounded up by about 20 %: a regression in any level moves its number past it.

use kapitza_core::stability::{averaging, floquet, harmonic_balance as hb, mathieu, End, Window};

fn value(e: End) -> f64 {
    e.value().unwrap_or_else(|| panic!("missing: {e:?}"))
}

fn reference(k: f64) -> (f64, f64) {
    let w: Window = floquet::window(k, 0.0, 1e-12).unwrap().value;
    (value(w.lower), value(w.upper))
}

/// |cheap − reference| ≤ tol.
fn within(cheap: f64, reference: f64, tol: f64, what: &str) -> f64 {
    let d = cheap - reference;
    assert!(
        d.abs() <= tol,
        "{what}: {cheap} − Floquet {reference} = {d:e}, tolerance {tol:e}"
    );
    d.abs()
}

#[test]
fn inverted_windows() {
    // (k, tolerances for: averaging lower, Mathieu lower, Mathieu upper, harmonic-balance lower,
    //  cubic upper, truncated upper). Measured differences (cheap − Floquet):
    //   k = −0.5: averaging −0.1918, Mathieu −0.1791 / −4.76e-3, HB +2.63e-4 / +1.70e-5,
    //             truncated +3.88e-3
    //   k = −0.3: averaging −0.0935, Mathieu −0.0462 / −1.05e-3, HB +6.93e-5 / +4.29e-6,
    //             truncated +1.63e-3
    //   k = −0.1: averaging −0.0190, Mathieu −1.01e-3 / −1.06e-4, HB +4.10e-6 / +5.08e-7,
    //             truncated +4.15e-4
    let cases = [
        (-0.5, [0.23, 0.215, 5.7e-3, 3.2e-4, 2.1e-5, 4.7e-3]),
        (-0.3, [0.112, 0.056, 1.3e-3, 8.3e-5, 5.2e-6, 2.0e-3]),
        (-0.1, [0.023, 1.2e-3, 1.3e-4, 5.0e-6, 6.1e-7, 5.0e-4]),
    ];
    for (k, tol) in cases {
        let (fl, fu) = reference(k);
        let avg = within(averaging::lower(k).unwrap(), fl, tol[0], "averaging lower");
        let m = mathieu::window(k).unwrap();
        let mat_l = within(value(m.lower), fl, tol[1], "Mathieu lower");
        let mat_u = within(value(m.upper), fu, tol[2], "Mathieu upper");
        let h = hb::window(k).unwrap();
        let hb_l = within(value(h.lower), fl, tol[3], "HB lower");
        let hb_u = within(value(h.upper), fu, tol[4], "HB cubic upper");
        let tr_u = within(
            value(hb::truncated_upper(k).unwrap()),
            fu,
            tol[5],
            "HB truncated upper",
        );
        // The ordering of physics §4: each cheaper level is less accurate.
        assert!(
            avg > mat_l && mat_l > hb_l,
            "k = {k}: lower ends out of order"
        );
        assert!(
            mat_u > hb_u && tr_u > hb_u,
            "k = {k}: upper ends out of order"
        );
        // The Mathieu window here lies at q > 1 and says so.
        assert_eq!(m.note, Some(mathieu::OUTSIDE_RANGE));
        // Averaging predicts no upper end at all.
        assert_eq!(
            averaging::window(k).unwrap().upper,
            End::Missing(averaging::NO_UPPER)
        );
    }
}

#[test]
fn hanging_windows() {
    // Upper ends (lower end m = 0 at every level). Measured (cheap − Floquet):
    //   k = 0:   Mathieu −1.80e-5, HB cubic +9.5e-8, truncated +1.40e-4
    //   k = 0.1: Mathieu −1.12e-6, HB cubic +6.5e-9, truncated +2.45e-5
    //   k = 0.6: Mathieu +1.08e-2 (q ≈ 2.1, flagged), HB cubic (a1-type) −1.19e-4
    //   k = 0.9: Mathieu +5.7e-4 (flagged), HB second-region (b2-type) +1.70e-5
    let (_, f0) = reference(0.0);
    within(
        value(mathieu::window(0.0).unwrap().upper),
        f0,
        2.2e-5,
        "Mathieu k=0",
    );
    within(value(hb::window(0.0).unwrap().upper), f0, 1.2e-7, "HB k=0");
    within(
        value(hb::truncated_upper(0.0).unwrap()),
        f0,
        1.7e-4,
        "truncated k=0",
    );
    let (_, f1) = reference(0.1);
    within(
        value(mathieu::window(0.1).unwrap().upper),
        f1,
        1.4e-6,
        "Mathieu k=0.1",
    );
    within(value(hb::window(0.1).unwrap().upper), f1, 8e-9, "HB k=0.1");
    within(
        value(hb::truncated_upper(0.1).unwrap()),
        f1,
        3e-5,
        "truncated k=0.1",
    );
    let (_, f6) = reference(0.6);
    let m6 = mathieu::window(0.6).unwrap();
    assert_eq!(m6.note, Some(mathieu::OUTSIDE_RANGE));
    within(value(m6.upper), f6, 1.3e-2, "Mathieu k=0.6");
    within(
        value(hb::window(0.6).unwrap().upper),
        f6,
        1.45e-4,
        "HB k=0.6",
    );
    let (_, f9) = reference(0.9);
    within(
        value(mathieu::window(0.9).unwrap().upper),
        f9,
        7e-4,
        "Mathieu k=0.9",
    );
    within(
        value(hb::window(0.9).unwrap().upper),
        f9,
        2.1e-5,
        "HB k=0.9",
    );
}

#[test]
fn subharmonic_thresholds() {
    // 5×5 harmonic balance − Floquet (tr M = 2cos(2π/n)), measured at k = −0.3 for n = 3 … 10:
    // 3.01e-4, 1.80e-4, 1.34e-4, 1.12e-4, 9.98e-5, 9.21e-5, 8.71e-5, 8.36e-5 (always above);
    // at k = −0.5: n = 3: 8.38e-4, n = 8: 3.28e-4. Tolerances 20 % above.
    let measured = [
        3.01e-4, 1.80e-4, 1.34e-4, 1.12e-4, 9.98e-5, 9.21e-5, 8.71e-5, 8.36e-5,
    ];
    for (n, d) in (3..=10).zip(measured) {
        let f = value(floquet::subharmonic_m(-0.3, n, 1e-12).unwrap().value);
        let h = value(hb::subharmonic_m(-0.3, n).unwrap());
        assert!(h > f, "n = {n}");
        within(h, f, 1.2 * d, "order-n threshold, k = −0.3");
    }
    for (n, d) in [(3, 8.38e-4), (8, 3.28e-4)] {
        let f = value(floquet::subharmonic_m(-0.5, n, 1e-12).unwrap().value);
        within(
            value(hb::subharmonic_m(-0.5, n).unwrap()),
            f,
            1.2 * d,
            "order-n threshold, k = −0.5",
        );
    }
}
