//! HC09 — bad parameters into the numerics.
//!
//! Risk: a NaN, an infinity, a zero or negative length, a zero frequency or an absurd amplitude
//! reaches an integrator or a root finder, which then panics, runs for ever, or returns a result
//! with a NaN or an infinity in it that looks like an answer.
//!
//! Guard: every entry point of the core API that takes a number checks it where it enters
//! (`error::ParamError`, `sim::scene::SceneError`, `IntegrateError::BadTolerance`,
//! `rig::safety::Refusal`) and names the parameter; derived quantities that could overflow
//! (R, ω0, c, ℓ) are checked too, so an accepted input gives a finite result.
//!
//! Criterion, for each entry point: fed NaN, ±∞, ±0, negatives, subnormals and ±1e300 / ±MAX
//! mixed with good values in the other arguments, it never panics, and returns either an error
//! whose message names the bad parameter, or a result in which every float is finite.
//!
//! The fixed-step integrators (`rk4_fixed`, `rk4_observe`, `symplectic_fixed`) have no error
//! channel: their callers check. For them the criterion is that they never panic and never hide
//! a non-finite input behind a finite output.

use kapitza_core::integrate::{
    rk4_fixed, rk4_observe, symplectic_fixed, Control, Dop853, Force, IntegrateError, Phase, Stats,
    Symplectic, System,
};
use kapitza_core::math;
use kapitza_core::model::drive::MAX_ANGLE_DEG;
use kapitza_core::model::equilibria::{averaged_energy, effective_potential, margin};
use kapitza_core::model::groups::omega_for_r;
use kapitza_core::model::{equilibria, infer_r, Drive, DriveAngle, Geometry, Groups};
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::controller::Rig;
use kapitza_core::rig::estimator::Tuning;
use kapitza_core::rig::fixed::{Amps, Angle, Duty};
use kapitza_core::rig::phase_lock::Motor;
use kapitza_core::rig::safety::Request;
use kapitza_core::sim::classify::Outcome;
use kapitza_core::sim::scene::{
    DriveFrequency, FidelityChoice, RunLength, Sensor, Viscous, MAX_PERIODS,
};
use kapitza_core::sim::{simulate, Controller, Format, Method, Options, Recorder, Scene, SimError};
use kapitza_core::stability::floquet::{self, Floquet};
use kapitza_core::stability::{averaging, harmonic_balance, mathieu, End, Window};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Strategies and checks

/// Values that break numerics: NaN, infinities, signed zeros, negatives, subnormals, extremes —
/// and, through `any::<f64>()`, everything else a float can be.
fn bad() -> impl Strategy<Value = f64> {
    prop_oneof![
        10 => specials(),
        1 => Just(f64::MIN_POSITIVE),
        1 => Just(5e-324), // the smallest subnormal
        1 => Just(1e-300),
        1 => -1e6..0.0f64,
        1 => any::<f64>(),
    ]
}

/// The values every strategy here includes (weighted as one value each): non-finite, signed
/// zeros, −1 and the ends of f64.
fn specials() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        -0.0,
        -1.0,
        1e300,
        -1e300,
        f64::MAX,
        f64::MIN,
    ])
}

/// A bad value, or (one time in three) a plausible one from `good`.
fn or_good(good: core::ops::Range<f64>) -> impl Strategy<Value = f64> {
    prop_oneof![2 => bad(), 1 => good]
}

/// Every float finite, else a failure naming the first that is not.
fn finite(what: &str, xs: &[f64]) -> Result<(), TestCaseError> {
    for (i, x) in xs.iter().enumerate() {
        prop_assert!(x.is_finite(), "{what}: value #{i} is {x} (all: {xs:?})");
    }
    Ok(())
}

/// The error's message names one of `names`.
fn names(err: &impl ToString, names: &[&str]) -> Result<(), TestCaseError> {
    let msg = err.to_string();
    prop_assert!(
        names.iter().any(|n| msg.contains(n)),
        "error {msg:?} names none of {names:?}"
    );
    Ok(())
}

