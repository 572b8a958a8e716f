//! Runge–Kutta–Nyström steps for θ'' = g(t, θ) − c θ': the pendulum's equation, second order,
//! whose only first-derivative term is linear damping.
//!
//! A Nyström method integrates y'' = g(t, y) directly: it needs no stages for y' = v, and the
//! 8(6) pair of Dormand, El-Mikkawy & Prince ([`tableau`]) reaches order 8 with eight
//! evaluations per step (nine stages, the last shared with the next step), where DOP853 needs
//! twelve. It is not symplectic: the long energy runs keep their symplectic methods.
//!
//! # Damping without losing order
//!
//! A Nyström method may not see θ'. Over one step from t0, change the independent variable:
//!
//! ```text
//! s = (1 − e^(−cτ))/c,   τ = t − t0,   so  ds/dτ = e^(−cτ) = 1 − c s,   τ(s) = −ln(1 − c s)/c
//! u(s) = θ(t0 + τ(s)):   θ' = (1 − c s) u_s
//!                         θ'' = (1 − c s)² u_ss − c (1 − c s) u_s = (1 − c s)² u_ss − c θ'
//! θ'' + c θ' = g   ⇔   u_ss = (1 − c s)^(−2) g(t0 + τ(s), u)          (exact)
//! ```
//! A step of H in t is a step of S = (1 − e^(−cH))/c in s, from u = θ0, u_s = θ0'; at its end
//! θ1 = u(S) and θ1' = e^(−cH) u_s(S). The transformed equation is smooth and free of u_s, so
//! the method keeps its full order (tested on a damped, forced oscillator with a closed form).
//! For a fixed H the stage times τ_i = τ(c_i S) and factors (1 − c c_i S)^(−2) = e^(2cτ_i) are
//! the same every step: they are computed once, and damping costs nothing per evaluation.
//! (c → 0 gives s = τ and the plain method; expm1 and log1p keep small cH exact.)

pub mod adaptive;
pub mod tableau;

#[cfg(test)]
mod order_conditions;

use crate::Real;
use tableau::{A, B, B6, BBAR, BBAR6, C, STAGES};

/// Steps of one size H for a given damping c: the stage times and weights of the change of
/// variable above.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedRkn {
    /// Step in t.
    pub h: f64,
    /// Step in s.
    s: f64,
    /// Stage times τ_i after the step's start.
    pub tau: [f64; STAGES],
    /// (1 − c c_i S)^(−2), multiplying g at stage i.
    weight: [f64; STAGES],
    /// e^(−cH): turns u_s(S) into θ'.
    decay: f64,
}

/// The end of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RknStep<R> {
    pub theta: R,
    pub rate: R,
    /// g(t0 + H, θ1), the first stage of the next step.
    pub g1: R,
    /// The embedded order-6 solution's distance from the order-8 one: (Δθ, Δθ').
    pub error: (R, R),
}

impl DampedRkn {
    /// Steps of size `h` with damping `c` ≥ 0.
    pub fn new(h: f64, c: f64) -> Self {
        Self::build(h, c, true)
    }

    /// The same for a g that does not depend on t: the stage times (one log1p each) are left
    /// out and [`DampedRkn::tau`] is NaN. What an adaptive run of an autonomous equation,
    /// building a new step size every step, wants.
    pub fn autonomous(h: f64, c: f64) -> Self {
        Self::build(h, c, false)
    }

    fn build(h: f64, c: f64, times: bool) -> Self {
        let ch = c * h;
        // S = (1 − e^(−cH))/c; τ(s) = −ln(1 − c s)/c; e^(−cH) = 1 − c S.
        let expm1 = libm::expm1(-ch);
        let s = if c > 0.0 { -expm1 / c } else { h };
        let mut tau = [f64::NAN; STAGES];
        let mut weight = [1.0; STAGES];
        for i in 0..STAGES {
            let x = c * C[i] * s;
            if c > 0.0 {
                weight[i] = 1.0 / ((1.0 - x) * (1.0 - x));
            }
            if times {
                tau[i] = if c > 0.0 {
                    -libm::log1p(-x) / c
                } else {
                    C[i] * h
                };
            }
        }
        Self {
            h,
            s,
            tau,
            weight,
            decay: 1.0 + expm1,
        }
    }

