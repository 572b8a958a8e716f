//! Damped stability through the undamped problem: the shift k' = k − δ²/4 and tr M_u.
//!
//! With x = e^{−δτ/2} u (see [`super`]), the damped verdict needs tr M_u of the undamped
//! equation at (k', m) only where the undamped problem is unstable, and the damped window's ends
//! are where |tr M_u| = 2 cosh(πδ) — not a zero of Hill's determinant, so tr M_u is integrated.
//! The coefficient k' − m cos τ is even in τ, so half a period suffices (Magnus & Winkler,
//! *Hill's Equation*, §1.1): with u₁ (u = 1, u' = 0) and u₂ (u = 0, u' = 1) at τ = 0,
//!
//! ```text
//! M_u = Φ(−π)⁻¹ Φ(π)   ⇒   tr M_u = 2 [u₁(π) u₂'(π) + u₁'(π) u₂(π)]
//! ```
//!
//! integrated with classical RK4 in `half_steps` equal steps (the cosines at the step and
//! half-step points can be tabulated once for many (k, m): [`trace_u_with`]).

use super::windows::{first_window, NEVER_STABLE, STABLE_TO_LIMIT};
use super::{is_stable, stability_count};
use crate::error::ParamError;
use crate::math;
use crate::stability::{check_delta, check_k, check_m, check_tol, End, Window, M_MAX};

/// Default RK4 steps per half period: the same step as 1000 per period (module doc of
/// [`crate::stability::floquet`]: ends converged to ≈ 1e-11).
pub const DEFAULT_HALF_STEPS: u32 = 500;

/// tr M_u of u'' + (k − m cos τ) u = 0, RK4 over [0, π] in `half_steps` steps, with cos τ at
/// τ = j·h/2 given by `cos_at(j)` (j = 0 … 2·half_steps).
pub fn trace_u_with(k: f64, m: f64, half_steps: u32, cos_at: impl Fn(u32) -> f64) -> f64 {
    let n = half_steps.max(1);
    let h = math::PI / f64::from(n);
    // Both solutions at once: (u₁, u₁', u₂, u₂'); u'' = −s u with s = k − m cos τ.
    let mut y = [1.0, 0.0, 0.0, 1.0];
    let f = |s: f64, y: &[f64; 4]| [y[1], -s * y[0], y[3], -s * y[2]];
    for i in 0..n {
        let s0 = k - m * cos_at(2 * i);
        let s1 = k - m * cos_at(2 * i + 1);
        let s2 = k - m * cos_at(2 * i + 2);
        let k1 = f(s0, &y);
        let k2 = f(s1, &core::array::from_fn(|j| y[j] + 0.5 * h * k1[j]));
        let k3 = f(s1, &core::array::from_fn(|j| y[j] + 0.5 * h * k2[j]));
        let k4 = f(s2, &core::array::from_fn(|j| y[j] + h * k3[j]));
        y = core::array::from_fn(|j| y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
    }
    2.0 * (y[0] * y[3] + y[1] * y[2])
}

/// tr M_u at (k, m) with `half_steps` RK4 steps over half a period.
pub fn trace_u(k: f64, m: f64, half_steps: u32) -> Result<f64, ParamError> {
    let (k, m) = (check_k(k)?, check_m(m)?);
    let h = math::PI / f64::from(half_steps.max(1));
    Ok(trace_u_with(k, m, half_steps, |j| {
        math::cos(0.5 * h * f64::from(j))
    }))
}

/// The shifted k' = k − δ²/4 and the bound 2 cosh(πδ) on |tr M_u|.
pub fn shift(k: f64, delta: f64) -> (f64, f64) {
    let e = math::exp(math::PI * delta);
    (k - 0.25 * delta * delta, e + 1.0 / e)
}

/// Whether x'' + δ x' + (k − m cos τ) x = 0 is stable: the undamped count at k' decides where it
/// says stable; elsewhere |tr M_u| < 2 cosh(πδ).
pub fn is_stable_damped(k: f64, delta: f64, m: f64, half_steps: u32) -> Result<bool, ParamError> {
    let (k, delta, m) = (check_k(k)?, check_delta(delta)?, check_m(m)?);
    if delta == 0.0 {
        return is_stable(k, m);
    }
    let (kp, bound) = shift(k, delta);
    let kp = check_k(kp)?;
    if stability_count(4.0 * kp, 2.0 * m) % 2 == 1 {
        return Ok(true);
    }
    Ok(trace_u(kp, m, half_steps)?.abs() < bound)
}

/// A damped first window and what it took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedWindow {
    pub window: Window,
    /// Half-period integrations of tr M_u.
    pub traces: u64,
    /// Sturm counts.
    pub counts: u64,
}