fn window_floats(w: &Window) -> Vec<f64> {
    [w.lower, w.upper]
        .iter()
        .filter_map(|e| e.value())
        .collect()
}

fn cases(n: u32) -> ProptestConfig {
    ProptestConfig::with_cases(n)
}

// ---------------------------------------------------------------------------------------------
// model

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

// ---------------------------------------------------------------------------------------------
// stability

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

// ---------------------------------------------------------------------------------------------
// integrate

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

// ---------------------------------------------------------------------------------------------
// sim

/// A 20 cm rod inverted by a 10 mm, 200 rad/s vertical drive (R ≈ 2.0), 20 periods.
fn base_scene() -> Scene {
    let mut s = crate::support::scene(Geometry::rod(0.2).unwrap(), 0.01, 200.0, 180.0);
    s.initial_angle = math::PI - 0.1;
    s.length = RunLength::Periods(20.0);
    s
}

/// One number of a scene.
#[derive(Debug, Clone, Copy)]
enum Field {
    RodLength,
    Inertia,
    Mass,
    Com,
    Amplitude,
    Omega,
    R,
    Gravity,
    InitialAngle,
    InitialRate,
    Periods,
    Duration,
    Q,
    Gamma,
    Coulomb,
    Tilt,
    SliderCrank,
    Ramp,
    SensorNoise,
    SensorRate,
    Actuator,
}

impl Field {
    const ALL: [Field; 21] = [
        Field::RodLength,
        Field::Inertia,
        Field::Mass,
        Field::Com,
        Field::Amplitude,
        Field::Omega,
        Field::R,
        Field::Gravity,
        Field::InitialAngle,
        Field::InitialRate,
        Field::Periods,
        Field::Duration,
        Field::Q,
        Field::Gamma,
        Field::Coulomb,
        Field::Tilt,
        Field::SliderCrank,
        Field::Ramp,
        Field::SensorNoise,
        Field::SensorRate,
        Field::Actuator,
    ];

    /// The base scene with this number set to x (and its effect switched on).
    fn scene(self, x: f64) -> Scene {
        let mut s = base_scene();
        let (m, l) = (0.05, 0.2);
        let general = |i, mass, com| Geometry::General {
            inertia: i,
            mass,
            com,
        };
        let sensor = |noise, rate_hz| {
            Some(Sensor {
                bits: 12,
                noise,
                rate_hz,
            })
        };
        let e = &mut s.effects;
        match self {
            Field::RodLength => s.pendulum = Geometry::Rod { length: x },
            Field::Inertia => s.pendulum = general(x, m, l / 2.0),
            Field::Mass => s.pendulum = general(m * l * l / 3.0, x, l / 2.0),
            Field::Com => s.pendulum = general(m * l * l / 3.0, m, x),
            Field::Amplitude => s.drive.amplitude = x,
            Field::Omega => s.drive.frequency = DriveFrequency::Omega(x),
            Field::R => s.drive.frequency = DriveFrequency::R(x),
            Field::Gravity => s.gravity = x,
            Field::InitialAngle => s.initial_angle = x,
            Field::InitialRate => s.initial_rate = x,
            Field::Periods => s.length = RunLength::Periods(x),
            Field::Duration => s.length = RunLength::Duration(x),
            Field::Q => e.viscous = Some(Viscous::Q(x)),
            Field::Gamma => e.viscous = Some(Viscous::Gamma(x)),
            Field::Coulomb => e.coulomb = Some(x),
            Field::Tilt => e.tilt = Some(x),
            Field::SliderCrank => e.slider_crank = Some(x),
            Field::Ramp => e.ramp = Some(x),
            Field::SensorNoise => e.sensor = sensor(x, 1000.0),
            Field::SensorRate => e.sensor = sensor(1e-3, x),
            Field::Actuator => e.actuator = Some(x),
        }
        s
    }

