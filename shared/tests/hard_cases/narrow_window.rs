//! HC04: the narrow stability window at k = −0.5 (physics §4): the inverted pendulum is stable
//! only for m between the lower and the upper boundary, 0.0308 apart. The risk: a scan steps
//! over the window, or the verdict next to a boundary depends on the step count.

use kapitza_core::stability::floquet::{self, Floquet};
use kapitza_core::stability::End;

fn value(e: End) -> f64 {
    e.value().unwrap_or_else(|| panic!("missing: {e:?}"))
}

#[test]
fn hc04_verdict_does_not_flip_a_hair_from_the_narrow_window() {
    // physics §6 hard case. k = −0.5: the window is 0.0308 wide. 1e-7 inside each end the verdict
    // is "stable", 1e-7 outside "unstable", at every converged step count (boundary error
    // ≤ 1.2e-11 ≪ 1e-7).
    let w = floquet::window(-0.5, 0.0, 1e-12).unwrap().value;
    let (l, u) = (value(w.lower), value(w.upper));
    assert!((u - l - 0.0308).abs() < 1e-4);
    for steps in [1000, 2000, 4000] {
        let fl = Floquet::new(steps).unwrap();
        let stable = |m| fl.monodromy(-0.5, 0.0, m).unwrap().is_stable();
        assert!(stable(l + 1e-7) && stable(u - 1e-7), "steps {steps}");
        assert!(!stable(l - 1e-7) && !stable(u + 1e-7), "steps {steps}");
    }
}

#[test]
fn hc04_window_narrower_than_the_scan_step_is_found() {
    // With a scan step of 0.05 the k = −0.5 window (0.031 wide) falls between two grid points:
    // tr M jumps from above +2 to below −2 in one step, and each end is bisected on its own
    // condition. Same ends as the default scan, within the bisection tolerance.
    let coarse = Floquet::default()
        .with_scan(0.05, 10.0)
        .unwrap()
        .window(-0.5, 0.0, 1e-12)
        .unwrap()
        .value;
    let fine = floquet::window(-0.5, 0.0, 1e-12).unwrap().value;
    assert!((value(coarse.lower) - value(fine.lower)).abs() < 2e-12);
    assert!((value(coarse.upper) - value(fine.upper)).abs() < 2e-12);
    // k = −2: a window only 0.0012 wide (measured [3.19782, 3.19899]), under the default step.
    let w = floquet::window(-2.0, 0.0, 1e-10).unwrap().value;
    let width = value(w.upper) - value(w.lower);
    assert!(width > 0.0 && width < 0.002, "{w:?}");
}
