//! Hill's method (Sturm counts) against the independent monodromy integration.

use kapitza_core::stability::{floquet, hill, End};

/// Converged monodromy reference: RK4 at 4000 steps per period (module doc of `floquet`: ends
/// move by ≤ 1.2e-11 from 1000 to 4000 steps), bisected to 1e-11.
fn reference(k: f64, delta: f64) -> kapitza_core::stability::Window {
    floquet::Floquet::new(4000)
        .unwrap()
        .window(k, delta, 1e-11)
        .unwrap()
        .value
}

fn val(e: End) -> f64 {
    e.value().unwrap_or_else(|| panic!("missing end: {e:?}"))
}

/// Asserts that the monodromy margin (4000 RK4 steps per period) changes sign across
/// [end − 1e-9, end + 1e-9]: the converged integration puts a boundary within 1e-9 of `end`.
fn brackets(k: f64, delta: f64, end: f64) {
    let fl = floquet::Floquet::new(4000).unwrap();
    let (below, above) = (
        fl.margin(k, delta, end - 1e-9).unwrap(),
        fl.margin(k, delta, end + 1e-9).unwrap(),
    );
    assert!(
        below * above < 0.0,
        "k {k} δ {delta}: end {end}: {below} {above}"
    );
}

#[test]
fn undamped_first_window_matches_the_monodromy_search() {
    // k = −0.3: the full monodromy window search (4000 steps, tol 1e-11) against Hill: 1e-9.
    let (w, _, _) = hill::first_window(-0.3, 10.0, 1e-13).unwrap();
    let r = reference(-0.3, 0.0);
    assert!((val(w.lower) - val(r.lower)).abs() < 1e-9, "{w:?} vs {r:?}");
    assert!((val(w.upper) - val(r.upper)).abs() < 1e-9, "{w:?} vs {r:?}");
}

#[test]
fn undamped_first_windows_bracket_monodromy_boundaries() {
    // Away from tongue tips (k = j²/4), each Hill end has a monodromy boundary within 1e-9.
    for k in [-1.5, -0.5, -0.1, 0.0, 0.1, 0.6, 2.0] {
        let (w, _, _) = hill::first_window(k, 10.0, 1e-13).unwrap();
        if k < 0.0 {
            brackets(k, 0.0, val(w.lower));
        }
        brackets(k, 0.0, val(w.upper));
    }
}

#[test]
fn narrow_window_is_not_stepped_over() {
    // k = −5: the inverted window is about 2e-5 wide in m. Bracket each Hill end by 1e-8 and
    // check that the monodromy margin (4000 steps) changes sign across it: an independent
    // proof that the boundary lies within 1e-8 of Hill's value.
    let (w, flutter, _) = hill::first_window(-5.0, 25.0, 1e-14).unwrap();
    let (l, u) = (val(w.lower), val(w.upper));
    assert!(u > l && u - l < 1e-4, "{l} {u}");
    assert!(flutter);
    let fl = floquet::Floquet::new(4000).unwrap();
    let margin = |m: f64| fl.margin(-5.0, 0.0, m).unwrap();
    for end in [l, u] {
        let (below, above) = (margin(end - 1e-8), margin(end + 1e-8));
        assert!(below * above < 0.0, "end {end}: {below} {above}");
    }
}

#[test]
fn every_crossing_of_a_hanging_sweep_matches_monodromy() {
    // k = 0.6: several windows in m ∈ [0, 4]. At every crossing Hill reports, the monodromy
    // margin (4000 steps) changes sign within ±1e-9, and it does not elsewhere on a fine grid
    // between crossings (no crossing missed) — checked where the margin is clearly nonzero.
    let ts: Vec<_> = hill::Windows::new(0.6, 4.0, 1e-13).unwrap().collect();
    assert!(ts.len() >= 3, "{ts:?}");
    let fl = floquet::Floquet::new(4000).unwrap();
    let margin = |m: f64| fl.margin(0.6, 0.0, m).unwrap();
    for t in &ts {
        let (b, a) = (margin(t.m - 1e-9), margin(t.m + 1e-9));
        assert_eq!(b > 0.0, t.stable_before(), "{t:?}");
        assert_eq!(a > 0.0, t.stable_after(), "{t:?}");
    }
    let fl = floquet::Floquet::new(1000).unwrap();
    for i in 0..=400 {
        let m = 4.0 * f64::from(i) / 400.0;
        let mg = fl.margin(0.6, 0.0, m).unwrap();
        if mg.abs() < 1e-6 {
            continue;
        }
        assert_eq!(
            hill::is_stable(0.6, m).unwrap(),
            mg > 0.0,
            "m {m}: margin {mg}"
        );
    }
}

