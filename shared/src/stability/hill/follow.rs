//! Where one characteristic value λ(q) first meets a fixed a, found with Newton steps that the
//! Sturm counts keep honest.
//!
//! Two searches, both on one family's block ([`super::family`]):
//!
//! * [`root_in`]: a bracket [lo, hi] in q whose block count changes once: Newton steps in q on
//!   det(B(q) − aI), each kept inside the bracket that the count of the same pass narrows
//!   (bisection where a step leaves it or stalls), closed by a last pair of counts tol apart.
//! * [`first_crossing`]: no bracket, only a start where the tracked value is on one side of a.
//!   It walks q upward in steps that provably cannot cross: with f = |λ − a|, f' its slope and
//!   g the distance to the block's other eigenvalues, f(q + t) ≥ f − 2t (|λ'| ≤ 2) and
//!   f(q + t) ≥ f + f't − (K/2)t² with K = 16/g for t ≤ g/8 (|λ''| ≤ 8/g while the distance
//!   is at least g/2), so the larger of the two safe steps is taken. Far from a root the steps
//!   are as long as g/8; near a simple root the quadratic bound makes them Newton steps
//!   (quadratic convergence). Once the slope is steep enough that f is monotone up to twice
//!   the predicted root, a count there brackets exactly one crossing, and [`root_in`] ends it.
//!   Nothing is stepped over except where λ stays within tol of a over an interval (a
//!   tangency), where the walk crawls in steps of tol.

use super::family::{eigenvalue_in, eigenvalue_with_slope, rows_for, Family, Value};
use crate::math;

/// The value of a slightly above its eigenvalue's rounding: the walk's lower bound on f is the
/// computed distance less this many units in the last place of λ.
const ULPS: f64 = 16.0;

/// Allowance for the error of the computed slope dλ/dq (≈ |λ''|·1e-9·|λ|).
const SLOPE_SLACK: f64 = 1e-6;

/// Newton steps in q on det(B(q) − aI) inside the bracket [lo, hi], where the block count at a
/// is `c_lo` at lo and differs at hi; returns the crossing to within `tol_q` (the converged
/// Newton iterate, far closer, where it lies in the final bracket) and adds the passes spent.
pub fn root_in(
    fam: Family,
    a: f64,
    (mut lo, mut hi): (f64, f64),
    c_lo: u32,
    guess: f64,
    tol_q: f64,
    passes: &mut u64,
) -> f64 {
    let mut x = if guess > lo && guess < hi {
        guess
    } else {
        lo + 0.5 * (hi - lo)
    };
    let mut last_step = hi - lo;
    let mut converged = None;
    for _ in 0..300 {
        let p = fam.factor(x, a, rows_for(a, x));
        *passes += 1;
        let below = p.count == c_lo;
        if below {
            lo = x;
        } else {
            hi = x;
        }
        if hi - lo <= tol_q {
            break;
        }
        let step = p.newton_q();
        let mut next = x + step;
        if step.abs() < 0.25 * tol_q && !p.degenerate {
            // Converged: straddle the root so that the next count closes the bracket.
            converged = Some(next);
            next += if below { 0.5 * tol_q } else { -0.5 * tol_q };
        }
        let mid = lo + 0.5 * (hi - lo);
        if !(next > lo && next < hi) || step.abs() > 0.5 * last_step {
            next = mid;
        }
        if next <= lo || next >= hi {
            break;
        }
        last_step = (next - x).abs();
        x = next;
    }
    match converged {
        Some(r) if r >= lo && r <= hi => r,
        _ => lo + 0.5 * (hi - lo),
    }
}

/// The result of a walk: where the tracked value first meets a (to within tol), if before the
/// end, and the passes spent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    pub q: Option<f64>,
    pub passes: u64,
}

/// One walk in progress (see the module doc): the tracked value at the q reached, its slope,
/// and a certified distance to the block's other eigenvalues (valid at `q_gap`, shrinking by at
/// most 4 per unit of q since both move at speed ≤ 2).
pub struct Follower {
    v: Value,
    a: f64,
    tol_q: f64,
    /// +1 if the value is above a (and falls to meet it), −1 if below.
    sign: f64,
    /// The block count at a until the crossing.
    c0: u32,
    /// The q reached: no crossing in [q_start, q].
    pub q: f64,
    lam: f64,
    slope: f64,
    gap: f64,
    q_gap: f64,
    /// Where the value meets a, once found.
    pub crossing: Option<f64>,
    pub passes: u64,
}

