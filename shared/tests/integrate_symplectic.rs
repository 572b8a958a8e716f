//! Störmer–Verlet and Yoshida's compositions (orders 2, 4, 6) against closed forms, and their
//! long-time energy behaviour against RK4 at equal cost. Run with `--nocapture` for the figures.

use kapitza_core::integrate::{
    rk4_observe, symplectic_fixed, Control, Force, Phase, Symplectic, System,
};
use kapitza_core::math;
use kapitza_core::Real;

/// θ'' = −sin θ (ω0 = 1), as a force and as a first-order system for RK4.
struct Pendulum;
impl<R: Real> Force<1, R> for Pendulum {
    fn accel(&self, _t: f64, q: &[R; 1], a: &mut [R; 1]) {
        a[0] = -q[0].sin();
    }
}
impl System<2> for Pendulum {
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = y[1];
        dy[1] = -math::sin(y[0]);
    }
}

/// E = θ'²/2 − cos θ, conserved by the exact flow.
fn energy(q: f64, v: f64) -> f64 {
    0.5 * v * v - math::cos(q)
}

/// q'' = −q + cos 2t from (1, 0): q = (4/3) cos t − (1/3) cos 2t (undetermined coefficients).
/// The explicit time dependence checks that sub-stage forces are taken at the right times.
struct Forced;
impl Force<1> for Forced {
    fn accel(&self, t: f64, q: &[f64; 1], a: &mut [f64; 1]) {
        a[0] = -q[0] + math::cos(2.0 * t);
    }
}
fn forced_exact(t: f64) -> [f64; 2] {
    [
        4.0 / 3.0 * math::cos(t) - math::cos(2.0 * t) / 3.0,
        -4.0 / 3.0 * math::sin(t) + 2.0 / 3.0 * math::sin(2.0 * t),
    ]
}

/// K(k) = π / (2 AGM(1, √(1 − k²))) (DLMF 19.8.5), a fixed number of AGM rounds.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0, math::sqrt(1.0 - k * k));
    for _ in 0..8 {
        (a, b) = (0.5 * (a + b), math::sqrt(a * b));
    }
    math::PI / (2.0 * a)
}

/// Period from rest at θ0: 4 K(sin(θ0/2)).
fn period(theta0: f64) -> f64 {
    4.0 * elliptic_k(math::sin(0.5 * theta0))
}

const METHODS: [Symplectic; 3] = [
    Symplectic::Verlet,
    Symplectic::Yoshida4,
    Symplectic::Yoshida6,
];

/// Error after n steps over [0, t1] against `exact`, in format R.
fn error<F: Force<1, R>, R: Real>(
    m: Symplectic,
    force: &F,
    x0: [f64; 2],
    t1: f64,
    n: u64,
    exact: [f64; 2],
) -> f64 {
    let x0 = Phase {
        q: [R::from_f64(x0[0])],
        v: [R::from_f64(x0[1])],
    };
    let run = symplectic_fixed(m, force, 0.0, x0, t1 / n as f64, n, |_, _| {
        Control::Continue
    });
    assert_eq!(run.stats.rhs_evals, 1 + m.weights().len() as u64 * n);
    (run.y.q[0].to_f64() - exact[0])
        .abs()
        .max((run.y.v[0].to_f64() - exact[1]).abs())
}

#[test]
fn measured_orders_are_2_4_6() {
    // Ratio of errors at h and h/2 ≈ 2^p. Pendulum θ0 = 2 over one period (back to (θ0, 0)),
    // and the forced oscillator over [0, 10] (closed form above).
    let t_pend = period(2.0);
    for (m, n) in [
        (Symplectic::Verlet, 400),
        (Symplectic::Yoshida4, 100),
        (Symplectic::Yoshida6, 40),
    ] {
        let p = f64::from(m.order());
        let pend = |n| error::<_, f64>(m, &Pendulum, [2.0, 0.0], t_pend, n, [2.0, 0.0]);
        let forced = |n| error::<_, f64>(m, &Forced, [1.0, 0.0], 10.0, n, forced_exact(10.0));
        let (e1, e2) = (pend(n), pend(2 * n));
        let (f1, f2) = (forced(n), forced(2 * n));
        let (op, of) = ((e1 / e2).log2(), (f1 / f2).log2());
        eprintln!(
            "{m:?}: pendulum {e1:.2e} → {e2:.2e} (order {op:.2}), forced {f1:.2e} → {f2:.2e} (order {of:.2})"
        );
        assert!((op - p).abs() < 0.25, "{m:?} pendulum order {op}");
        assert!((of - p).abs() < 0.25, "{m:?} forced order {of}");
    }
}