#[test]
fn subharmonic_thresholds_match_monodromy() {
    // tr M = 2 cos(2π/n) from the exponent ν = 2/n of Hill's problem against the monodromy's
    // value at 4000 steps: its trace passes 2 cos(2π/n) within ±1e-9 of Hill's m.
    for k in [-0.3, -0.5] {
        for n in 3..=8 {
            let h = val(hill::subharmonic_m(k, n, 1e-13).unwrap());
            let target = 2.0 * (std::f64::consts::TAU / f64::from(n)).cos();
            let tr = |m: f64| floquet::monodromy(k, 0.0, m, 4000).unwrap().trace - target;
            assert!(tr(h - 1e-9) * tr(h + 1e-9) < 0.0, "k {k} n {n}: {h}");
        }
        // n = 2 is the window's flutter end.
        let (w, _, _) = hill::first_window(k, 25.0, 1e-13).unwrap();
        assert_eq!(hill::subharmonic_m(k, 2, 1e-13).unwrap(), w.upper);
    }
}

#[test]
fn damped_trace_and_window_match_monodromy() {
    // x = e^{−δτ/2} u: tr M = e^{−πδ} tr M_u(k − δ²/4, m) exactly; RK4 over half a period at
    // 2000 steps against the full-period monodromy at 4000 steps: 1e-9 relative.
    for (k, d, m) in [(-0.3, 0.1, 0.9), (0.2, 0.05, 0.7), (-0.5, 0.2, 1.0)] {
        let full = floquet::monodromy(k, d, m, 4000).unwrap().trace;
        let (kp, _) = hill::damped::shift(k, d);
        let half = hill::trace_u(kp, m, 2000).unwrap() * (-std::f64::consts::PI * d).exp();
        assert!(
            (full - half).abs() < 1e-9 * full.abs().max(1.0),
            "{k} {d} {m}: {full} {half}"
        );
    }
    // Damped windows (Q = 5 at k = −0.3: δ = √0.3/5; δ = 0.05 at k = 0.1): a monodromy
    // boundary within 1e-9 of each end.
    for (k, d) in [(-0.3, 0.3f64.sqrt() / 5.0), (0.1, 0.05)] {
        let w = hill::damped_window(k, d, 1e-13, 2000).unwrap().window;
        if k < 0.0 {
            brackets(k, d, val(w.lower));
        }
        brackets(k, d, val(w.upper));
    }
}

#[test]
fn point_verdicts_match_monodromy_on_a_grid() {
    // The verdict at each point of a coarse (k, m) grid, damped and undamped, against the sign
    // of the monodromy margin where that is clearly nonzero (|margin| > 1e-6).
    for delta in [0.0, 0.08] {
        for i in 0..=16 {
            for j in 0..=16 {
                let k = -1.0 + 2.0 * f64::from(i) / 16.0;
                let m = 3.0 * f64::from(j) / 16.0;
                let mg = floquet::monodromy(k, delta, m, 1000).unwrap().margin();
                if mg.abs() < 1e-6 {
                    continue;
                }
                let got = hill::is_stable_damped(k, delta, m, hill::DEFAULT_HALF_STEPS).unwrap();
                assert_eq!(got, mg > 0.0, "k {k} δ {delta} m {m}: margin {mg}");
            }
        }
    }
}

