//! RK4 with the fixed-step observer driver: measured order against closed forms, exact step
//! times, stopping.

use kapitza_core::integrate::{rk4_observe, Control, System};
use kapitza_core::math;

/// y'' = −y: (cos t, −sin t) from (1, 0).
struct Oscillator;
impl System<2> for Oscillator {
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = y[1];
        dy[1] = -y[0];
    }
}

/// θ'' = −sin θ.
struct Pendulum;
impl System<2> for Pendulum {
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = y[1];
        dy[1] = -math::sin(y[0]);
    }
}

/// K(k) = π / (2 AGM(1, √(1 − k²))) (DLMF 19.8.5), a fixed number of AGM rounds.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0, math::sqrt(1.0 - k * k));
    for _ in 0..8 {
        (a, b) = (0.5 * (a + b), math::sqrt(a * b));
    }
    math::PI / (2.0 * a)
}

fn rk4_error<S: System<2>>(sys: &S, y0: [f64; 2], t1: f64, n: u64, exact: [f64; 2]) -> f64 {
    let run = rk4_observe(sys, 0.0, y0, t1 / n as f64, n, |_, _| Control::Continue);
    assert_eq!(run.stats.rhs_evals, 4 * n);
    assert_eq!(run.t, t1);
    (run.y[0] - exact[0]).abs().max((run.y[1] - exact[1]).abs())
}

#[test]
fn rk4_order_is_four() {
    // Oscillator over [0, 10] (closed form) and the pendulum from θ0 = 2 over one period
    // 4 K(sin 1) (back to (2, 0)). Halving h divides the error by ≈ 2⁴.
    let osc = |n| {
        rk4_error(
            &Oscillator,
            [1.0, 0.0],
            10.0,
            n,
            [math::cos(10.0), -math::sin(10.0)],
        )
    };
    let t_pend = 4.0 * elliptic_k(math::sin(1.0));
    let pend = |n| rk4_error(&Pendulum, [2.0, 0.0], t_pend, n, [2.0, 0.0]);
    for (name, e1, e2) in [
        ("oscillator", osc(100), osc(200)),
        ("pendulum", pend(400), pend(800)),
    ] {
        let order = (e1 / e2).log2();
        eprintln!("RK4 {name}: {e1:.2e} → {e2:.2e}, order {order:.2}");
        assert!((order - 4.0).abs() < 0.15, "{name}: order {order}");
    }
}

#[test]
fn observer_sees_exact_step_times_and_can_stop() {
    // t = 1e4 + i·0.1: an accumulated clock would drift from t0 + i·h by many ulps here.
    let (t0, h) = (1e4, 0.1);
    let mut seen = 0u64;
    let run = rk4_observe(&Oscillator, t0, [1.0, 0.0], h, 1000, |t, _| {
        seen += 1;
        assert_eq!(t, t0 + seen as f64 * h);
        if seen == 7 {
            Control::Stop
        } else {
            Control::Continue
        }
    });
    assert_eq!(
        (run.t, run.stats.steps, run.stats.rhs_evals),
        (t0 + 0.7, 7, 28)
    );
}