/// The first window in m at (k, δ > 0): it contains the undamped window at k' = k − δ²/4, and
/// each end is found by walking outward from that window's end in growing steps to the first
/// unstable m, then closing in on |tr M_u| = 2 cosh(πδ) by regula falsi (Illinois).
pub fn damped_window(
    k: f64,
    delta: f64,
    tol: f64,
    half_steps: u32,
) -> Result<DampedWindow, ParamError> {
    let (k, delta, tol) = (check_k(k)?, check_delta(delta)?, check_tol(tol)?);
    let (kp, bound) = shift(k, delta);
    let kp = check_k(kp)?;
    let (inner, _, counts) = first_window(kp, M_MAX, tol)?;
    let mut traces = 0u64;
    let mut counts = counts;
    let h = math::PI / f64::from(half_steps.max(1));
    // |tr M_u| − 2 cosh(πδ): negative exactly where the damped problem is stable.
    let mut excess = |m: f64| {
        traces += 1;
        trace_u_with(kp, m, half_steps, |j| math::cos(0.5 * h * f64::from(j))).abs() - bound
    };
    let mut stable = |m: f64| {
        counts += 1;
        stability_count(4.0 * kp, 2.0 * m) % 2 == 1 || excess(m) < 0.0
    };
    let (l0, u0) = match (inner.lower, inner.upper) {
        (End::Value(l), u) => (l, u.value()),
        (End::Missing(_), _) => {
            let missing = Window {
                lower: End::Missing(NEVER_STABLE),
                upper: End::Missing(NEVER_STABLE),
                note: Some("the shifted undamped problem has no window: none searched"),
            };
            return Ok(DampedWindow {
                window: missing,
                traces,
                counts,
            });
        }
    };
    let lower_bracket = if l0 == 0.0 {
        None
    } else {
        outward(&mut stable, l0, -1.0, 0.0)
    };
    let upper_bracket = u0.and_then(|u| outward(&mut stable, u, 1.0, M_MAX));
    let lower = lower_bracket.map_or(0.0, |b| illinois(&mut excess, b, tol));
    let upper = match (u0, upper_bracket) {
        (Some(_), Some(b)) => End::Value(illinois(&mut excess, b, tol)),
        _ => End::Missing(STABLE_TO_LIMIT),
    };
    Ok(DampedWindow {
        window: Window {
            lower: End::Value(lower),
            upper,
            note: None,
        },
        traces,
        counts,
    })
}

/// From a stable `start`, steps in direction `dir` (growing by half each step) to the first
/// unstable m before `limit`: the bracket (last stable, first unstable); `None` if stable all
/// the way.
fn outward(
    stable: &mut impl FnMut(f64) -> bool,
    start: f64,
    dir: f64,
    limit: f64,
) -> Option<(f64, f64)> {
    let mut inside = start;
    let mut h = 1e-4;
    loop {
        let m = inside + dir * h;
        let m = if dir > 0.0 {
            m.min(limit)
        } else {
            m.max(limit)
        };
        if !stable(m) {
            return Some((inside, m));
        }
        if m == limit {
            return None;
        }
        inside = m;
        h *= 1.5;
    }
}

/// The zero of `excess` between a stable `inside` (excess < 0) and an unstable `outside`
/// (excess ≥ 0), to within `tol`: regula falsi with the Illinois modification (the value at a
/// side kept twice is halved, so both sides close in; Dowell & Jarratt, BIT 11, 1971).
fn illinois(excess: &mut impl FnMut(f64) -> f64, (inside, outside): (f64, f64), tol: f64) -> f64 {
    let (mut a, mut b) = (inside, outside);
    let (mut fa, mut fb) = (excess(a), excess(b));
    if !(fa < 0.0 && fb >= 0.0) {
        // The trace disagrees with the verdict that made the bracket (only at rounding level):
        // the bracket's midpoint is as good as any point in it.
        return a + 0.5 * (b - a);
    }
    let mut kept = 0i8;
    for _ in 0..200 {
        if (b - a).abs() <= tol {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        if !(c > lo && c < hi) {
            c = a + 0.5 * (b - a);
            if !(c > lo && c < hi) {
                break;
            }
        }
        let fc = excess(c);
        if fc < 0.0 {
            a = c;
            fa = fc;
            if kept == -1 {
                fb *= 0.5;
            }
            kept = -1;
        } else {
            b = c;
            fb = fc;
            if kept == 1 {
                fa *= 0.5;
            }
            kept = 1;
        }
    }
    a + 0.5 * (b - a)
}
