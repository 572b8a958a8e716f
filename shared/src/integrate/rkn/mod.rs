//! Runge–Kutta–Nyström steps for θ'' = g(t, θ) − c θ': the pendulum's equation, second order,
//! whose only first-derivative term is linear damping.
//!
//! A Nyström method integrates y'' = g(t, y) directly: it needs no stages for y' = v, and the
//! 8(6) pair of Dormand, El-Mikkawy & Prince ([`tableau`]) reaches order 8 with eight
//! evaluations per step (nine stages, the last shared with the next step), where DOP853 needs
//! twelve; their 12(10) pair ([`tableau12`]) reaches order 12 with seventeen. Neither is
//! symplectic: the long energy runs keep their symplectic methods.
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
pub mod tableau12;

#[cfg(test)]
mod order_conditions;

use crate::Real;

/// An embedded RKN pair: its table, orders and whether its last stage is the next step's first.
#[derive(Debug, PartialEq)]
pub struct Pair<const S: usize> {
    pub c: [f64; S],
    pub a: [[f64; S]; S],
    /// Position and velocity weights of the higher order.
    pub bbar: [f64; S],
    pub b: [f64; S],
    /// The same of the embedded lower order.
    pub bbar_low: [f64; S],
    pub b_low: [f64; S],
    /// The orders (higher, embedded).
    pub orders: (u32, u32),
    /// The last stage is g at the step's end (first same as last).
    pub fsal: bool,
    /// For each stage, the latest earlier stage its row uses: the one whose g it waits for.
    pub waits_for: [usize; S],
}

/// The latest j < i with a_ij ≠ 0, for every row i (0 for the first two). A stage that skips
/// its predecessor can start before that predecessor's g is known.
const fn waits_for<const S: usize>(a: &[[f64; S]; S]) -> [usize; S] {
    let mut out = [0; S];
    let mut i = 1;
    while i < S {
        let mut j = i - 1;
        while j > 0 && a[i][j] == 0.0 {
            j -= 1;
        }
        out[i] = j;
        i += 1;
    }
    out
}

/// Dormand, El-Mikkawy & Prince 8(6), nine stages, FSAL ([`tableau`]).
pub const RKN86: Pair<{ tableau::STAGES }> = Pair {
    c: tableau::C,
    a: tableau::A,
    bbar: tableau::BBAR,
    b: tableau::B,
    bbar_low: tableau::BBAR6,
    b_low: tableau::B6,
    orders: (8, 6),
    fsal: true,
    waits_for: waits_for(&tableau::A),
};

/// Dormand, El-Mikkawy & Prince 12(10), seventeen stages ([`tableau12`]).
pub const RKN1210: Pair<{ tableau12::STAGES }> = Pair {
    c: tableau12::C,
    a: tableau12::A,
    bbar: tableau12::BBAR,
    b: tableau12::B,
    bbar_low: tableau12::BBAR10,
    b_low: tableau12::B10,
    orders: (12, 10),
    fsal: false,
    waits_for: waits_for(&tableau12::A),
};

/// Steps of one size H of a pair for a given damping c: the stage times and weights of the
/// change of variable above.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Damped<const S: usize> {
    pair: &'static Pair<S>,
    /// Step in t.
    pub h: f64,
    /// Step in s.
    s: f64,
    /// Stage times τ_i after the step's start.
    pub tau: [f64; S],
    /// (1 − c c_i S)^(−2), multiplying g at stage i.
    weight: [f64; S],
    /// e^(−cH): turns u_s(S) into θ'.
    decay: f64,
}

/// RKN 8(6) steps: what the whole-steps-per-period runs use.
pub type DampedRkn = Damped<{ tableau::STAGES }>;

/// The end of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RknStep<R> {
    pub theta: R,
    pub rate: R,
    /// g(t0 + H, θ1), the first stage of the next step, for a first-same-as-last pair (NaN for
    /// the others, whose caller evaluates it).
    pub g1: R,
    /// The embedded solution's distance from the higher-order one: (Δθ, Δθ').
    pub error: (R, R),
}

impl DampedRkn {
    /// RKN 8(6) steps of size `h` with damping `c` ≥ 0.
    pub fn new(h: f64, c: f64) -> Self {
        Self::of(&RKN86, h, c, true)
    }
}

impl<const S: usize> Damped<S> {
    /// Steps of `pair` of size `h` with damping `c` ≥ 0. Without `times` the stage times (one
    /// log1p each) are left out and [`Damped::tau`] is NaN: what an adaptive run of an
    /// autonomous equation, building a new step size every step, wants.
    #[inline(always)]
    pub fn of(pair: &'static Pair<S>, h: f64, c: f64, times: bool) -> Self {
        let ch = c * h;
        // S = (1 − e^(−cH))/c; τ(s) = −ln(1 − c s)/c; e^(−cH) = 1 − c S. 1/c does not wait
        // for the step size.
        let expm1 = crate::math::expm1(-ch);
        let s = if c > 0.0 { -expm1 * (1.0 / c) } else { h };
        let mut tau = [f64::NAN; S];
        let mut weight = [1.0; S];
        if c > 0.0 {
            // Branch-free, so that the divisions pair up in vector registers.
            for (w, &ci) in weight.iter_mut().zip(&pair.c) {
                let e = 1.0 - c * ci * s;
                *w = 1.0 / (e * e);
            }
        }
        if times {
            for (t, &ci) in tau.iter_mut().zip(&pair.c) {
                *t = if c > 0.0 {
                    -libm::log1p(-(c * ci * s)) / c
                } else {
                    ci * h
                };
            }
        }
        Self {
            pair,
            h,
            s,
            tau,
            weight,
            decay: 1.0 + expm1,
        }
    }