#[test]
fn f32_errors_plateau_near_its_precision() {
    // Each method in f32 follows f64 while truncation dominates and levels off near f32 rounding
    // (ε = 1.2e-7) as h shrinks, where f64 keeps falling.
    let t1 = period(2.0);
    for m in METHODS {
        let n_coarse = [64, 16, 8][m.order() as usize / 2 - 1];
        // Fine enough that f64's truncation error is far below f32 rounding.
        let n_fine = [65_536, 4096, 4096][m.order() as usize / 2 - 1];
        let e32 = |n| error::<_, f32>(m, &Pendulum, [2.0, 0.0], t1, n, [2.0, 0.0]);
        let e64 = |n| error::<_, f64>(m, &Pendulum, [2.0, 0.0], t1, n, [2.0, 0.0]);
        let (c32, c64) = (e32(n_coarse), e64(n_coarse));
        let (f32_fine, f64_fine) = (e32(n_fine), e64(n_fine));
        eprintln!(
            "{m:?}: {n_coarse} steps f32 {c32:.2e} / f64 {c64:.2e}; {n_fine} steps f32 {f32_fine:.2e} / f64 {f64_fine:.2e}"
        );
        assert!(
            (c32 / c64 - 1.0).abs() < 0.1,
            "{m:?}: coarse f32 {c32:e} vs f64 {c64:e}"
        );
        assert!(
            (1e-8..1e-4).contains(&f32_fine),
            "{m:?}: fine f32 {f32_fine:e}"
        );
        assert!(f64_fine < 0.1 * f32_fine, "{m:?}: f64 {f64_fine:e}");
    }
}

/// Max |E − E0| over the first and the last tenth of a run of `periods` periods.
struct Drift {
    first: f64,
    last: f64,
}

fn symplectic_drift(m: Symplectic, theta0: f64, evals_per_period: u64, periods: u64) -> Drift {
    let steps_per_period = evals_per_period / m.weights().len() as u64;
    let n = steps_per_period * periods;
    let h = period(theta0) / steps_per_period as f64;
    let e0 = energy(theta0, 0.0);
    let (mut first, mut last, mut i) = (0.0f64, 0.0f64, 0u64);
    let x0 = Phase {
        q: [theta0],
        v: [0.0],
    };
    symplectic_fixed(m, &Pendulum, 0.0, x0, h, n, |_, x| {
        i += 1;
        let de = (energy(x.q[0], x.v[0]) - e0).abs();
        if i <= n / 10 {
            first = first.max(de);
        } else if i > n - n / 10 {
            last = last.max(de);
        }
        Control::Continue
    });
    Drift { first, last }
}

#[test]
fn energy_stays_bounded_over_1e5_periods_while_rk4_decays() {
    // Pendulum θ0 = 2, 10⁵ periods, 96 force evaluations per period for every method
    // (Verlet 96 steps, Yoshida4 32, Yoshida6 ~13, RK4 24 steps of 4 evaluations).
    // Symplectic: the energy error oscillates; its maximum over the last tenth of the run is
    // the same size as over the first tenth (no secular drift; HNW GNI §IX.8).
    let (theta0, evals, periods) = (2.0, 96, 100_000);
    let mut worst = 0.0f64;
    for m in METHODS {
        let d = symplectic_drift(m, theta0, evals, periods);
        eprintln!(
            "{m:?}: max |ΔE| first 10% {:.2e}, last 10% {:.2e}",
            d.first, d.last
        );
        let ratio = d.last / d.first;
        assert!(
            (0.5..2.0).contains(&ratio),
            "{m:?}: {:e} then {:e}",
            d.first,
            d.last
        );
        worst = worst.max(d.last);
    }
    // RK4 at the same cost: the energy decays monotonically (RK4 damps oscillations: its
    // stability function has |R(ih)| < 1 on the imaginary axis, HNW I §IV.2) until the pendulum
    // hangs at rest, E = −1. Sampled every 100 periods over the first 2000.
    let steps_per_period = evals / 4;
    let h = period(theta0) / steps_per_period as f64;
    let n = steps_per_period * periods;
    let mut samples = Vec::new();
    let mut i = 0u64;
    let end = rk4_observe(&Pendulum, 0.0, [theta0, 0.0], h, n, |_, y| {
        i += 1;
        if i.is_multiple_of(100 * steps_per_period) && samples.len() < 20 {
            samples.push(energy(y[0], y[1]));
        }
        Control::Continue
    });
    let e0 = energy(theta0, 0.0);
    let e_end = energy(end.y[0], end.y[1]);
    eprintln!(
        "RK4: E − E0 every 100 periods {:?}; after 10⁵ periods {:.3}",
        samples
            .iter()
            .map(|e| format!("{:.2e}", e - e0))
            .collect::<Vec<_>>(),
        e_end - e0
    );
    assert!(
        samples.windows(2).all(|w| w[1] < w[0]),
        "not monotone: {samples:?}"
    );
    assert!(e0 - e_end > 100.0 * worst, "RK4 lost {:e}", e0 - e_end);
}

#[test]
fn observer_sees_exact_step_times_and_can_stop() {
    let (t0, h) = (1e3, 0.1);
    let mut seen = 0u64;
    let x0 = Phase { q: [1.0], v: [0.0] };
    let run = symplectic_fixed(Symplectic::Yoshida4, &Forced, t0, x0, h, 100, |t, _| {
        seen += 1;
        // t_i = t0 + i·h computed afresh, bit for bit.
        assert_eq!(t, t0 + seen as f64 * h);
        if seen == 5 {
            Control::Stop
        } else {
            Control::Continue
        }
    });
    assert_eq!(run.t, t0 + 5.0 * h);
    assert_eq!(run.stats.steps, 5);
    assert_eq!(run.stats.rhs_evals, 1 + 3 * 5);
    let zero = symplectic_fixed(Symplectic::Verlet, &Forced, t0, x0, h, 0, |_, _| {
        Control::Continue
    });
    assert_eq!((zero.t, zero.y, zero.stats.rhs_evals), (t0, x0, 0));
}
