//! HC09 for the integrators, adaptive and fixed-step.

use kapitza_core::integrate::{
    rk4_fixed, rk4_observe, symplectic_fixed, Control, Dop853, Force, IntegrateError, Phase, Stats,
    Symplectic, System,
};
use proptest::prelude::*;

use super::*;

/// y'' = −y.
struct Oscillator;
impl System<2> for Oscillator {
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = y[1];
        dy[1] = -y[0];
    }
}
impl Force<1> for Oscillator {
    fn accel(&self, _t: f64, q: &[f64; 1], a: &mut [f64; 1]) {
        a[0] = -q[0];
    }
}

proptest! {
    #![proptest_config(cases(512))]

    #[test]
    fn hc09_dop853_bad_settings_are_errors(
        rtol in or_good(1e-10..1e-3),
        atol in or_good(1e-10..1e-3),
        h_max in prop_oneof![Just(f64::INFINITY), or_good(0.01..10.0)],
        h_init in proptest::option::of(or_good(1e-6..1.0)),
        beta in or_good(0.0..0.2),
        max_steps in prop_oneof![Just(0u64), 1..5000u64],
        (t0, t1) in (or_good(-10.0..10.0), or_good(-10.0..10.0)),
        y0 in (or_good(-1.0..1.0), or_good(-1.0..1.0)),
    ) {
        let mut s = Dop853::new(rtol, atol);
        s.h_max = h_max;
        s.h_init = h_init;
        s.beta = beta;
        s.max_steps = max_steps;
        let settings_ok = rtol.is_finite() && atol.is_finite() && rtol >= 0.0 && atol >= 0.0
            && rtol + atol > 0.0 && h_max > 0.0 && !h_max.is_nan()
            && h_init.is_none_or(|h| h.is_finite() && h > 0.0)
            && beta.is_finite() && (0.0..=0.2).contains(&beta);
        match s.integrate(&Oscillator, t0, [y0.0, y0.1], t1) {
            Err(e) => {
                prop_assert!(!e.to_string().is_empty());
                if !settings_ok {
                    prop_assert_eq!(e, IntegrateError::BadTolerance);
                }
            }
            Ok(sol) => {
                prop_assert!(settings_ok, "bad settings accepted: {s:?}");
                finite("dop853", &[sol.t, sol.y[0], sol.y[1]])?;
            }
        }
    }

    #[test]
    fn hc09_fixed_step_integrators_never_panic(
        t0 in or_good(-10.0..10.0),
        h in or_good(-0.1..0.1),
        n in 0..200u32,
        y0 in (or_good(-1.0..1.0), or_good(-1.0..1.0)),
    ) {
        let y0 = [y0.0, y0.1];
        let t1 = t0 + f64::from(n) * h;
        let input_finite = y0.iter().all(|x| x.is_finite()) && t0.is_finite() && h.is_finite();
        let small_steps = h.abs() <= 0.1 && y0.iter().all(|x| x.abs() <= 1e6);
        let check = |name: &str, y: [f64; 2], steps_taken: bool| -> Result<(), TestCaseError> {
            let out_finite = y.iter().all(|x| x.is_finite());
            if input_finite && small_steps {
                prop_assert!(out_finite, "{name}: finite input gave {y:?}");
            }
            if !y0.iter().all(|x| x.is_finite()) && steps_taken {
                prop_assert!(!out_finite, "{name}: non-finite y0 {y0:?} hidden behind {y:?}");
            }
            Ok(())
        };
        let mut stats = Stats::default();
        let y = rk4_fixed(&Oscillator, t0, y0, t1, n, &mut stats);
        check("rk4_fixed", y, true)?;
        let run = rk4_observe(&Oscillator, t0, y0, h, u64::from(n), |_, _| Control::Continue);
        check("rk4_observe", run.y, n > 0)?;
        prop_assert_eq!(run.stats.steps, u64::from(n));
        for scheme in [Symplectic::Verlet, Symplectic::Yoshida4, Symplectic::Yoshida6] {
            let x0 = Phase { q: [y0[0]], v: [y0[1]] };
            let run = symplectic_fixed(scheme, &Oscillator, t0, x0, h, u64::from(n),
                                       |_, _| Control::Continue);
            check("symplectic", [run.y.q[0], run.y.v[0]], n > 0)?;
        }
    }
}

#[test]
fn hc09_integrator_examples() {
    let osc = |s: Dop853| s.integrate(&Oscillator, 0.0, [1.0, 0.0], 1.0);
    for s in [
        Dop853::new(f64::NAN, 1e-9),
        Dop853::new(-1e-9, 1e-9),
        Dop853::new(0.0, 0.0),
        Dop853::new(1e-9, f64::INFINITY),
        Dop853 {
            h_max: 0.0,
            ..Dop853::new(1e-9, 1e-9)
        },
        Dop853 {
            h_init: Some(-1.0),
            ..Dop853::new(1e-9, 1e-9)
        },
        Dop853 {
            beta: 1.0,
            ..Dop853::new(1e-9, 1e-9)
        },
    ] {
        assert_eq!(osc(s).unwrap_err(), IntegrateError::BadTolerance, "{s:?}");
    }
    let s = Dop853::new(1e-9, 1e-9);
    assert!(matches!(
        s.integrate(&Oscillator, 0.0, [f64::NAN, 0.0], 1.0),
        Err(IntegrateError::NonFinite { .. })
    ));
    assert!(matches!(
        s.integrate(&Oscillator, 0.0, [1.0, 0.0], f64::INFINITY),
        Err(IntegrateError::NonFinite { .. })
    ));
    // A subnormal first step cannot advance the clock: an error, not a hang.
    let tiny = Dop853 {
        h_init: Some(5e-324),
        ..s
    };
    assert!(matches!(
        osc(tiny),
        Err(IntegrateError::StepTooSmall { .. })
    ));
}