    /// One step from (θ, θ') with g0 = g(t0, θ) known. `g(i, θ)` evaluates g at t0 + τ_i for
    /// stages i = 1..S (S − 1 evaluations; for a first-same-as-last pair the last is at θ1).
    #[inline(always)]
    pub fn step<R: Real>(
        &self,
        theta: R,
        rate: R,
        g0: R,
        mut g: impl FnMut(usize, R) -> R,
    ) -> RknStep<R> {
        self.step_from(theta, rate, g0, |i, th, _, (f, e)| {
            let gi = g(i, th);
            (gi, e + f * gi)
        })
    }

    /// [`Damped::step`] with g also handed each stage's offset δ = θ_i − θ from the step's
    /// start, computed without the rounding of θ_i − θ, and the next stage's offset in two
    /// parts (f, e) such that δ_{i+1} = e + f g_i: `g(i, θ_i, δ_i, (f, e))` returns
    /// (g_i, e + f g_i), and may form the second without waiting for the first ((0, 0) where
    /// the next stage does not use g_i).
    ///
    /// Every stage waits for an earlier one's g, so the arithmetic between two evaluations is
    /// the step's latency. The offset is
    /// δ_{i+1} = ((c_{i+1} S θ' + S² Σ_{j<i−1} a_{i+1,j} w_j g_j) + S² a_{i+1,i−1} w_{i−1} g_{i−1}) + S² a_{i+1,i} w_i g_i
    /// (w_j: the damping weights; w_0 = 1, known without a division): all but the last term
    /// is ready before g_i is. A row that skips its predecessor ([`Pair::waits_for`]) does
    /// not wait for it.
    #[inline(always)]
    pub fn step_from<R: Real>(
        &self,
        theta: R,
        rate: R,
        g0: R,
        mut g: impl FnMut(usize, R, R, (R, R)) -> (R, R),
    ) -> RknStep<R> {
        let p = self.pair;
        let s = R::from_f64(self.s);
        let s2 = R::from_f64(self.s * self.s);
        // c_0 = 0 (an explicit pair's first stage is its start): w_0 = 1.
        let weight = |i: usize| if i == 0 { 1.0 } else { self.weight[i] };
        // S² a_ij w_j, the factor of g_j in stage i's offset.
        let factor = |i: usize, j: usize| s2 * R::from_f64(p.a[i][j] * weight(j));
        // k[j] = w_j g_j: the transformed acceleration at stage j.
        let mut k = [R::ZERO; S];
        k[0] = R::from_f64(weight(0)) * g0;
        // c_i S θ' + S² Σ_{j<n} a_ij w_j g_j.
        let early = |i: usize, n: usize, k: &[R; S]| {
            R::from_f64(p.c[i]) * s * rate + s2 * dot(&p.a[i][..n], &k[..n])
        };
        let mut prev = g0;
        let mut d = early(1, 0, &k) + factor(1, 0) * g0;
        for i in 1..S {
            // Stage i + 1's offset as e + f g_i when it waits for g_i.
            let n = i + 1;
            let waits = n < S && p.waits_for[n] == i;
            let next = if waits {
                (factor(n, i), early(n, i - 1, &k) + factor(n, i - 1) * prev)
            } else {
                (R::ZERO, R::ZERO)
            };
            let (raw, d_next) = g(i, theta + d, d, next);
            k[i] = R::from_f64(weight(i)) * raw;
            prev = raw;
            if n < S {
                d = if waits {
                    d_next
                } else {
                    let m = p.waits_for[n];
                    early(n, m + 1, &k)
                };
            }
        }
        let (ph, vh) = (dot(&p.bbar, &k), dot(&p.b, &k));
        let (pl, vl) = (dot(&p.bbar_low, &k), dot(&p.b_low, &k));
        let decay = R::from_f64(self.decay);
        RknStep {
            theta: theta + s * rate + s2 * ph,
            rate: decay * (rate + s * vh),
            g1: if p.fsal { prev } else { R::from_f64(f64::NAN) },
            error: (s2 * (ph - pl), decay * s * (vh - vl)),
        }
    }
}