    /// One step from (θ, θ') with g0 = g(t0, θ) known. `g(i, θ)` evaluates g at t0 + τ_i for
    /// stages i = 1..8 (eight evaluations; stage 8 is at the step's end, θ1).
    #[inline(always)]
    pub fn step<R: Real>(
        &self,
        theta: R,
        rate: R,
        g0: R,
        mut g: impl FnMut(usize, R) -> R,
    ) -> RknStep<R> {
        let s = R::from_f64(self.s);
        let s2 = R::from_f64(self.s * self.s);
        // k[i]: the transformed acceleration at stage i.
        let mut k = [R::ZERO; STAGES];
        k[0] = g0;
        let mut raw_last = g0;
        for i in 1..STAGES {
            let mut acc = R::ZERO;
            for j in 0..i {
                acc += R::from_f64(A[i][j]) * k[j];
            }
            let y = theta + R::from_f64(C[i]) * s * rate + s2 * acc;
            raw_last = g(i, y);
            k[i] = R::from_f64(self.weight[i]) * raw_last;
        }
        let (mut p8, mut v8, mut p6, mut v6) = (R::ZERO, R::ZERO, R::ZERO, R::ZERO);
        for i in 0..STAGES {
            p8 += R::from_f64(BBAR[i]) * k[i];
            v8 += R::from_f64(B[i]) * k[i];
            p6 += R::from_f64(BBAR6[i]) * k[i];
            v6 += R::from_f64(B6[i]) * k[i];
        }
        let decay = R::from_f64(self.decay);
        RknStep {
            theta: theta + s * rate + s2 * p8,
            rate: decay * (rate + s * v8),
            g1: raw_last,
            error: (s2 * (p8 - p6), decay * s * (v8 - v6)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// θ'' + c θ' + k θ = F cos(Ω t) from (θ0, θ0'): the closed form (particular solution
    /// X cos Ωt + Y sin Ωt, X = F(k − Ω²)/D, Y = F c Ω/D, D = (k − Ω²)² + (cΩ)², plus the
    /// damped free oscillation that meets the start), and the RKN run with n steps.
    fn forced(c: f64, n: u32) -> f64 {
        let (k, f, w, t_end): (f64, f64, f64, f64) = (4.0, 1.3, 3.0, 4.0);
        let (th0, v0) = (0.5, -0.2);
        let d = (k - w * w).powi(2) + (c * w).powi(2);
        let (x, y) = (f * (k - w * w) / d, f * c * w / d);
        let (sig, wd) = (-0.5 * c, (k - 0.25 * c * c).sqrt());
        // Free part e^(σt)(P cos ωd t + Q sin ωd t) with P = θ0 − X, σP + ωd Q = θ0' − YΩ.
        let p = th0 - x;
        let q = (v0 - y * w - sig * p) / wd;
        let exact = |t: f64| {
            (sig * t).exp() * (p * (wd * t).cos() + q * (wd * t).sin())
                + x * (w * t).cos()
                + y * (w * t).sin()
        };
        let h = t_end / f64::from(n);
        let m = DampedRkn::new(h, c);
        let g = |t: f64, th: f64| -k * th + f * (w * t).cos();
        let (mut th, mut v, mut g0) = (th0, v0, g(0.0, th0));
        for step in 0..n {
            let t0 = f64::from(step) * h;
            let out = m.step(th, v, g0, |i, y| g(t0 + m.tau[i], y));
            (th, v, g0) = (out.theta, out.rate, out.g1);
        }
        (th - exact(t_end)).abs()
    }

    #[test]
    fn order_8_with_and_without_damping() {
        // Halving the step divides the error by 2^8 = 256 for an order-8 method. Measured
        // ratios (n = 16 → 32) are checked to lie in [2^7.5, 2^8.7]: the order, not a
        // constant. The damped run proves the change of variable keeps the order.
        for c in [0.0, 0.7, 3.0] {
            let (e1, e2) = (forced(c, 16), forced(c, 32));
            let order = (e1 / e2).log2();
            assert!(
                (7.5..8.7).contains(&order),
                "c = {c}: {e1:e} → {e2:e}, order {order}"
            );
        }
    }

    #[test]
    fn undamped_weights_are_the_plain_method() {
        let m = DampedRkn::new(0.1, 0.0);
        assert_eq!(m.tau, C.map(|c| c * 0.1));
        assert_eq!(m.decay, 1.0);
    }
}
