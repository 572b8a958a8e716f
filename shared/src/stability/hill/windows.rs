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
//! [`first_window`] does not walk all values: the first window lies between two known ones
//! (a₀ and b₁ below the first tongue, k < 1/4; aⱼ and bⱼ₊₁ above it), and each end is where one
//! of them meets a, found by [`super::follow`] in its own family's block: 2–40 passes over a
//! block of ≈ 15 rows per end instead of hundreds of full counts.

use super::family::{rows_for, Family, Value};
use super::follow::Follower;
use super::{count_below, follow, harmonics, stability_count};
use crate::error::ParamError;
use crate::math;
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
/// `m_max`, with whether its upper end is a flutter (tr M = −2) boundary and the LDLᵀ passes
/// it took.
pub fn first_window(k: f64, m_max: f64, tol: f64) -> Result<(Window, bool, u64), ParamError> {
    let k = check_k(k)?;
    let tol = check_tol(tol)?;
    if !(m_max.is_finite() && m_max > 0.0) {
        return Err(ParamError {
            name: "m_max",
            value: m_max,
            allowed: "a positive number",
        });
    }
    let q_end = 2.0 * m_max.min(M_MAX);
    if k < 0.25 {
        return Ok(below_first_tongue(4.0 * k, q_end, 2.0 * tol));
    }
    Ok(between_tongues(4.0 * k, q_end, 2.0 * tol))
}

fn window(lower: End, upper: End) -> Window {
    Window {
        lower,
        upper,
        note: None,
    }
}

/// a < 1 (k < 1/4): the window (a₀, b₁). Both decrease in q (McLachlan §2.2; checked against
/// the walk in the tests), so each end is the one change of its family's count on [0, q_end]:
/// Newton in q from the large-q asymptote a₀ ≈ b₁ ≈ −2q + 2√q − 1/4 (A&S 20.2.30), or from the
/// small-q series a₀ ≈ −q²/2, b₁ ≈ 1 − q − q²/8 (A&S 20.2.25) where that is nearer.
fn below_first_tongue(a: f64, q_end: f64, tol_q: f64) -> (Window, bool, u64) {
    let mut passes = 0u64;
    let crosses = |fam: Family, passes: &mut u64| {
        *passes += 1;
        fam.count(q_end, a, rows_for(a, q_end)) > 0
    };
    // −2q + 2√q − 1/4 = a  ⇔  √q = (1 + √(1/2 − 2a))/2.
    let asymptote = {
        let s = 0.5 * (1.0 + math::sqrt((0.5 - 2.0 * a).max(0.0)));
        s * s
    };
    let lower = if a >= 0.0 {
        Some(0.0)
    } else if crosses(Family::EvenCos, &mut passes) {
        let series = math::sqrt(-2.0 * a);
        let guess = if series < 1.0 { series } else { asymptote };
        Some(follow::root_in(
            Family::EvenCos,
            a,
            (0.0, q_end),
            0,
            guess,
            tol_q,
            &mut passes,
        ))
    } else {
        None
    };
    let Some(lower) = lower else {
        let none = window(End::Missing(NEVER_STABLE), End::Missing(NEVER_STABLE));
        return (none, false, passes);
    };
    if !crosses(Family::OddSin, &mut passes) {
        return (
            window(End::Value(0.5 * lower), End::Missing(STABLE_TO_LIMIT)),
            false,
            passes,
        );
    }
    // b₁ > a₀, so b₁ meets a above a₀'s crossing (a bracket end, unless the window is
    // narrower than the tolerance).
    passes += 1;
    let lo = if Family::OddSin.count(lower, a, rows_for(a, lower)) == 0 {
        lower
    } else {
        0.0
    };
    // q²/8 + q = 1 − a on the series.
    let series = 4.0 * (math::sqrt(1.0 + 0.5 * (1.0 - a)) - 1.0);
    let guess = if a > -1.0 { series } else { asymptote.max(lo) };
    let upper = follow::root_in(Family::OddSin, a, (lo, q_end), 0, guess, tol_q, &mut passes);
    (
        window(End::Value(0.5 * lower), End::Value(0.5 * upper)),
        true,
        passes,
    )
}

/// a ≥ 1 (k ≥ 1/4): the window starts at m = 0 between aⱼ and bⱼ₊₁ (j = ⌊√a⌋; the values
/// interlace a₀ < b₁ < a₁ < b₂ < … for q > 0, so no other value can reach a first) and ends
/// where aⱼ rising or bⱼ₊₁ falling first meets a, each followed from q = 0.
///
/// At a tongue tip a = j²: for j = 1, 2 the pair splits across a at once (b₁ = 1 − q,
/// a₁ = 1 + q; b₂ = 4 − q²/12, a₂ = 4 + 5q²/12), so the window has zero width; for j ≥ 3 both
/// rise (aⱼ, bⱼ = j² + q²/(2(j² − 1)) + O(q³); A&S 20.2.25), so the window lies between aⱼ₋₁ and
/// bⱼ, and bⱼ is followed from q = 0.1, where the series' q² term outweighs the rest by ≥ 40
/// (b₃ = 9 + q²/16 − q³/64 + …, b₄ = 16 + q²/30 − 317q⁴/864000 + …).
fn between_tongues(a: f64, q_end: f64, tol_q: f64) -> (Window, bool, u64) {
    let mut j = math::sqrt(a) as u32;
    while f64::from(j + 1) * f64::from(j + 1) <= a {
        j += 1;
    }
    while f64::from(j) * f64::from(j) > a {
        j -= 1;
    }
    let tip = f64::from(j * j) == a;
    if tip && j <= 2 {
        return (window(End::Value(0.0), End::Value(0.0)), j == 1, 0);
    }
    let (below, above, q_above) = if tip {
        (Value::a(j - 1), Value::b(j), 0.1)
    } else {
        (Value::a(j), Value::b(j + 1), 0.0)
    };
    // Both walks advance together, the one behind first, so that neither goes past the
    // other's crossing.
    let mut rising = Follower::new(below, a, 0.0, tol_q);
    let mut falling = Follower::new(above, a, q_above, tol_q);
    for _ in 0..200_000 {
        let limit = [rising.crossing, falling.crossing]
            .into_iter()
            .flatten()
            .fold(q_end, f64::min);
        let (behind, ahead) = if rising.q <= falling.q {
            (&mut rising, &mut falling)
        } else {
            (&mut falling, &mut rising)
        };
        let moved = behind.step(limit) || ahead.step(limit);
        if !moved {
            break;
        }
    }
    let passes = rising.passes + falling.passes;
    let (end, by) = match (rising.crossing, falling.crossing) {
        (Some(r), Some(f)) if f < r => (f, above),
        (Some(r), _) => (r, below),
        (None, Some(f)) => (f, above),
        (None, None) => {
            let w = window(End::Value(0.0), End::Missing(STABLE_TO_LIMIT));
            return (w, false, passes);
        }
    };
    (
        window(End::Value(0.0), End::Value(0.5 * end)),
        by.is_odd(),
        passes,
    )
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