    /// The scene keys an error about this number may name: its own, or that of a limit it
    /// takes part in (A < 10ℓ, the run's length in its fastest time scale).
    fn keys(self) -> &'static [&'static str] {
        match self {
            Field::RodLength => &["pendulum", "drive.amplitude", "run.periods"],
            Field::Inertia | Field::Mass | Field::Com => {
                &["pendulum", "drive.amplitude", "run.periods"]
            }
            Field::Amplitude => &["drive.amplitude", "drive.omega"],
            Field::Omega => &["drive.omega", "run.periods"],
            Field::R => &["drive.r", "run.periods"],
            Field::Gravity => &["environment.gravity", "run.periods"],
            Field::InitialAngle => &["initial.angle"],
            Field::InitialRate => &["initial.rate", "run.periods"],
            Field::Periods => &["run.periods"],
            Field::Duration => &["run.duration"],
            Field::Q => &["effects.viscous.q", "run.periods"],
            Field::Gamma => &["effects.viscous.gamma", "run.periods"],
            Field::Coulomb => &["effects.coulomb"],
            Field::Tilt => &["effects.tilt", "environment.gravity", "run.periods"],
            Field::SliderCrank => &["effects.slider_crank"],
            Field::Ramp => &["effects.ramp"],
            Field::SensorNoise => &["effects.sensor.noise"],
            Field::SensorRate => &["effects.sensor.rate"],
            Field::Actuator => &["effects.actuator"],
        }
    }
}

fn field() -> impl Strategy<Value = Field> {
    (0..Field::ALL.len()).prop_map(|i| Field::ALL[i])
}

/// A recorder that notes the first non-finite value it is handed.
#[derive(Default)]
struct FiniteRecorder {
    first_bad: Option<String>,
}

impl FiniteRecorder {
    fn see(&mut self, what: &str, xs: &[f64]) {
        if self.first_bad.is_none() && xs.iter().any(|x| !x.is_finite()) {
            self.first_bad = Some(format!("{what} {xs:?}"));
        }
    }
}

impl Recorder for FiniteRecorder {
    fn sample(&mut self, t: f64, theta: f64, rate: f64) {
        self.see("sample", &[t, theta, rate]);
    }
    fn strobe(&mut self, _k: u64, t: f64, theta: f64, rate: f64, mean: f64) {
        // `mean` is NaN by contract outside the analysis window; never infinite.
        self.see(
            "strobe",
            &[t, theta, rate, if mean.is_nan() { 0.0 } else { mean }],
        );
    }
    fn sensed(&mut self, t: f64, angle: f64) {
        self.see("sensed", &[t, angle]);
    }
    fn progress(&mut self, done: f64) {
        self.see("progress", &[done]);
    }
}

fn outcome_floats(o: &Outcome) -> Vec<f64> {
    use kapitza_core::sim::classify::Undecided;
    match *o {
        Outcome::Rest { angle } | Outcome::Flutter { angle } => vec![angle],
        Outcome::Subharmonic { angle, .. } => vec![angle],
        Outcome::Rotation { .. } => vec![],
        Outcome::Chaotic { lyapunov } => vec![lyapunov],
        Outcome::Oscillation { angle, amplitude } => vec![angle, amplitude],
        Outcome::Undecided { reason } => match reason {
            Undecided::NeitherPeriodicNorChaotic { lyapunov } => vec![lyapunov],
            _ => vec![],
        },
    }
}

/// Values that pass a scene's checks, or just fail them, at the extremes; unlike [`bad`] never
/// a value that makes an accepted run take long (a random finite ω of 1e-5 rad/s would).
fn extreme() -> impl Strategy<Value = f64> {
    prop_oneof![
        10 => specials(),
        6 => prop::sample::select(vec![5e-324, 1e-300, 1e-100, 1e-3, 1e3, 1e100]),
    ]
}

