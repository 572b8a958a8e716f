//! `kapitza boundary`, run in-process as a user would call it, against the physics §4.5.

use kapitza_core::cases::{self, BoundaryCase};
use serde_json::Value;

fn boundary(args: &[&str]) -> Value {
    let mut argv = vec!["kapitza", "boundary", "--json"];
    argv.extend_from_slice(args);
    let mut out = Vec::new();
    kapitza::run(argv, &mut out).unwrap_or_else(|e| panic!("{args:?}: {e}"));
    serde_json::from_slice(&out).unwrap()
}

fn criterion<'a>(v: &'a Value, name: &str) -> &'a Value {
    v["criteria"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap()
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Checks every printed value of one reference-table row (physics §4.5) against the matching criterion (each printed value
/// must round to what we compute: tolerance half a unit in its last printed place).
fn check_case(case: &BoundaryCase) {
    let k = case.k.to_string();
    let v = boundary(&["--k", &k]);
    assert_eq!(num(&v["k"]), case.k);
    if let Some(p) = case.conventional_lower {
        let got = num(&criterion(&v, "averaging")["lower_m"]);
        assert!(p.matches(got), "k {k}: averaging lower {got} vs {p:?}");
    }
    let hb = criterion(&v, "harmonic_balance");
    if let Some(p) = case.improved_lower {
        let got = num(&hb["lower_m"]);
        assert!(p.matches(got), "k {k}: improved lower {got} vs {p:?}");
    }
    if let Some(p) = case.upper_cubic {
        let got = num(&hb["upper_m"]);
        assert!(p.matches(got), "k {k}: cubic upper {got} vs {p:?}");
    }
    if let Some(p) = case.upper_truncated {
        let got = num(&hb["upper_m_truncated"]);
        assert!(p.matches(got), "k {k}: truncated upper {got} vs {p:?}");
    }
    if let Some((n, p)) = case.subharmonic {
        let s = v["subharmonics"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["order"] == n)
            .unwrap();
        let got = num(&s["m"]);
        assert!(p.matches(got), "k {k}: order-{n} threshold {got} vs {p:?}");
    }
    // Differences from Floquet are what they say they are.
    let f = criterion(&v, "floquet");
    for c in v["criteria"].as_array().unwrap() {
        for end in ["lower", "upper"] {
            let (x, r, d) = (
                &c[format!("{end}_m")],
                &f[format!("{end}_m")],
                &c[format!("{end}_diff_from_floquet")],
            );
            if x.is_number() && r.is_number() {
                assert!((num(d) - (num(x) - num(r))).abs() < 1e-15);
            } else {
                assert!(d.is_null());
            }
        }
        assert!(num(&c["seconds_per_eval"]) > 0.0);
    }
}

#[test]
fn spec_rows() {
    check_case(&cases::K_MINUS_0_3);
    check_case(&cases::K_MINUS_0_5);
    check_case(&cases::K_ZERO);
}

#[test]
fn floquet_matches_the_printed_boundaries() {
    // The Floquet reference rounds to the reference table's printed window ends at k = −0.3 (0.868, 0.929)
    // and to the cubic value at k = 0 (0.4540). At k = −0.5 it gives 1.19182 for the lower end,
    // which the reference table prints as the formula's 1.19208 — see docs/stability.md.
    let v = boundary(&["--k", "-0.3"]);
    let f = criterion(&v, "floquet");
    assert!(cases::K_MINUS_0_3
        .improved_lower
        .unwrap()
        .matches(num(&f["lower_m"])));
    assert!(cases::K_MINUS_0_3
        .upper_cubic
        .unwrap()
        .matches(num(&f["upper_m"])));
    assert_eq!(f["includes_damping"], true);
    // Undamped, the ends come from passes over Hill's matrices: work, but no integration.
    assert!(num(&f["sturm_counts"]) > 0.0);
    assert_eq!(num(&f["monodromies"]), 0.0);
    let v = boundary(&["--k", "0"]);
    assert!(cases::K_ZERO
        .upper_cubic
        .unwrap()
        .matches(num(&criterion(&v, "floquet")["upper_m"])));
    assert_eq!(num(&criterion(&v, "floquet")["lower_m"]), 0.0);
}

#[test]
fn landau_amplitude_in_metres() {
    // physics §4.5 (Landau & Lifshitz): g = 9.81, l = 1 m, ω = 9 rad/s → lower bound on the
    // amplitude 0.492 m from averaging; given a pendulum, ends are also reported in metres.
    let l = cases::LANDAU;
    let v = boundary(&["--point", "1", "--omega", "9"]);
    assert_eq!(v["position"], "inverted");
    let a = criterion(&v, "averaging");
    assert!(
        l.lower_amplitude.matches(num(&a["lower_amplitude"])),
        "{}",
        a["lower_amplitude"]
    );
    assert!(a["upper_amplitude"].is_null() && a["upper_reason"].is_string());
    // k = −g/(ℓω²) (physics §3).
    assert!((num(&v["k"]) + 9.81 / 81.0).abs() < 1e-15);
}

#[test]
fn damping_enters_floquet_only() {
    // δ = √|k|/Q (physics §3). Floquet's window narrows from below with damping; the others keep
    // their undamped values and say so.
    let undamped = boundary(&["--k", "-0.3"]);
    let damped = boundary(&["--k", "-0.3", "--q", "5"]);
    assert!((num(&damped["delta"]) - 0.3f64.sqrt() / 5.0).abs() < 1e-15);
    let (f0, f1) = (
        criterion(&undamped, "floquet"),
        criterion(&damped, "floquet"),
    );
    assert!(num(&f1["lower_m"]) > num(&f0["lower_m"]));
    let hb = criterion(&damped, "harmonic_balance");
    assert_eq!(
        hb["lower_m"],
        criterion(&undamped, "harmonic_balance")["lower_m"]
    );
    assert!(hb["notes"]
        .as_array()
        .unwrap()
        .iter()
        .any(|n| n.as_str().unwrap().contains("undamped")));
    // Physical damping c in 1/s: c = ω0/Q gives the same δ as --q.
    let w0 = (9.81f64 / 0.2).sqrt();
    let c = (w0 / 20.0).to_string();
    let by_c = boundary(&["--point", "0.2", "--omega", "60", "--damping", &c]);
    let by_q = boundary(&["--point", "0.2", "--omega", "60", "--q", "20"]);
    assert!((num(&by_c["delta"]) - num(&by_q["delta"])).abs() < 1e-15);
}

#[test]
fn unconvergeable_steps_are_refused() {
    // Damped, tr M is integrated: 3 steps per period cannot meet --tol 1e-7 (doubling them
    // moves the ends by far more), so the command refuses rather than shift the reference.
    let mut out = Vec::new();
    let err = kapitza::run(
        [
            "kapitza", "boundary", "--k", "-0.3", "--q", "5", "--steps", "3",
        ],
        &mut out,
    )
    .expect_err("must refuse")
    .to_string();
    assert!(
        err.contains("--steps") && err.contains("cannot be converged"),
        "{err}"
    );
    // Undamped, --steps does not enter: the ends stay exact and a note says so.
    let v = boundary(&["--k", "-0.3", "--steps", "3"]);
    let f = criterion(&v, "floquet");
    assert!(cases::K_MINUS_0_3
        .upper_cubic
        .unwrap()
        .matches(num(&f["upper_m"])));
    assert!(f["notes"]
        .as_array()
        .unwrap()
        .iter()
        .any(|n| n.as_str().unwrap().contains("--steps does not apply")));
}

#[test]
fn hanging_position_window_starts_at_zero() {
    // About the hanging position every criterion's window starts at m = 0; at k = 0.1 the first
    // tongue (b1, period 2) ends it: Floquet and harmonic balance agree to 1e-6.
    let v = boundary(&["--k", "0.1"]);
    assert_eq!(v["position"], "hanging");
    for c in v["criteria"].as_array().unwrap() {
        assert_eq!(num(&c["lower_m"]), 0.0, "{}", c["name"]);
    }
    let d = num(&criterion(&v, "harmonic_balance")["upper_diff_from_floquet"]);
    assert!(d.abs() < 1e-6);
}

#[test]
fn bad_input_names_the_argument() {
    for (args, flag) in [
        (vec!["--k", "nan"], "--k"),
        (vec!["--k", "-100"], "--k"),
        (vec!["--k", "-0.3", "--q", "-2"], "--q"),
        (vec!["--k", "-0.3", "--tol", "0"], "--tol"),
        (vec!["--rod", "0.25"], "--omega"),
        (vec!["--rod", "-0.25", "--omega", "100"], "--rod"),
        (
            vec!["--point", "0.2", "--omega", "60", "--damping", "-1"],
            "--damping",
        ),
    ] {
        let mut argv = vec!["kapitza", "boundary"];
        argv.extend_from_slice(&args);
        let mut out = Vec::new();
        let err = kapitza::run(argv, &mut out)
            .expect_err("must fail")
            .to_string();
        assert!(err.contains(flag), "{args:?}: {err}");
        assert!(out.is_empty());
    }
    // --damping needs a physical ω: with --k it is a usage error.
    let mut out = Vec::new();
    assert!(kapitza::run(
        ["kapitza", "boundary", "--k", "-0.3", "--damping", "1"],
        &mut out
    )
    .is_err());
}

#[test]
fn omega_window_for_a_given_stroke() {
    // `--rod L --amplitude A` inverts the window: at the ω it reports as the lower (upper) end,
    // the window in m found by `--omega` (bisected in m, tol 1e-7) has its lower (upper) end at
    // exactly this A. Tolerance: 1e-7 in m, times ℓ = 0.1667 m, plus rounding: 5e-8 m.
    let w = boundary(&["--rod", "0.25", "--amplitude", "0.09"]);
    let f = |omega: f64| {
        let v = boundary(&["--rod", "0.25", "--omega", &omega.to_string()]);
        let fl = criterion(&v, "floquet");
        (num(&fl["lower_amplitude"]), num(&fl["upper_amplitude"]))
    };
    let lo = num(&w["lower"]["omega"]);
    assert!((f(lo).0 - 0.09).abs() < 5e-8, "{w}");
    let hi = num(&w["upper"]["omega"]);
    assert!((f(hi).1 - 0.09).abs() < 5e-8, "{w}");
    // Units: Hz = ω/2π, rpm = 60 Hz.
    assert!((num(&w["lower"]["hz"]) * std::f64::consts::TAU - lo).abs() < 1e-12 * lo);
    assert!((num(&w["lower"]["rpm"]) - 60.0 * num(&w["lower"]["hz"])).abs() < 1e-9);
    // ωc = √(2gℓ)/A (physics §3), ℓ = 2L/3.
    let wc = (2.0 * 9.81 * 0.25 * 2.0 / 3.0f64).sqrt() / 0.09;
    assert!((num(&w["omega_c"]) - wc).abs() < 1e-12 * wc);
    // The demo rod's stroke (m = 0.076) never flutters: no upper end.
    let demo = boundary(&["--rod", "0.25", "--amplitude", "0.0127"]);
    assert!(demo["upper"].is_null());
}
