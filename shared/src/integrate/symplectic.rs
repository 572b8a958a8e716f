//! Symplectic integrators for undamped second-order systems q'' = a(t, q): Störmer–Verlet and
//! its symmetric compositions of orders 4 and 6.
//!
//! Why: a symplectic method integrates a nearby Hamiltonian system exactly (up to rounding), so
//! its energy error stays bounded and oscillates instead of drifting, for exponentially long
//! times (HNW, *Geometric Numerical Integration*, 2nd ed. 2006, §IX.8). Over 10⁶ drive periods
//! (physics §6) that matters more than the local error: a non-symplectic method such as RK4 lets the
//! energy decay steadily at any step size.
//!
//! # Störmer–Verlet (velocity form, kick–drift–kick)
//!
//! ```text
//! v½   = v_i + (h/2) a(t_i, q_i)
//! q_i+1 = q_i + h v½
//! v_i+1 = v½ + (h/2) a(t_i+1, q_i+1)
//! ```
//! Order 2, symmetric. a(t_i+1, q_i+1) is also the first kick of the next step, so each step
//! costs one force evaluation (plus one at the start). An explicit time dependence is handled by
//! treating t as a coordinate that drifts with q (extended phase space), so the force is
//! evaluated at the time the drift has reached.
//!
//! # Compositions
//!
//! ```text
//! Φ_h = V(w_s h) ∘ … ∘ V(w_1 h),   Σ w = 1,  w symmetric
//! order 4, Yoshida (1990) "triple jump":  w1 = w3 = 1/(2 − 2^{1/3}),  w2 = −2^{1/3}/(2 − 2^{1/3})
//! order 6, Yoshida (1990) solution A, 7 stages:  (w3, w2, w1, w0, w1, w2, w3),
//!          w1 = −1.17767998417887, w2 = 0.235573213359357, w3 = 0.784513610477560,
//!          w0 = 1 − 2(w1 + w2 + w3)
//! ```
//! H. Yoshida, "Construction of higher order symplectic integrators", Phys. Lett. A 150 (1990)
//! 262–268 (the triple jump, and Table 1 for solution A, printed to 15 digits: its order
//! conditions then hold to ~1e-14, below anything a test can see). Each composition step costs one
//! force evaluation per stage: 3 and 7.

use super::fixed::{self, Control};
use super::{Solution, Stats};
use crate::Real;

/// The acceleration of an undamped second-order system q'' = a(t, q).
pub trait Force<const N: usize, R: Real = f64> {
    /// Writes a(t, q) into `a`.
    fn accel(&self, t: f64, q: &[R; N], a: &mut [R; N]);
}

/// Position and velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phase<const N: usize, R: Real = f64> {
    pub q: [R; N],
    pub v: [R; N],
}

/// Which symplectic method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Symplectic {
    /// Störmer–Verlet, order 2, 1 force evaluation per step.
    Verlet,
    /// Yoshida's triple jump, order 4, 3 evaluations per step.
    Yoshida4,
    /// Yoshida's 7-stage solution A, order 6, 7 evaluations per step.
    Yoshida6,
}

/// 2^{1/3}, rounded to f64.
const CBRT2: f64 = 1.259_921_049_894_873_2;
const TJ1: f64 = 1.0 / (2.0 - CBRT2);
const TJ0: f64 = -CBRT2 / (2.0 - CBRT2);
const Y6_1: f64 = -1.177_679_984_178_87;
const Y6_2: f64 = 0.235_573_213_359_357;
const Y6_3: f64 = 0.784_513_610_477_560;
const Y6_0: f64 = 1.0 - 2.0 * (Y6_1 + Y6_2 + Y6_3);

const VERLET: [f64; 1] = [1.0];
const YOSHIDA4: [f64; 3] = [TJ1, TJ0, TJ1];
const YOSHIDA6: [f64; 7] = [Y6_3, Y6_2, Y6_1, Y6_0, Y6_1, Y6_2, Y6_3];

impl Symplectic {
    /// The Verlet sub-step weights w_j (see the module doc).
    pub fn weights(self) -> &'static [f64] {
        match self {
            Self::Verlet => &VERLET,
            Self::Yoshida4 => &YOSHIDA4,
            Self::Yoshida6 => &YOSHIDA6,
        }
    }

    /// The order of accuracy.
    pub const fn order(self) -> u32 {
        match self {
            Self::Verlet => 2,
            Self::Yoshida4 => 4,
            Self::Yoshida6 => 6,
        }
    }
}

