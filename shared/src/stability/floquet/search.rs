//! Finding the window and the subharmonic thresholds in m from the monodromy matrix.

use super::{Floquet, Linearised, Measured};
use crate::error::ParamError;
use crate::integrate::Stats;
use crate::math;
use crate::stability::{check_delta, check_k, check_order, check_tol, End, Window};

/// Which condition is violated at a given m (at most one can be: their sum is 2(1 + det) > 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// tr M > 1 + det: a real multiplier beyond +1 (period-1 or aperiodic instability).
    TraceHigh,
    /// tr M < −(1 + det): a real multiplier beyond −1 (period-2: flutter).
    TraceLow,
    Stable,
}

/// Evaluates the two conditions at m, counting the work.
struct Probe<'a> {
    fl: &'a Floquet,
    k: f64,
    delta: f64,
    monodromies: u64,
    stats: Stats,
}

impl Probe<'_> {
    /// (1 + det − tr, 1 + det + tr, tr).
    fn eval(&mut self, m: f64) -> (f64, f64, f64) {
        let mo = self.fl.monodromy_unchecked(&Linearised {
            k: self.k,
            delta: self.delta,
            m,
        });
        self.monodromies += 1;
        self.stats.add(mo.stats);
        (
            1.0 + mo.det_exact - mo.trace,
            1.0 + mo.det_exact + mo.trace,
            mo.trace,
        )
    }

    fn state(&mut self, m: f64) -> State {
        let (lo, hi, _) = self.eval(m);
        if lo <= 0.0 {
            State::TraceHigh
        } else if hi <= 0.0 {
            State::TraceLow
        } else {
            State::Stable
        }
    }

    /// Bisects g on [a, b] to width ≤ tol, where g(a) and g(b) differ in sign (g(a) ≤ 0 < g(b)
    /// if `rising`, else g(a) > 0 ≥ g(b)); returns (midpoint, b-side end).
    fn bisect(
        &mut self,
        a: f64,
        b: f64,
        tol: f64,
        rising: bool,
        g: fn((f64, f64, f64)) -> f64,
    ) -> (f64, f64) {
        let (a, b) = math::bisect_flip(|m| (g(self.eval(m)) > 0.0) == rising, a, b, tol);
        (0.5 * (a + b), b)
    }
}

fn cond_lo(v: (f64, f64, f64)) -> f64 {
    v.0
}
fn cond_hi(v: (f64, f64, f64)) -> f64 {
    v.1
}

/// The window and, for its upper end, which condition ended it.
struct Found {
    window: Window,
    upper_by: Option<State>,
}

impl Floquet {
    /// The first stability window in m at (k, δ): see the module doc for the method.
    ///
    /// For k ≥ 0 the lower end is m = 0 by definition (the hanging position is stable without
    /// drive); for k < 0 both ends are searched. Ends are bisected to within `tol` in m.
    pub fn window(&self, k: f64, delta: f64, tol: f64) -> Result<Measured<Window>, ParamError> {
        let mut p = Probe {
            fl: self,
            k: check_k(k)?,
            delta: check_delta(delta)?,
            monodromies: 0,
            stats: Stats::default(),
        };
        let found = self.find(&mut p, check_tol(tol)?);
        Ok(Measured {
            value: found.window,
            monodromies: p.monodromies,
            stats: p.stats,
        })
    }

    fn find(&self, p: &mut Probe, tol: f64) -> Found {
        let h = self.scan_step;
        let mut lower = if p.k >= 0.0 { Some(0.0) } else { None };
        let mut state = if lower.is_some() {
            State::Stable
        } else {
            p.state(0.0)
        };
        if state == State::Stable {
            lower = Some(0.0);
        }
        let mut prev: f64 = 0.0;
        let mut i: u32 = 0;
        while prev < self.scan_limit {
            i += 1;
            // Grid points computed afresh (i·h), not accumulated, so they stay on the grid.
            let m = (f64::from(i) * h).min(self.scan_limit);
            let next = p.state(m);
            match (lower, state, next) {
                (None, State::TraceHigh, State::Stable) => {
                    lower = Some(p.bisect(prev, m, tol, true, cond_lo).0);
                }
                (None, State::TraceHigh, State::TraceLow) => {
                    // The whole window lies inside this step: tr fell from above 1 + det to
                    // below −(1 + det). Bisect each condition separately.
                    let (l, l_b) = p.bisect(prev, m, tol, true, cond_lo);
                    let (u, _) = p.bisect(l_b, m, tol, false, cond_hi);
                    return Found::both(l, u, State::TraceLow);
                }
                (None, State::TraceLow, _) | (None, State::TraceHigh, State::TraceHigh) => {}
                (Some(l), State::Stable, State::TraceHigh) => {
                    let u = p.bisect(prev.max(l), m, tol, false, cond_lo).0;
                    return Found::both(l, u, State::TraceHigh);
                }
                (Some(l), State::Stable, State::TraceLow) => {
                    let u = p.bisect(prev.max(l), m, tol, false, cond_hi).0;
                    return Found::both(l, u, State::TraceLow);
                }
                _ => {}
            }
            state = next;
            prev = m;
        }
        let window = match lower {
            Some(l) => Window {
                lower: End::Value(l),
                upper: End::Missing(STABLE_TO_LIMIT),
                note: None,
            },
            None => Window {
                lower: End::Missing(NEVER_STABLE),
                upper: End::Missing(NEVER_STABLE),
                note: None,
            },
        };
        Found {
            window,
            upper_by: None,
        }
    }

