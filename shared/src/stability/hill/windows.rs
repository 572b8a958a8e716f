//! Stability windows in m at fixed k, undamped, by following characteristic values.
//!
//! At fixed a = 4k, each characteristic value λ(q) is a Lipschitz function of q with constant 2
//! (Weyl's inequality: T(ν, q) changes by an off-diagonal of q's, whose norm is at most 2|Δq|).
//! So if the nearest eigenvalue of T(0, q) or T(1, q) is at distance d from a, none can reach a
//! before q + d/2. [`Windows`] walks q upward in such certified steps, the distance bounded from
//! below by Sturm counts (C(a ± d) = C(a) means no eigenvalue between), extrapolating towards the
//! approaching value and bisecting the count where it changes: every crossing is found, one
//! characteristic value at a time, to within the tolerance. Two things could be stepped over: a
//! tongue inside the extrapolation's look-ahead (at most eight certified steps) *and* past the
//! value being approached, and a tongue narrower than 5e-7 in m where a characteristic value
//! stays within 2e-6 of a (steps never go below 1e-6 in q; that happens only at tongue tips).
//!
//! Below the first tongue (k < 1/4, which includes the inverted position) the first window is
//! (a₀, b₁), and a₀(q), b₁(q) decrease monotonically (McLachlan §2.2; checked against the walk
//! in the tests), so [`first_window`] bisects the counts "C ≥ 1" and "C ≥ 2" directly: about
//! 90 Sturm counts per window.

use super::{count_below, harmonics, stability_count};
use crate::error::ParamError;
use crate::stability::{check_k, check_order, check_tol, End, Window, M_MAX};

/// Reason: no end up to the largest m searched.
pub const STABLE_TO_LIMIT: &str = "stable up to the largest m searched";
/// Reason: never stable up to the largest m searched.
pub const NEVER_STABLE: &str = "not stable for any m up to the largest m searched";
/// Reason: the window does not end at tr M = −2.
pub const NOT_FLUTTER: &str = "the window ends at tr M = +2, not at a period-2 (flutter) boundary";
/// Reason: the exponent does not pass 2/n inside the window.
pub const TRACE_NOT_REACHED: &str = "tr M does not pass 2 cos(2π/n) inside the window";

/// Bisections that sharpen each gap bound (to within 1/8 of the distance).
const GAP_REFINE: u32 = 3;
/// How many certified steps ahead the extrapolation may look.
const LOOK_AHEAD: f64 = 8.0;
/// Smallest step in q of the walk: where a characteristic value stays within 2e-6 of a (a
/// tangency, e.g. a tongue tip at q = 0), certified steps would crawl.
const MIN_STEP_Q: f64 = 1e-6;

/// One change of the count C(4k, 2m) as m grows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// Where (in m), to within the tolerance.
    pub m: f64,
    /// C just below and just above.
    pub before: u32,
    pub after: u32,
    /// Whether a ν = 1 value crossed (tr M = −2: period 2) rather than a ν = 0 one (tr M = +2).
    pub flutter: bool,
}

impl Transition {
    pub fn stable_before(&self) -> bool {
        self.before % 2 == 1
    }
    pub fn stable_after(&self) -> bool {
        self.after % 2 == 1
    }
}

/// The crossings of characteristic values through a = 4k for m from 0 to `m_max`, in order.
pub struct Windows {
    a: f64,
    q: f64,
    q_end: f64,
    tol_q: f64,
    count: u32,
    /// The last certified gap: the next search starts from four times it.
    last_gap: f64,
    /// Sturm counts spent (the work measure).
    pub counts: u64,
}

impl Windows {
    /// Starts at m = 0. `tol` is the tolerance on each crossing in m.
    pub fn new(k: f64, m_max: f64, tol: f64) -> Result<Windows, ParamError> {
        let a = 4.0 * check_k(k)?;
        let tol = check_tol(tol)?;
        if !(m_max.is_finite() && m_max > 0.0 && m_max <= M_MAX) {
            return Err(ParamError {
                name: "m_max",
                value: m_max,
                allowed: "a number in (0, 25]",
            });
        }
        let count = stability_count(a, 0.0);
        Ok(Windows {
            a,
            q: 0.0,
            q_end: 2.0 * m_max,
            tol_q: 2.0 * tol,
            count,
            last_gap: 2.0,
            counts: 1,
        })
    }