/// Σ a_j k_j in four interleaved partial sums: one running sum would chain every addition.
#[inline(always)]
fn dot<R: Real>(a: &[f64], k: &[R]) -> R {
    let (mut s0, mut s1, mut s2, mut s3) = (R::ZERO, R::ZERO, R::ZERO, R::ZERO);
    let (a4, k4) = (a.chunks_exact(4), k.chunks_exact(4));
    let (ar, kr) = (a4.remainder(), k4.remainder());
    for (a, k) in a4.zip(k4) {
        s0 += R::from_f64(a[0]) * k[0];
        s1 += R::from_f64(a[1]) * k[1];
        s2 += R::from_f64(a[2]) * k[2];
        s3 += R::from_f64(a[3]) * k[3];
    }
    for (&a, &k) in ar.iter().zip(kr) {
        s0 += R::from_f64(a) * k;
    }
    (s0 + s1) + (s2 + s3)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// θ'' + c θ' + k θ = F cos(Ω t) from (θ0, θ0'): the closed form (particular solution
    /// X cos Ωt + Y sin Ωt, X = F(k − Ω²)/D, Y = F c Ω/D, D = (k − Ω²)² + (cΩ)², plus the
    /// damped free oscillation that meets the start), and the RKN run with n steps.
    fn forced<const S: usize>(pair: &'static Pair<S>, c: f64, n: u32) -> f64 {
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
        let m = Damped::of(pair, h, c, true);
        let g = |t: f64, th: f64| -k * th + f * (w * t).cos();
        let (mut th, mut v, mut g0) = (th0, v0, g(0.0, th0));
        for step in 0..n {
            let t0 = f64::from(step) * h;
            let out = m.step(th, v, g0, |i, y| g(t0 + m.tau[i], y));
            (th, v) = (out.theta, out.rate);
            g0 = if pair.fsal { out.g1 } else { g(t0 + h, th) };
        }
        (th - exact(t_end)).abs()
    }

    #[test]
    fn order_8_with_and_without_damping() {
        // Halving the step divides the error by 2^8 = 256 for an order-8 method. Measured
        // ratios (n = 16 → 32) are checked to lie in [2^7.5, 2^8.7]: the order, not a
        // constant. The damped run proves the change of variable keeps the order.
        for c in [0.0, 0.7, 3.0] {
            let (e1, e2) = (forced(&RKN86, c, 16), forced(&RKN86, c, 32));
            let order = (e1 / e2).log2();
            assert!(
                (7.5..8.7).contains(&order),
                "c = {c}: {e1:e} → {e2:e}, order {order}"
            );
        }
    }

    /// θ'' = −10 sin θ − c θ' from (2.5, 0) over a time h in n steps of `pair`: a large swing,
    /// so every elementary differential (not only the linear ones) enters the error.
    fn swing<const S: usize>(pair: &'static Pair<S>, c: f64, h: f64, n: u32) -> (f64, f64) {
        let m = Damped::of(pair, h / f64::from(n), c, true);
        let g = |th: f64| -10.0 * th.sin();
        let (mut th, mut v, mut g0) = (2.5, 0.0, g(2.5));
        for _ in 0..n {
            let out = m.step(th, v, g0, |_, y| g(y));
            (th, v) = (out.theta, out.rate);
            g0 = if pair.fsal { out.g1 } else { g(th) };
        }
        (th, v)
    }

    #[test]
    fn order_12_with_and_without_damping() {
        // One step's error is O(h^13) for an order-12 method. Reference: 32 steps of the same
        // pair over the same h (their own error is 32^12 times smaller, below rounding). On a
        // large nonlinear swing, so that every elementary differential enters. From h = 0.6 to
        // 0.2 (errors 1e-7 → 1e-14, above rounding; the error constants change sign between,
        // so nearer steps give erratic ratios) the measured order log(e1/e2)/log 3 must be at
        // least 13 − 0.7, in θ and in θ', with damping as without: the change of variable
        // loses no order. (Measured 12.6–15: the order conditions' test is the exact check of
        // the table; this one is about the damping. Stronger damping, cH ≳ 1, moves the
        // transformed equation's singularity at s = 1/c close to the step, and steps short
        // enough for the asymptotic regime there have errors at rounding.)
        for c in [0.0, 0.7, 1.5] {
            let err = |h: f64| {
                let (one, many) = (swing(&RKN1210, c, h, 1), swing(&RKN1210, c, h, 32));
                ((one.0 - many.0).abs(), (one.1 - many.1).abs())
            };
            let (e1, e2) = (err(0.6), err(0.2));
            for (a, b) in [(e1.0, e2.0), (e1.1, e2.1)] {
                let order = (a / b).ln() / 3.0f64.ln();
                assert!(order > 12.3, "c = {c}: {a:e} → {b:e}, order {order}");
            }
        }
    }

    #[test]
    fn every_pair_starts_at_the_step_start() {
        // Damped::step_from takes w_0 = 1 without looking: c_0 = 0 makes it so.
        assert_eq!(RKN86.c[0], 0.0);
        assert_eq!(RKN1210.c[0], 0.0);
    }

    #[test]
    fn undamped_weights_are_the_plain_method() {
        let m = DampedRkn::new(0.1, 0.0);
        assert_eq!(m.tau, tableau::C.map(|c| c * 0.1));
        assert_eq!(m.decay, 1.0);
    }
}