    /// The undamped order-n subharmonic threshold: the m inside the window where
    /// tr M = 2 cos(2π/n). For n = 2 that is the window's upper end when the window ends at
    /// tr M = −2 (flutter).
    pub fn subharmonic_m(&self, k: f64, n: u32, tol: f64) -> Result<Measured<End>, ParamError> {
        let n = check_order(n)?;
        let mut p = Probe {
            fl: self,
            k: check_k(k)?,
            delta: 0.0,
            monodromies: 0,
            stats: Stats::default(),
        };
        let found = self.find(&mut p, check_tol(tol)?);
        let value = match (found.window.lower, found.window.upper) {
            (End::Value(_), End::Value(u)) if n == 2 => {
                if found.upper_by == Some(State::TraceLow) {
                    End::Value(u)
                } else {
                    End::Missing(NOT_FLUTTER)
                }
            }
            (End::Value(l), End::Value(u)) => {
                let target = 2.0 * math::cos(math::TAU / f64::from(n));
                let above = |v: (f64, f64, f64)| v.2 > target;
                let at_l = above(p.eval(l));
                if at_l == above(p.eval(u)) {
                    End::Missing(TRACE_NOT_REACHED)
                } else {
                    let (a, b) = math::bisect_flip(|m| above(p.eval(m)) != at_l, l, u, tol);
                    End::Value(0.5 * (a + b))
                }
            }
            (_, End::Missing(why)) | (End::Missing(why), _) => End::Missing(why),
        };
        Ok(Measured {
            value,
            monodromies: p.monodromies,
            stats: p.stats,
        })
    }
}

impl Found {
    fn both(l: f64, u: f64, by: State) -> Found {
        Found {
            window: Window {
                lower: End::Value(l),
                upper: End::Value(u),
                note: None,
            },
            upper_by: Some(by),
        }
    }
}

/// Reason: the position stays stable to the end of the scan.
pub const STABLE_TO_LIMIT: &str = "stable up to the scan limit in m";
/// Reason: no stable m on the scan.
pub const NEVER_STABLE: &str = "not stable for any m up to the scan limit";
/// Reason: the window does not end at tr M = −2.
pub const NOT_FLUTTER: &str = "the window ends at tr M = +2, not at a period-2 (flutter) boundary";
/// Reason: tr M does not pass 2 cos(2π/n) between the window's ends.
pub const TRACE_NOT_REACHED: &str = "tr M does not pass 2 cos(2π/n) inside the window";

/// [`Floquet::window`] with the defaults ([`super::DEFAULT_STEPS`], scan step and limit).
///
/// The inverted window opens where the characteristic value a0(q) of Mathieu's equation equals
/// a = 4k (q = 2m, physics §4). At q = 1, a0 = −0.4551386634 (Abramowitz & Stegun, table
/// 20.1), so at k = a0/4 the window's lower end is m = 0.5:
///
/// ```
/// use kapitza_core::stability::floquet;
///
/// let k = -0.455_138_663_4 / 4.0;
/// let w = floquet::window(k, 0.0, 1e-9)?.value;
/// let lower = w.lower.value().unwrap();
/// // Tolerance: the table's ten digits carry into m at about 1e-10; 1e-7 covers the search.
/// assert!((lower - 0.5).abs() < 1e-7, "{lower}");
/// # Ok::<(), kapitza_core::ParamError>(())
/// ```
pub fn window(k: f64, delta: f64, tol: f64) -> Result<Measured<Window>, ParamError> {
    Floquet::default().window(k, delta, tol)
}

/// [`Floquet::subharmonic_m`] with the defaults.
pub fn subharmonic_m(k: f64, n: u32, tol: f64) -> Result<Measured<End>, ParamError> {
    Floquet::default().subharmonic_m(k, n, tol)
}