impl Follower {
    /// Starts at q_start: at 0 the value is its order squared with slope ±1 (a₁, b₁) or 0; a
    /// positive q_start is computed.
    pub fn new(v: Value, a: f64, q_start: f64, tol_q: f64) -> Follower {
        let (fam, i) = (v.family, v.index);
        let mut passes = 0;
        let (lam, slope) = if q_start == 0.0 {
            let s = match (fam, i) {
                (Family::OddCos, 0) => 1.0,
                (Family::OddSin, 0) => -1.0,
                _ => 0.0,
            };
            (fam.at_zero(i), s)
        } else {
            let (lam, slope, n) = eigenvalue_with_slope(v, q_start);
            passes += n;
            (lam, slope)
        };
        // The distance to the neighbours at q = 0 (diagonal spacing).
        let above = fam.at_zero(i + 1) - fam.at_zero(i);
        let below = if i > 0 {
            fam.at_zero(i) - fam.at_zero(i - 1)
        } else {
            f64::INFINITY
        };
        let is_above = lam > a;
        Follower {
            v,
            a,
            tol_q,
            sign: if is_above { 1.0 } else { -1.0 },
            c0: if is_above { i } else { i + 1 },
            q: q_start,
            lam,
            slope,
            gap: above.min(below),
            q_gap: 0.0,
            crossing: None,
            passes,
        }
    }

    /// One certified step, not beyond `q_end`; finds the crossing if it lies within reach.
    /// Returns false once the walk is over (crossing found or q_end reached).
    pub fn step(&mut self, q_end: f64) -> bool {
        if self.crossing.is_some() || self.q >= q_end {
            return false;
        }
        let (fam, a, tol_q) = (self.v.family, self.a, self.tol_q);
        let rows = rows_for(self.lam.abs().max(a.abs()) + 8.0, self.q);
        let f = self.sign * (self.lam - a) - ULPS * f64::EPSILON * (1.0 + self.lam.abs());
        // The slope is taken up to one converged Newton step (1e-9 relative) from λ.
        let df = self.sign * self.slope - SLOPE_SLACK;
        let lipschitz = 0.5 * f.max(0.0);
        let mut g = self.gap - 4.0 * (self.q - self.q_gap);
        // The gap only matters where the curvature bound could beat the Lipschitz step.
        if g < 0.5 * self.gap && lipschitz < self.gap / 8.0 {
            g = self.certify_gap(rows);
            self.gap = g;
            self.q_gap = self.q;
        }
        let k = 16.0 / g;
        // Finish: f monotone on [q, q + 2t_N + tol] and the count changed there.
        if df < 0.0 && f > 0.0 && g > 0.0 {
            let t_n = f / -df;
            let reach = 2.0 * t_n + tol_q;
            if reach <= g / 8.0 && k * reach < -0.5 * df && f <= g / 16.0 {
                let hi = (self.q + reach).min(q_end);
                self.passes += 1;
                if fam.count(hi, a, rows) != self.c0 {
                    let guess = self.q + t_n;
                    let q = root_in(
                        fam,
                        a,
                        (self.q, hi),
                        self.c0,
                        guess,
                        tol_q,
                        &mut self.passes,
                    );
                    self.crossing = Some(q);
                    return false;
                }
            }
        }
        let taylor = if f > 0.0 && g > 0.0 {
            ((df + math::sqrt(df * df + 2.0 * k * f)) / k).min(g / 8.0)
        } else {
            0.0
        };
        let mut h = lipschitz.max(taylor);
        if h < tol_q {
            // A tangency (or f below rounding): look one tolerance ahead.
            self.passes += 1;
            let hi = (self.q + tol_q).min(q_end);
            if fam.count(hi, a, rows) != self.c0 {
                self.crossing = Some(self.q + 0.5 * (hi - self.q));
                return false;
            }
            h = tol_q;
        }
        let q = self.q + h;
        if q >= q_end {
            self.q = q_end;
            return false;
        }
        // λ(q) lies within 2h of λ (Lipschitz); Newton from the linear prediction.
        let r = 2.0 * h + ULPS * f64::EPSILON * (1.0 + self.lam.abs());
        let rows = rows_for(self.lam.abs().max(a.abs()) + 8.0, q);
        let guess = self.lam + self.slope * h;
        let (lam, slope, n) = eigenvalue_in(self.v, q, self.lam - r, self.lam + r, guess, rows);
        self.passes += n;
        self.q = q;
        self.lam = lam;
        self.slope = slope;
        true
    }

