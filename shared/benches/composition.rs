//! Composition without waste: what a scene's effects cost per step.
//!
//! * `rhs`: the same number of RK4 steps with a hand-written gravity + drive function, with the
//!   composed bare equation, and as a whole bare-scene run through `simulate` (sampling and
//!   strobes included). The goal: the scene within 5 % of the hand-written loop.
//! * `scene_rk4`: whole runs through `simulate` with RK4 at 32 steps per period (so every
//!   strobe and period-mean sample falls on a step and no interpolation is needed), bare and
//!   with one effect at a time: the marginal cost of each effect, runner included.
//! * `scene_dop853`: the adaptive method, bare and with Coulomb friction (which needs it).
//!
//! Run: `cargo bench -p kapitza-core --bench composition`. Figures: docs/performance.md.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use kapitza_core::cases::TILTED_135 as TILTED;
use kapitza_core::integrate::{rk4_step, Stats, System};
use kapitza_core::math;
use kapitza_core::model::DriveAngle;
use kapitza_core::sim::eom::{FullEom, NoExtra};
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::{Effects, Fidelity, RunLength, Sensor, Viscous};
use kapitza_core::sim::signal::Steady;
use kapitza_core::sim::{simulate, Method, Options, Scene};

/// Gravity and a sinusoidal drive, written out by hand: the cost floor.
struct HandWritten {
    w0sq: f64,
    peak: f64,
    omega: f64,
    sd: f64,
    cd: f64,
}

impl System<2> for HandWritten {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        let (s, c) = math::sin_cos(y[0]);
        dy[0] = y[1];
        dy[1] =
            -self.w0sq * s - self.peak * math::cos(self.omega * t) * (s * self.cd - c * self.sd);
    }
}

const PERIODS: f64 = 512.0;
const STEPS_PER_PERIOD: f64 = 32.0;

/// The tilted example scene ([`cases::TILTED_135`]) with the given effects.
fn scene(effects: Effects) -> Scene {
    let tilted = Scene::from_case(&TILTED, RunLength::Periods(PERIODS), Fidelity::Full).unwrap();
    Scene { effects, ..tilted }
}

fn rhs(c: &mut Criterion) {
    let (ell, a, w) = (
        2.0 * TILTED.rod_length / 3.0,
        TILTED.amplitude,
        TILTED.omega,
    );
    let angle = DriveAngle::from_deg(TILTED.drive_angle_deg).unwrap();
    let hand = HandWritten {
        w0sq: TILTED.gravity / ell,
        peak: a / ell * w * w,
        omega: w,
        sd: angle.sin(),
        cd: angle.cos(),
    };
    let composed = FullEom::<f64, _, _>::new(
        TILTED.gravity / ell,
        angle,
        Steady::new(a / ell, w),
        NoExtra,
    );
    // As many steps as a scene run below, so the three rows compare directly.
    let n = (PERIODS * STEPS_PER_PERIOD) as u32;
    let h = math::TAU / w / STEPS_PER_PERIOD;
    let mut g = c.benchmark_group("rhs");
    g.throughput(Throughput::Elements(u64::from(n)));
    fn steps<S: System<2>>(sys: &S, n: u32, h: f64) -> [f64; 2] {
        let mut y = [1.7, 0.0];
        let mut stats = Stats::default();
        for i in 0..n {
            y = rk4_step(sys, f64::from(i) * h, &y, h, &mut stats);
        }
        y
    }
    g.bench_function("hand_written_rk4_steps", |b| {
        b.iter(|| steps(black_box(&hand), n, h))
    });
    g.bench_function("composed_bare_rk4_steps", |b| {
        b.iter(|| steps(black_box(&composed), n, h))
    });
    let bare = scene(Effects::default());
    let rk4 = Options {
        method: Method::Rk4 {
            steps_per_period: STEPS_PER_PERIOD,
        },
        classify: false,
        ..Options::default()
    };
    g.bench_function("simulate_bare_scene", |b| {
        b.iter(|| simulate(black_box(&bare), &rk4, &mut Discard).unwrap().end)
    });
    g.finish();
}

fn scenes_rk4(c: &mut Criterion) {
    // classify: false — the benchmark is about the integration loop, not the verdict.
    let rk4 = Options {
        method: Method::Rk4 {
            steps_per_period: STEPS_PER_PERIOD,
        },
        classify: false,
        ..Options::default()
    };
    let cases: [(&str, Effects); 7] = [
        ("bare", Effects::default()),
        (
            "viscous",
            Effects {
                viscous: Some(Viscous::Q(50.0)),
                ..Effects::default()
            },
        ),
        (
            "tilt",
            Effects {
                tilt: Some(math::to_rad(30.0)),
                ..Effects::default()
            },
        ),
        (
            "slider_crank",
            Effects {
                slider_crank: Some(0.05),
                ..Effects::default()
            },
        ),
        (
            "ramp",
            Effects {
                ramp: Some(0.5),
                ..Effects::default()
            },
        ),
        (
            "actuator",
            Effects {
                actuator: Some(0.02),
                ..Effects::default()
            },
        ),
        (
            "sensor_2khz",
            Effects {
                sensor: Some(Sensor {
                    bits: 12,
                    noise: 1e-3,
                    rate_hz: 2000.0,
                }),
                ..Effects::default()
            },
        ),
    ];
    let mut g = c.benchmark_group("scene_rk4");
    g.throughput(Throughput::Elements((PERIODS * STEPS_PER_PERIOD) as u64));
    g.sample_size(20);
    for (name, effects) in cases {
        let s = scene(effects);
        g.bench_with_input(BenchmarkId::from_parameter(name), &s, |b, s| {
            b.iter(|| simulate(black_box(s), &rk4, &mut Discard).unwrap().end)
        });
    }
    g.finish();
}

fn scenes_dop853(c: &mut Criterion) {
    let opts = Options {
        method: Method::Dop853 {
            rtol: 1e-8,
            atol: 1e-8,
        },
        classify: false,
        ..Options::default()
    };
    let mut g = c.benchmark_group("scene_dop853");
    g.sample_size(20);
    for (name, effects) in [
        ("bare", Effects::default()),
        (
            "coulomb",
            Effects {
                coulomb: Some(0.4),
                ..Effects::default()
            },
        ),
    ] {
        let s = scene(effects);
        g.bench_with_input(BenchmarkId::from_parameter(name), &s, |b, s| {
            b.iter(|| simulate(black_box(s), &opts, &mut Discard).unwrap().end)
        });
    }
    g.finish();
}

criterion_group!(benches, rhs, scenes_rk4, scenes_dop853);
criterion_main!(benches);
