//! Real-time factor: simulated seconds per wall second over 60 s of simulated time, at a
//! final-state error of 1e-6 against a converged reference, for the full and the averaged model.
//!
//! Error: max(|Δθ|, |Δθ'|/ω) at the end, Δθ wrapped. Reference: DOP853 at rtol = atol = 1e-13,
//! checked converged by its distance to rtol 1e-12 (printed; must be ≪ 1e-6). For each model the
//! loosest tolerance of each adaptive method (DOP853, RKN 8(6), RKN 12(10), each with the
//! standard and the PI controller where it has one) and the fewest RK4 steps per period that
//! reach 1e-6 are found on a ladder, and the fastest is timed. Each is reported as the median of
//! 7 runs in wall time and in the thread's CPU time (the steadier figure on a shared machine).
//!
//! Run: `cargo bench -p kapitza-core --bench realtime`. Figures: docs/performance.md.

mod support;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use kapitza_core::cases::{self, SceneCase};
use kapitza_core::math;
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::{Fidelity, RunLength};
use kapitza_core::sim::{simulate, Controller, Method, Options, Scene};
use std::time::Instant;
use support::thread_cpu_seconds;

const SIMULATED: f64 = 60.0;
const TARGET: f64 = 1e-6;

/// The tilted example scene (R ≈ 3.3 at 135°) with Q = 50, for 60 s.
fn scene(fidelity: Fidelity) -> Scene {
    let case = SceneCase {
        q: 50.0,
        ..cases::TILTED_135
    };
    Scene::from_case(&case, RunLength::Duration(SIMULATED), fidelity).unwrap()
}

/// A method and its step controller.
type Setting = (Method, Controller);

fn options((method, controller): Setting) -> Options {
    Options {
        method,
        controller,
        classify: false,
        ..Options::default()
    }
}

fn end(s: &Scene, m: impl Into<Setting>) -> (f64, f64) {
    let r = simulate(s, &options(m.into()), &mut Discard).unwrap();
    r.end.angle_rate()
}

fn error(a: (f64, f64), b: (f64, f64), omega: f64) -> f64 {
    math::wrap_pi(a.0 - b.0)
        .abs()
        .max((a.1 - b.1).abs() / omega)
}

/// Median (over 7 runs) wall and thread-CPU seconds of one run.
fn median_seconds(s: &Scene, m: Setting) -> (f64, f64) {
    let (mut wall, mut cpu): (Vec<f64>, Vec<f64>) = (0..7)
        .map(|_| {
            let (start, c0) = (Instant::now(), thread_cpu_seconds());
            black_box(end(s, m));
            (start.elapsed().as_secs_f64(), thread_cpu_seconds() - c0)
        })
        .unzip();
    wall.sort_by(f64::total_cmp);
    cpu.sort_by(f64::total_cmp);
    (wall[3], cpu[3])
}

/// The fastest setting on the ladders that reaches TARGET.
fn calibrate(fidelity: Fidelity) -> Setting {
    let s = scene(fidelity);
    let omega = 330.0;
    let standard = Controller::Standard;
    let dop = |tol: f64| Method::Dop853 {
        rtol: tol,
        atol: tol,
    };
    let reference = end(&s, (dop(1e-13), standard));
    let check = end(&s, (dop(1e-12), standard));
    println!(
        "{fidelity:?}: reference converged to {:.1e} (rtol 1e-12 vs 1e-13)",
        error(reference, check, omega)
    );
    // 1, 1.5, 2, 3, 5 and 7 per decade.
    let tolerances = [
        1e-2, 7e-3, 5e-3, 3e-3, 2e-3, 1.5e-3, 1e-3, 7e-4, 5e-4, 3e-4, 2e-4, 1.5e-4, 1e-4, 7e-5,
        5e-5, 3e-5, 2e-5, 1.5e-5, 1e-5, 7e-6, 5e-6, 3e-6, 2e-6, 1.5e-6, 1e-6, 7e-7, 5e-7, 3e-7,
        2e-7, 1.5e-7, 1e-7, 7e-8, 5e-8, 3e-8, 2e-8, 1.5e-8, 1e-8, 7e-9, 5e-9, 3e-9, 2e-9, 1.5e-9,
        1e-9,
    ];
    let rkn86 = |tol: f64| Method::Rkn86 {
        rtol: tol,
        atol: tol,
    };
    let rkn1210 = |tol: f64| Method::Rkn1210 {
        rtol: tol,
        atol: tol,
    };
    let mut ladders: Vec<Vec<Setting>> = Vec::new();
    for controller in [standard, Controller::Pi] {
        ladders.push(tolerances.map(|t| (dop(t), controller)).to_vec());
        ladders.push(tolerances.map(|t| (rkn1210(t), controller)).to_vec());
        // RKN 8(6) adapts its step on the averaged equation only.
        if controller == standard || fidelity == Fidelity::Averaged {
            ladders.push(tolerances.map(|t| (rkn86(t), controller)).to_vec());
        }
    }
    ladders.push(
        [
            0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0, 48.0, 64.0,
            96.0, 128.0, 192.0, 256.0,
        ]
        .map(|spp| {
            (
                Method::Rk4 {
                    steps_per_period: spp,
                },
                standard,
            )
        })
        .to_vec(),
    );
    let mut best: Option<(Setting, f64)> = None;
    for ladder in ladders {
        let Some(m) = ladder
            .into_iter()
            .find(|&m| error(end(&s, m), reference, omega) <= TARGET)
        else {
            continue;
        };
        let (wall, cpu) = median_seconds(&s, m);
        println!(
            "{fidelity:?} {m:?}: error {:.2e}; wall {:.3} ms, real-time factor {:.0}; CPU {:.3} ms, real-time factor {:.0}",
            error(end(&s, m), reference, omega),
            wall * 1e3,
            SIMULATED / wall,
            cpu * 1e3,
            SIMULATED / cpu
        );
        if best.is_none_or(|(_, c)| cpu < c) {
            best = Some((m, cpu));
        }
    }
    best.expect("some setting reaches 1e-6").0
}

fn realtime(c: &mut Criterion) {
    let mut g = c.benchmark_group("realtime_60s_at_1e-6");
    g.sample_size(10);
    for fidelity in [Fidelity::Full, Fidelity::Averaged] {
        let m = calibrate(fidelity);
        let s = scene(fidelity);
        g.bench_function(format!("{fidelity:?}"), |b| {
            b.iter(|| end(black_box(&s), m))
        });
    }
    g.finish();
}

criterion_group!(benches, realtime);
criterion_main!(benches);