/// Fields whose extreme values keep an accepted 20-period run cheap.
fn sim_field() -> impl Strategy<Value = Field> {
    prop_oneof![
        Just(Field::RodLength),
        Just(Field::Inertia),
        Just(Field::Amplitude),
        Just(Field::Omega),
        Just(Field::R),
        Just(Field::Gravity),
        Just(Field::InitialAngle),
        Just(Field::InitialRate),
        Just(Field::Q),
        Just(Field::Gamma),
        Just(Field::Tilt),
        Just(Field::SliderCrank),
        Just(Field::Ramp),
        Just(Field::SensorNoise),
        Just(Field::Actuator),
        Just(Field::Coulomb),
        Just(Field::Mass),
        Just(Field::Com),
        Just(Field::SensorRate),
    ]
}

fn method() -> impl Strategy<Value = Method> {
    prop_oneof![
        Just(Method::DEFAULT),
        (or_good(1e-10..1e-4), or_good(1e-10..1e-4))
            .prop_map(|(rtol, atol)| Method::Dop853 { rtol, atol }),
        (or_good(1e-10..1e-4), or_good(1e-10..1e-4))
            .prop_map(|(rtol, atol)| Method::Rkn86 { rtol, atol }),
        (or_good(1e-10..1e-4), or_good(1e-10..1e-4))
            .prop_map(|(rtol, atol)| Method::Rkn1210 { rtol, atol }),
        // Bad step counts, 1e300 included, must be refused (more than 1e6 per period).
        prop_oneof![extreme(), Just(1.0), Just(3.0), 10.0..200.0]
            .prop_map(|steps_per_period| Method::Rk4 { steps_per_period }),
        (10.0..200.0f64).prop_map(|steps_per_period| Method::Symplectic {
            scheme: Symplectic::Yoshida4,
            steps_per_period
        }),
    ]
}

proptest! {
    #![proptest_config(cases(512))]

    #[test]
    fn hc09_scene_check_names_the_bad_key(f in field(), x in bad()) {
        let s = f.scene(x);
        match s.check() {
            Err(e) => names(&e, f.keys())?,
            Ok(()) => {
                let p = s.physical();
                prop_assert!(p.is_ok(), "checked scene, physical() failed: {p:?}");
                let p = p.unwrap();
                finite("physical", &[p.ell, p.g_eff, p.omega0, p.omega, p.r, p.c, p.amplitude])?;
                prop_assert!(p.ell > 0.0 && p.omega0 > 0.0 && p.omega > 0.0 && p.c >= 0.0);
                let t = s.duration(p.omega);
                // Not longer than MAX_PERIODS of its fastest time scale (drive, swing, damping,
                // initial rate of turning): the work of every method grows with that count.
                let fastest = p.omega.max(p.omega0).max(p.c).max(s.initial_rate.abs());
                prop_assert!(t.is_finite() && t > 0.0 && t * fastest / math::TAU <= MAX_PERIODS,
                             "{f:?} = {x}: run of {t} s at {fastest} rad/s");
            }
        }
        // physical() alone (without check) never reports a non-finite constant as Ok.
        if let Ok(p) = s.physical() {
            finite("physical alone", &[p.ell, p.g_eff, p.omega0, p.omega, p.r, p.c])?;
        }
    }
}

proptest! {
    #![proptest_config(cases(256))]

    #[test]
    fn hc09_simulate_refuses_or_finishes_finite(
        f in sim_field(),
        x in extreme(),
        method in method(),
        f32 in any::<bool>(),
        classify in any::<bool>(),
        auto in any::<bool>(),
        pi in any::<bool>(),
        // A tiny out_dt (1e-300) must be refused (more than 1e9 samples), not sample for ever.
        out_dt in prop_oneof![extreme(), 1e-3..0.1],
    ) {
        let mut s = f.scene(x);
        if auto {
            s.fidelity = FidelityChoice::Auto;
        }
        let opts = Options {
            method,
            controller: if pi { Controller::Pi } else { Controller::Standard },
            format: if f32 { Format::F32 } else { Format::F64 },
            out_dt,
            seed: 7,
            classify,
        };
        let mut rec = FiniteRecorder::default();
        match simulate(&s, &opts, &mut rec) {
            Err(e) => {
                prop_assert!(!e.to_string().is_empty());
                if let SimError::Scene(e) = e {
                    names(&e, f.keys())?;
                }
            }
            Ok(r) => {
                let p = r.physical;
                finite("report", &[r.duration, r.end.t, r.end.theta, r.end.rate, p.ell, p.omega0,
                                   p.omega, p.r, p.c])?;
                finite("outcome", &outcome_floats(&r.outcome))?;
                prop_assert!(rec.first_bad.is_none(), "recorder saw {:?}", rec.first_bad);
            }
        }
    }
}