    /// Whether m = 0 is stable (C(a, 0) odd).
    pub fn stable_at_start(&self) -> bool {
        self.count % 2 == 1
    }

    fn c(&mut self, q: f64) -> u32 {
        self.counts += 1;
        stability_count(self.a, q)
    }

    /// A lower bound on the distance from a to the nearest characteristic value at q, halving
    /// from four times the last one (at most 8) down to a quarter of the smallest step, then
    /// bisected to within 1/2^[`GAP_REFINE`] of the true distance, so that the extrapolation
    /// in [`Windows::next`] sees how fast the value approaches.
    fn gap(&mut self, q: f64) -> f64 {
        let n = harmonics(self.a + 8.0, q);
        let c = self.count;
        let a = self.a;
        let start = (4.0 * self.last_gap).clamp(MIN_STEP_Q, 8.0);
        let mut side = |sign: f64| {
            // Below a: C(a − d) = C(a) means nothing in [a − d, a); above: C(a + d) = C(a).
            let mut clear = |d: f64| {
                self.counts += 1;
                let x = a + sign * d;
                count_below(0.0, q, x, n) + count_below(1.0, q, x, n) == c
            };
            let mut d = start;
            while d > 0.25 * MIN_STEP_Q {
                if clear(d) {
                    // A value lies within 2d (unless d is the start): close in on it.
                    if d < start {
                        let mut hi = 2.0 * d;
                        for _ in 0..GAP_REFINE {
                            let mid = 0.5 * (d + hi);
                            if clear(mid) {
                                d = mid;
                            } else {
                                hi = mid;
                            }
                        }
                    }
                    return d;
                }
                d *= 0.5;
            }
            0.0
        };
        let below = if c == 0 { 8.0 } else { side(-1.0) };
        let gap = below.min(side(1.0));
        self.last_gap = gap.max(MIN_STEP_Q);
        gap
    }

    /// Bisects the first change of C in (lo, hi], given C(lo) = self.count ≠ C(hi).
    fn crossing(&mut self, mut lo: f64, mut hi: f64) -> (f64, u32) {
        let mut after = self.c(hi);
        while hi - lo > self.tol_q {
            let mid = lo + 0.5 * (hi - lo);
            if mid <= lo || mid >= hi {
                break;
            }
            let c = self.c(mid);
            if c == self.count {
                lo = mid;
            } else {
                hi = mid;
                after = c;
            }
        }
        (hi, after)
    }
}

impl Iterator for Windows {
    type Item = Transition;

    fn next(&mut self) -> Option<Transition> {
        let mut prev: Option<(f64, f64)> = None;
        while self.q < self.q_end {
            let d = self.gap(self.q);
            let safe = (0.5 * d).max(MIN_STEP_Q);
            // Extrapolate the approaching value linearly from the last two gaps and test just
            // beyond its predicted crossing; a change of count there brackets the crossing.
            let mut step = safe;
            if let Some((q0, d0)) = prev {
                let slope = (d0 - d) / (self.q - q0);
                if slope > 0.0 && d > 0.0 {
                    step = step.max((1.05 * d / slope + self.tol_q).min(LOOK_AHEAD * safe));
                }
            }
            let mut hi = (self.q + step).min(self.q_end);
            let mut c_hi = self.c(hi);
            if c_hi == self.count && hi > self.q + safe {
                // The guess found nothing: fall back to the certified step.
                hi = (self.q + safe).min(self.q_end);
                c_hi = self.c(hi);
            }
            if c_hi != self.count {
                let lo = self.q;
                let (q, after) = self.crossing(lo, hi);
                let n = harmonics(self.a, q);
                let flutter = count_below(1.0, q, self.a, n) != count_below(1.0, lo, self.a, n);
                let t = Transition {
                    m: 0.5 * q,
                    before: self.count,
                    after,
                    flutter,
                };
                self.q = q;
                self.count = after;
                return Some(t);
            }
            prev = Some((self.q, d));
            self.q = hi;
        }
        None
    }
}