/// Integrates q'' = a(t, q) for `n` steps of size `h` from t0 with `method`, calling
/// `observer(t_i, &x_i)` after every step (t_i = t0 + i·h, computed afresh). The run ends after
/// step n or when the observer returns [`Control::Stop`]. `stats.rhs_evals` counts force
/// evaluations: 1 + (stages)·(steps).
///
/// ```
/// use kapitza_core::integrate::{symplectic_fixed, Control, Force, Phase, Symplectic};
/// struct Spring;
/// impl Force<1> for Spring {
///     fn accel(&self, _t: f64, q: &[f64; 1], a: &mut [f64; 1]) {
///         a[0] = -q[0];
///     }
/// }
/// // q = cos t over one period.
/// let x0 = Phase { q: [1.0], v: [0.0] };
/// let h = core::f64::consts::TAU / 100.0;
/// let run = symplectic_fixed(Symplectic::Yoshida4, &Spring, 0.0, x0, h, 100, |_, _| Control::Continue);
/// assert!((run.y.q[0] - 1.0).abs() < 1e-6);
/// assert_eq!(run.stats.rhs_evals, 1 + 3 * 100);
/// ```
pub fn symplectic_fixed<F: Force<N, R>, R: Real, const N: usize>(
    method: Symplectic,
    force: &F,
    t0: f64,
    x0: Phase<N, R>,
    h: f64,
    n: u64,
    observer: impl FnMut(f64, &Phase<N, R>) -> Control,
) -> Solution<Phase<N, R>> {
    let mut stats = Stats::default();
    if n == 0 {
        return Solution {
            t: t0,
            y: x0,
            stats,
        };
    }
    let weights = method.weights();
    // The acceleration at the current (t, q): carried from one step to the next (FSAL).
    let mut acc = [R::ZERO; N];
    force.accel(t0, &x0.q, &mut acc);
    stats.rhs_evals += 1;
    let (t, y) = fixed::run(
        t0,
        h,
        n,
        x0,
        |t, t_next, x| {
            stats.steps += 1;
            stats.rhs_evals += weights.len() as u64;
            compose(force, weights, t, t_next, x, &mut acc)
        },
        observer,
    );
    Solution { t, y, stats }
}

/// One step of the composition from t to t_next: a kick–drift–kick Verlet sub-step of size w·h
/// per weight. `acc` holds a(t, q) on entry and a(t_next, q_next) on exit.
fn compose<F: Force<N, R>, R: Real, const N: usize>(
    force: &F,
    weights: &[f64],
    t: f64,
    t_next: f64,
    x: &Phase<N, R>,
    acc: &mut [R; N],
) -> Phase<N, R> {
    let h = t_next - t;
    let Phase { mut q, mut v } = *x;
    // Fraction of the step the drift has covered; the last sub-step lands exactly on t_next.
    let mut drifted = 0.0;
    for (j, &w) in weights.iter().enumerate() {
        let half_kick = R::from_f64(0.5 * w * h);
        let drift = R::from_f64(w * h);
        for i in 0..N {
            v[i] += half_kick * acc[i];
            q[i] += drift * v[i];
        }
        drifted += w;
        let ts = if j + 1 == weights.len() {
            t_next
        } else {
            t + drifted * h
        };
        force.accel(ts, &q, acc);
        for i in 0..N {
            v[i] += half_kick * acc[i];
        }
    }
    Phase { q, v }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_cancel_the_third_order_term() {
        // A symmetric composition of a symmetric 2nd-order method is of order 4 iff Σ w = 1 and
        // Σ w³ = 0 (Yoshida 1990, eq. 4.4); order 6 also needs Σ w⁵ = 0 (plus one more condition
        // on nested commutators, tested through the measured order in tests/integrate_symplectic).
        for m in [
            Symplectic::Verlet,
            Symplectic::Yoshida4,
            Symplectic::Yoshida6,
        ] {
            let w = m.weights();
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            if m.order() >= 4 {
                assert!(w.iter().map(|w| w * w * w).sum::<f64>().abs() < 1e-13);
            }
            if m.order() >= 6 {
                assert!(w.iter().map(|w| w * w * w * w * w).sum::<f64>().abs() < 1e-13);
            }
        }
    }
}