/// The key `check` names when `f` is set to `x`.
#[track_caller]
fn key(f: Field, x: f64) -> &'static str {
    match f.scene(x).check() {
        Err(e) => e.key,
        Ok(()) => panic!("{f:?} = {x} accepted"),
    }
}

proptest! {
    #![proptest_config(cases(64))]

    /// Damping so strong that RK4's fixed step is past its stability limit (c·h > 2.78): the run
    /// blows up, which must end in an error, never a panic or a NaN in a result.
    #[test]
    fn hc09_unstable_fixed_step_run_is_an_error(
        q in 1e-4..1e-2f64,
        steps_per_period in 3.0..30.0f64,
        f32 in any::<bool>(),
    ) {
        let mut s = Field::Q.scene(q);
        s.drive.amplitude = 0.05;
        s.drive.angle = DriveAngle::from_deg(90.0).unwrap();
        s.initial_angle = 1.0;
        s.length = RunLength::Periods(2000.0);
        let opts = Options {
            method: Method::Rk4 { steps_per_period },
            format: if f32 { Format::F32 } else { Format::F64 },
            ..Options::default()
        };
        let mut rec = FiniteRecorder::default();
        match simulate(&s, &opts, &mut rec) {
            Err(e) => prop_assert!(
                matches!(e, SimError::Integrate(IntegrateError::NonFinite { .. })),
                "{e}"
            ),
            Ok(r) => {
                finite("report", &[r.end.t, r.end.theta, r.end.rate])?;
                prop_assert!(rec.first_bad.is_none(), "recorder saw {:?}", rec.first_bad);
            }
        }
    }
}

#[test]
fn hc09_scene_examples() {
    assert_eq!(base_scene().check(), Ok(()));
    // A zero-length rod (built as a literal: the variants' fields are public).
    assert_eq!(key(Field::RodLength, 0.0), "pendulum.length");
    assert_eq!(key(Field::Mass, f64::NAN), "pendulum.mass");
    // Zero frequency, negative amplitude, NaN gravity.
    assert_eq!(key(Field::Omega, 0.0), "drive.omega");
    assert_eq!(key(Field::R, 0.0), "drive.r");
    assert_eq!(key(Field::Amplitude, -0.01), "drive.amplitude");
    assert_eq!(key(Field::Gravity, f64::NAN), "environment.gravity");
    // Absurd amplitude: a 1000 km stroke on a 20 cm rod.
    assert_eq!(key(Field::Amplitude, 1e6), "drive.amplitude");
    // A drive so fast that R overflows.
    assert_eq!(key(Field::Omega, 1e300), "drive.omega");
    // Damping so strong that c = ω0/Q overflows; ramp and motor lag so short that ω/T does.
    assert_eq!(key(Field::Q, 1e-320), "effects.viscous.q");
    assert_eq!(key(Field::Ramp, 1e-310), "effects.ramp.seconds");
    assert_eq!(key(Field::Actuator, 1e-310), "effects.actuator.lag_s");
    // A sensor noise larger than a turn (its samples would overflow the quantiser).
    assert_eq!(key(Field::SensorNoise, 1e300), "effects.sensor.noise_deg");
    // Runs that would never end: a day at 1e6 rad/s, 20 periods of a 1e-8 rad/s drive (each
    // longer than 1e9 periods of the drive or of the pendulum's own swing).
    let mut s = base_scene();
    s.drive.frequency = DriveFrequency::Omega(1e6);
    s.length = RunLength::Duration(1e5);
    assert_eq!(s.check().unwrap_err().key, "run.duration");
    assert_eq!(key(Field::Omega, 1e-8), "run.periods");
    // The simulator refuses before integrating.
    let err = simulate(
        &Field::Q.scene(-1.0),
        &Options::default(),
        &mut FiniteRecorder::default(),
    );
    assert!(
        matches!(err, Err(SimError::Scene(ref e)) if e.key == "effects.viscous.q"),
        "{err:?}"
    );
}

