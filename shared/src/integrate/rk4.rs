//! The classical fourth-order Runge–Kutta method with a fixed step.

use super::fixed::{self, Control};
use super::{Solution, Stats, System};
use crate::Real;

/// One RK4 step of size `h` from (t, y); four right-hand-side evaluations.
pub fn rk4_step<S: System<N, R>, R: Real, const N: usize>(
    sys: &S,
    t: f64,
    y: &[R; N],
    h: f64,
    stats: &mut Stats,
) -> [R; N] {
    let mut k1 = [R::ZERO; N];
    let mut k2 = [R::ZERO; N];
    let mut k3 = [R::ZERO; N];
    let mut k4 = [R::ZERO; N];
    let mut tmp = [R::ZERO; N];
    let (hr, half, sixth) = (R::from_f64(h), R::from_f64(0.5 * h), R::from_f64(h / 6.0));
    let two = R::from_f64(2.0);
    sys.rhs(t, y, &mut k1);
    for i in 0..N {
        tmp[i] = y[i] + half * k1[i];
    }
    sys.rhs(t + 0.5 * h, &tmp, &mut k2);
    for i in 0..N {
        tmp[i] = y[i] + half * k2[i];
    }
    sys.rhs(t + 0.5 * h, &tmp, &mut k3);
    for i in 0..N {
        tmp[i] = y[i] + hr * k3[i];
    }
    sys.rhs(t + h, &tmp, &mut k4);
    let mut out = [R::ZERO; N];
    for i in 0..N {
        out[i] = y[i] + sixth * (k1[i] + two * k2[i] + two * k3[i] + k4[i]);
    }
    stats.steps += 1;
    stats.rhs_evals += 4;
    out
}

/// Integrates from `t0` to `t1` in `n` equal steps. Step times are `t0 + i·h`, computed afresh
/// each step rather than accumulated, so rounding does not build up over long runs.
pub fn rk4_fixed<S: System<N, R>, R: Real, const N: usize>(
    sys: &S,
    t0: f64,
    y0: [R; N],
    t1: f64,
    n: u32,
    stats: &mut Stats,
) -> [R; N] {
    let n = n.max(1);
    let h = (t1 - t0) / f64::from(n);
    let mut y = y0;
    for i in 0..n {
        let t = t0 + f64::from(i) * h;
        y = rk4_step(sys, t, &y, h, stats);
    }
    y
}

/// Integrates `n` steps of size `h` from (t0, y0), calling `observer(t_i, &y_i)` after every step
/// (t_i = t0 + i·h, computed afresh); the run ends after step n or when the observer returns
/// [`Control::Stop`]. Four right-hand-side evaluations per step.
///
/// ```
/// use kapitza_core::integrate::{rk4_observe, Control, System};
/// struct Decay;
/// impl System<1> for Decay {
///     fn rhs(&self, _t: f64, y: &[f64; 1], dy: &mut [f64; 1]) {
///         dy[0] = -y[0];
///     }
/// }
/// // Stop at the first sample below 1/2: y = e^{−t} crosses it at t = ln 2 ≈ 0.693.
/// let run = rk4_observe(&Decay, 0.0, [1.0], 0.01, 1000, |_t, y| {
///     if y[0] < 0.5 { Control::Stop } else { Control::Continue }
/// });
/// assert!((run.t - 0.70).abs() < 1e-12);
/// assert_eq!(run.stats.steps, 70);
/// assert_eq!(run.stats.rhs_evals, 4 * 70);
/// ```
pub fn rk4_observe<S: System<N, R>, R: Real, const N: usize>(
    sys: &S,
    t0: f64,
    y0: [R; N],
    h: f64,
    n: u64,
    observer: impl FnMut(f64, &[R; N]) -> Control,
) -> Solution<[R; N]> {
    let mut stats = Stats::default();
    let (t, y) = fixed::run(
        t0,
        h,
        n,
        y0,
        |t, _t_next, y| rk4_step(sys, t, y, h, &mut stats),
        observer,
    );
    Solution { t, y, stats }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;

    /// y'' = −y: exact solution cos t.
    struct Oscillator;
    impl System<2> for Oscillator {
        fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    #[test]
    fn fourth_order_convergence() {
        // Closed form: y(2π) = (1, 0). Halving h must cut the error by ≈ 2⁴ = 16 (order 4).
        let err = |n| {
            let mut s = Stats::default();
            let y = rk4_fixed(&Oscillator, 0.0, [1.0, 0.0], math::TAU, n, &mut s);
            assert_eq!(s.rhs_evals, 4 * u64::from(n));
            ((y[0] - 1.0).powi(2) + y[1].powi(2)).sqrt()
        };
        let ratio = err(64) / err(128);
        assert!((14.0..18.0).contains(&ratio), "ratio {ratio}");
    }
}