#[test]
fn newton_first_window_agrees_with_the_walk() {
    // Below the first tongue, first_window finds where a₀ and b₁ meet a by Newton steps in q,
    // relying on both decreasing in q; the walk follows every crossing without that
    // assumption. They must find the same ends (to the tolerance, 1e-10).
    for i in 0..=40 {
        let k = -3.0 + 3.2 * f64::from(i) / 40.0;
        let (w, _, _) = hill::first_window(k, 10.0, 1e-12).unwrap();
        let mut walk = hill::Windows::new(k, 10.0, 1e-12).unwrap();
        let mut lower = walk.stable_at_start().then_some(0.0);
        let mut upper = None;
        for t in walk.by_ref() {
            if !t.stable_before() && t.stable_after() && lower.is_none() {
                lower = Some(t.m);
            } else if t.stable_before() && !t.stable_after() {
                upper = Some(t.m);
                break;
            }
        }
        if k >= 0.0 {
            lower = Some(0.0);
        }
        assert!(
            (val(w.lower) - lower.unwrap()).abs() < 1e-10,
            "k {k}: {w:?} {lower:?}"
        );
        assert!(
            (val(w.upper) - upper.unwrap()).abs() < 1e-10,
            "k {k}: {w:?} {upper:?}"
        );
    }
}

/// The first window's upper end by the walk over every crossing (the first stable → unstable
/// transition), with whether it is a flutter boundary.
fn walked_upper(k: f64, m_max: f64, tol: f64) -> Option<(f64, bool)> {
    hill::Windows::new(k, m_max, tol)
        .unwrap()
        .find(|t| t.stable_before() && !t.stable_after())
        .map(|t| (t.m, t.flutter))
}

#[test]
fn followed_first_window_agrees_with_the_walk_above_the_first_tongue() {
    // k ≥ 1/4: first_window follows only aⱼ and bⱼ₊₁; the walk certifies every crossing of every
    // value. Same upper end (to 1e-10; tolerance 1e-12) and the same kind of end, on a sweep
    // that avoids the tongue tips k = j²/4.
    for i in 0..=60 {
        let k = 0.26 + 0.1963 * f64::from(i);
        let (w, flutter, _) = hill::first_window(k, 10.0, 1e-12).unwrap();
        assert_eq!(val(w.lower), 0.0);
        match walked_upper(k, 10.0, 1e-12) {
            Some((m, f)) => {
                assert!((val(w.upper) - m).abs() < 1e-10, "k {k}: {w:?} vs {m}");
                assert_eq!(flutter, f, "k {k}");
            }
            None => assert!(w.upper.value().is_none(), "k {k}: {w:?}"),
        }
    }
}

#[test]
fn tongue_tips() {
    // k = 1/4 and 1 (a = 1, 4): the tongue leaves m = 0 at once (a₁, b₁ = 1 ± q; a₂, b₂ =
    // 4 + 5q²/12, 4 − q²/12: A&S 20.2.25), so the window is exactly [0, 0].
    for (k, flutter) in [(0.25, true), (1.0, false)] {
        let (w, f, _) = hill::first_window(k, 10.0, 1e-12).unwrap();
        assert_eq!(
            (val(w.lower), val(w.upper), f),
            (0.0, 0.0, flutter),
            "k {k}"
        );
    }
    // k = 9/4, 4, 25/4: both values of the tip rise, and the window is the limit from below
    // (computed without the tip's special start), to 1e-7 (the window's end moves by
    // ≈ |dm/dk|·1e-9 ≪ 1e-7); the k = 9/4 end also brackets a monodromy boundary.
    for k in [2.25, 4.0, 6.25] {
        let (w, _, _) = hill::first_window(k, 10.0, 1e-12).unwrap();
        let (near, _, _) = hill::first_window(k - 1e-9, 10.0, 1e-12).unwrap();
        match (w.upper.value(), near.upper.value()) {
            (Some(a), Some(b)) => assert!((a - b).abs() < 1e-7, "k {k}: {a} vs {b}"),
            (a, b) => assert_eq!(a, b, "k {k}"),
        }
    }
    let (w, _, _) = hill::first_window(2.25, 10.0, 1e-13).unwrap();
    brackets(2.25, 0.0, val(w.upper));
}
