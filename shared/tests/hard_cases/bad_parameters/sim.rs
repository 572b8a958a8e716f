//! HC09 for scenes and simulation runs.

use kapitza_core::integrate::{IntegrateError, Symplectic};
use kapitza_core::math;
use kapitza_core::model::{DriveAngle, Geometry};
use kapitza_core::sim::classify::Outcome;
use kapitza_core::sim::scene::{
    DriveFrequency, FidelityChoice, RunLength, Sensor, Viscous, MAX_PERIODS,
};
use kapitza_core::sim::{simulate, Controller, Format, Method, Options, Recorder, Scene, SimError};
use proptest::prelude::*;

use super::*;

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