/// The undamped first window in m at k (the one starting at m = 0 for k ≥ 0), searched up to
/// `m_max`, with whether its upper end is a flutter (tr M = −2) boundary.
pub fn first_window(k: f64, m_max: f64, tol: f64) -> Result<(Window, bool, u64), ParamError> {
    let k = check_k(k)?;
    if k < 0.25 {
        return below_first_tongue(k, m_max, tol);
    }
    let mut w = Windows::new(k, m_max, tol)?;
    // At k ≥ 0 the hanging position is stable without drive (k = 0: marginal, and stable for
    // any small m since a₀(q) < 0): the window starts at m = 0.
    let l = 0.0;
    for t in w.by_ref() {
        if t.stable_before() && !t.stable_after() {
            let win = window(End::Value(l), End::Value(t.m));
            return Ok((win, t.flutter, w.counts));
        }
    }
    let counts = w.counts;
    Ok((
        window(End::Value(l), End::Missing(STABLE_TO_LIMIT)),
        false,
        counts,
    ))
}

fn window(lower: End, upper: End) -> Window {
    Window {
        lower,
        upper,
        note: None,
    }
}

/// k < 1/4 (a < 1): the window (a₀, b₁) by bisecting the monotone counts C ≥ 1 (for k < 0;
/// for k ≥ 0, a₀(q) ≤ 0 ≤ a and the window starts at m = 0) and C ≥ 2.
fn below_first_tongue(k: f64, m_max: f64, tol: f64) -> Result<(Window, bool, u64), ParamError> {
    let tol = check_tol(tol)?;
    let a = 4.0 * k;
    let q_end = 2.0 * m_max.min(M_MAX);
    let mut counts = 0u64;
    let mut first_at_least = |want: u32| -> Option<f64> {
        counts += 1;
        if stability_count(a, q_end) < want {
            return None;
        }
        let (mut lo, mut hi) = (0.0, q_end);
        while hi - lo > 2.0 * tol {
            let mid = lo + 0.5 * (hi - lo);
            if mid <= lo || mid >= hi {
                break;
            }
            counts += 1;
            if stability_count(a, mid) >= want {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Some(0.25 * (lo + hi))
    };
    let lower = if k >= 0.0 {
        Some(0.0)
    } else {
        first_at_least(1)
    };
    let w = match (lower, first_at_least(2)) {
        (None, _) => window(End::Missing(NEVER_STABLE), End::Missing(NEVER_STABLE)),
        (Some(l), None) => window(End::Value(l), End::Missing(STABLE_TO_LIMIT)),
        (Some(l), Some(u)) => window(End::Value(l), End::Value(u)),
    };
    Ok((w, w.upper.value().is_some(), counts))
}

/// The undamped order-n subharmonic threshold in the first window: the m where the
/// characteristic exponent passes ν = 2/n (tr M = 2 cos(2π/n)); n = 2 is the window's upper end
/// when that is a flutter boundary.
pub fn subharmonic_m(k: f64, n: u32, tol: f64) -> Result<End, ParamError> {
    let n = check_order(n)?;
    let (w, flutter, _) = first_window(k, M_MAX, tol)?;
    let (l, u) = match (w.lower, w.upper) {
        (End::Value(l), End::Value(u)) => (l, u),
        (End::Missing(why), _) | (_, End::Missing(why)) => return Ok(End::Missing(why)),
    };
    if n == 2 {
        return Ok(if flutter {
            End::Value(u)
        } else {
            End::Missing(NOT_FLUTTER)
        });
    }
    let nu = 2.0 / f64::from(n);
    let a = 4.0 * k;
    let count = |m: f64| count_below(nu, 2.0 * m, a, harmonics(a, 2.0 * m));
    // Inside the window the exponent moves monotonically between its values at the ends, and
    // the eigenvalue of T(ν) nearest a crosses it once where the exponent equals ν.
    let (c_l, c_u) = (count(l), count(u));
    if c_l == c_u {
        return Ok(End::Missing(TRACE_NOT_REACHED));
    }
    let (mut lo, mut hi) = (l, u);
    while hi - lo > tol {
        let mid = lo + 0.5 * (hi - lo);
        if mid <= lo || mid >= hi {
            break;
        }
        if count(mid) == c_l {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(End::Value(0.5 * (lo + hi)))
}