// ---------------------------------------------------------------------------------------------
// rig

/// An ideal motor: the crank turns at duty × ω_full; no current.
struct IdealMotor {
    crank: f64,
    omega_full: f64,
    dt: f64,
    duty: f64,
}

impl Motor for IdealMotor {
    fn crank_angle(&mut self) -> Angle {
        self.crank += self.duty * self.omega_full * self.dt;
        self.crank = math::wrap_pi(self.crank);
        Angle::from_rad(self.crank)
    }
    fn current(&mut self) -> Amps {
        Amps::ZERO
    }
    fn set_duty(&mut self, duty: Duty) {
        self.duty = duty.to_num();
    }
}

/// Starts the rig at half its speed limit and runs it for 4 s (at most 100 000 samples): long
/// enough for the reference rig's ramp (60 rad/s²) to reach 210 rad/s, where the duty conversion
/// and the stall test multiply the largest numbers.
fn run_rig(cfg: &RigConfig) {
    let mut rig = Rig::new(cfg, &Tuning::DEFAULT, Angle::from_deg(90.0), 0);
    let fc = cfg.control_hz;
    let spc = cfg.sample_hz / fc;
    let _ = rig.request(Request::Start {
        omega: 0.5 * cfg.limits.omega_max,
    });
    let mut motor = IdealMotor {
        crank: 0.0,
        omega_full: cfg.motor.omega_per_duty,
        dt: 1.0 / f64::from(fc),
        duty: 0.0,
    };
    let dt_us = 1_000_000 / fc;
    let dt_sample = (dt_us / spc.max(1)).max(1);
    let ticks = (100_000 / spc.max(1)).clamp(1, 4 * fc);
    let mut t = 0u32;
    for _ in 0..ticks {
        for _ in 0..spc {
            t = t.wrapping_add(dt_sample);
            rig.sample(t, Angle::from_deg(90.0));
        }
        rig.link_message(t);
        rig.control(t, &mut motor, false);
    }
}

/// One number of a rig configuration.
fn rig_field() -> impl Strategy<Value = (&'static str, usize)> {
    const NAMES: [&str; 17] = [
        "amplitude",
        "length",
        "gravity",
        "omega_max",
        "omega_rate_max",
        "drive_angle_min_deg",
        "drive_angle_max_deg",
        "drive_angle_rate_max_deg",
        "current_max",
        "stall_min_omega",
        "stall_fraction",
        "omega_per_duty",
        "lag",
        "kp",
        "ki",
        "max_correction",
        "control_hz",
    ];
    (0..NAMES.len()).prop_map(|i| (NAMES[i], i))
}

fn rig_with(i: usize, x: f64) -> RigConfig {
    let mut c = RigConfig::REFERENCE;
    let (l, m) = (&mut c.limits, &mut c.motor);
    match i {
        0 => c.amplitude = x,
        1 => c.geometry = Geometry::Rod { length: x },
        2 => c.gravity = x,
        3 => l.omega_max = x,
        4 => l.omega_rate_max = x,
        5 => l.drive_angle_min_deg = x,
        6 => l.drive_angle_max_deg = x,
        7 => l.drive_angle_rate_max_deg = x,
        8 => l.current_max = x,
        9 => l.stall_min_omega = x,
        10 => l.stall_fraction = x,
        11 => m.omega_per_duty = x,
        12 => m.lag = x,
        13 => m.kp = x,
        14 => m.ki = x,
        15 => m.max_correction = x,
        _ => {
            // Integers: the control rate from the float's magnitude (0, huge, or plausible).
            c.control_hz = if x.is_finite() && x > 0.0 {
                x.min(4e9) as u32
            } else {
                0
            };
        }
    }
    c
}