    /// A distance g from λ within which the block has no other eigenvalue: counts at λ ± g,
    /// from twice the last certified value, halved until both counts agree.
    fn certify_gap(&mut self, rows: usize) -> f64 {
        let (fam, i) = (self.v.family, self.v.index);
        let mut g = 2.0 * self.gap;
        for _ in 0..60 {
            self.passes += 1;
            let clear_above = fam.count(self.q, self.lam + g, rows) == i + 1;
            let clear_below = i == 0 || {
                self.passes += 1;
                fam.count(self.q, self.lam - g, rows) == i
            };
            if clear_above && clear_below {
                return g;
            }
            g *= 0.5;
        }
        g
    }
}

/// The first q in [q_start, q_end] where the value `v` meets a, walking from q_start.
pub fn first_crossing(v: Value, a: f64, q_start: f64, q_end: f64, tol_q: f64) -> Crossing {
    let mut w = Follower::new(v, a, q_start, tol_q);
    for _ in 0..100_000 {
        if !w.step(q_end) {
            break;
        }
    }
    Crossing {
        q: w.crossing,
        passes: w.passes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crossing of λ(q) = a by bisecting the block count alone (no Newton), to 1e-14.
    fn bisected(fam: Family, a: f64, mut lo: f64, mut hi: f64, c_lo: u32) -> f64 {
        while hi - lo > 1e-14 {
            let mid = 0.5 * (lo + hi);
            if fam.count(mid, a, rows_for(a, mid)) == c_lo {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn newton_root_matches_bisection() {
        // a₀(q) = a and b₁(q) = a (both decrease in q) for a = 4k, k from −5 to 0.2 (a₀ only
        // for k < 0: at a = 0 it is a double root at q = 0): Newton in q on the determinant
        // against plain bisection of the count, to 1e-12.
        for i in 0..=26 {
            let a = 4.0 * (-5.0 + 0.2 * f64::from(i));
            let fams: &[Family] = if a < 0.0 {
                &[Family::EvenCos, Family::OddSin]
            } else {
                &[Family::OddSin]
            };
            for &fam in fams {
                let mut passes = 0;
                let got = root_in(fam, a, (0.0, 50.0), 0, 1.0, 1e-13, &mut passes);
                let want = bisected(fam, a, 0.0, 50.0, 0);
                assert!((got - want).abs() < 1e-12, "{fam:?} a {a}: {got} vs {want}");
                assert!(passes < 40, "{fam:?} a {a}: {passes} passes");
            }
        }
    }

    #[test]
    fn walk_finds_the_first_crossing_of_a_rising_then_falling_value() {
        // a₁(q) rises from 1 (slope 1), turns and falls: at a = 1.5 it meets a first on the
        // way up. Reference: the first change of the OddCos count on a grid of 1e-3 in q,
        // then bisected (a₁ is the only value of that block near 1.5 for q < 10).
        let a = 1.5;
        let walk = first_crossing(Value::a(1), a, 0.0, 20.0, 1e-13);
        let mut q = 0.0;
        while Family::OddCos.count(q + 1e-3, a, rows_for(a, q)) == 1 {
            q += 1e-3;
        }
        let want = bisected(Family::OddCos, a, q, q + 1e-3, 1);
        let got = walk.q.expect("a crossing");
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        // b₂(q) = 4 − q²/12 + … falls through 3.9 (a₂ rises away): the same check.
        let walk = first_crossing(Value::b(2), 3.9, 0.0, 20.0, 1e-13);
        let mut q = 0.0;
        while Family::EvenSin.count(q + 1e-3, 3.9, rows_for(3.9, q)) == 0 {
            q += 1e-3;
        }
        let want = bisected(Family::EvenSin, 3.9, q, q + 1e-3, 0);
        let got = walk.q.expect("a crossing");
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }

    #[test]
    fn walk_reports_no_crossing_before_the_end() {
        // a₀ decreases from 0: it never rises to a = 0.5 (count stays 1 up to q = 20).
        let walk = first_crossing(Value::a(0), 0.5, 0.0, 20.0, 1e-12);
        assert_eq!(walk.q, None);
        assert_eq!(Family::EvenCos.count(20.0, 0.5, rows_for(0.5, 20.0)), 1);
    }
}