proptest! {
    #![proptest_config(cases(512))]

    #[test]
    fn hc09_rig_config_names_the_bad_field((name, i) in rig_field(), x in bad()) {
        let cfg = rig_with(i, x);
        match cfg.validate() {
            Err(e) => {
                // ℓ takes part in the limits on A/ℓ and g/ℓ; the drive-angle range and the
                // rates are checked as pairs.
                let also: &[&str] = match name {
                    "length" => &["amplitude", "gravity"],
                    "drive_angle_min_deg" => &["drive_angle_max_deg"],
                    "control_hz" => &["sample_hz", "omega_max"],
                    _ => &[],
                };
                let mut all = vec![name];
                all.extend_from_slice(also);
                names(&e, &all)?;
            }
            Ok(cfg) => {
                finite("rig", &[cfg.ell(), cfg.omega0(), cfg.r_for_omega(cfg.limits.omega_max)])?;
                for r in [0.5, 1.0, 3.0] {
                    if let Ok(w) = cfg.omega_for_r(r) {
                        finite("omega_for_r", &[w])?;
                    }
                }
                // Any configuration that validates runs without a panic (overflow checks are on).
                run_rig(&cfg);
            }
        }
    }

    #[test]
    fn hc09_rig_requests_refuse_bad_numbers(omega in or_good(0.0..400.0), deg in or_good(0.0..180.0),
                                            r in or_good(0.1..5.0)) {
        let cfg = RigConfig::REFERENCE;
        let mut rig = Rig::new(&cfg, &Tuning::DEFAULT, Angle::from_deg(90.0), 0);
        let before = *rig.supervisor();
        match rig.request(Request::Start { omega }) {
            Err(e) => {
                names(&e, &["omega"])?;
                prop_assert_eq!(*rig.supervisor(), before, "a refusal changed the supervisor");
            }
            Ok(()) => prop_assert!(omega.is_finite() && (0.0..=cfg.limits.omega_max).contains(&omega)),
        }
        if let Err(e) = rig.request(Request::SetOmega { omega }) {
            names(&e, &["omega", "mode"])?;
        }
        match rig.request(Request::SetDriveAngle { deg }) {
            Err(e) => names(&e, &["drive angle"])?,
            Ok(()) => prop_assert!(deg.is_finite()),
        }
        match cfg.omega_for_r(r) {
            Err(e) => names(&e, &["R", "omega"])?,
            Ok(w) => prop_assert!(w.is_finite() && w > 0.0),
        }
    }
}

#[test]
fn hc09_rig_examples() {
    let name = |i: usize, x: f64| -> &'static str { rig_with(i, x).validate().unwrap_err().name };
    // Zero-length rod, NaN gravity, a 1 km stroke on a 25 cm rod.
    assert_eq!(name(1, 0.0), "length");
    assert_eq!(name(2, f64::NAN), "gravity");
    assert_eq!(name(0, 1e3), "amplitude");
    // Each of these would validate and then panic in the control loop: ki below one LSB of
    // I16F16 (0: division by zero in the anti-windup limit), a stall fraction of 1e300 (i64
    // overflow in the stall test), a motor too slow for the duty conversion (i64 overflow).
    assert_eq!(name(14, 1e-9), "ki");
    assert_eq!(name(10, 1e300), "stall_fraction");
    assert_eq!(name(11, 1e-3), "omega_per_duty");
    // Bad requests are refused with the number in the reason.
    let mut rig = Rig::new(
        &RigConfig::REFERENCE,
        &Tuning::DEFAULT,
        Angle::from_deg(90.0),
        0,
    );
    let e = rig.request(Request::Start { omega: f64::NAN }).unwrap_err();
    assert!(e.to_string().contains("omega = NaN"), "{e}");
    let e = rig
        .request(Request::SetDriveAngle { deg: 1e300 })
        .unwrap_err();
    assert!(e.to_string().contains("drive angle"), "{e}");
    assert_eq!(RigConfig::REFERENCE.omega_for_r(0.0).unwrap_err().name, "R");
}
