//! Level 4: Floquet theory — the reference the other levels are judged against (physics §4).
//!
//! The linearised equation has 2π-periodic coefficients, so one period's solution map, the
//! *monodromy matrix* M, decides stability (Floquet; e.g. Magnus & Winkler, *Hill's Equation*,
//! ch. 1):
//!
//! ```text
//! x'' + δ x' + (k − m cos τ) x = 0,      y = (x, x')
//! columns of M = y(2π) from y(0) = (1, 0) and y(0) = (0, 1)
//! det M = exp(−∫₀^{2π} δ dτ) = e^{−2πδ}                            (Liouville)
//! multipliers μ solve μ² − (tr M) μ + det M = 0
//! undamped (δ = 0):  stable ⇔ |tr M| < 2
//! damped   (δ > 0):  stable ⇔ |tr M| < 1 + det M                   (both |μ| < 1; Jury)
//! margin  = 1 + det M − |tr M|     (positive = stable; det M taken as the exact e^{−2πδ})
//! order-n subharmonic (undamped): μ = e^{±2πi/n}  ⇔  tr M = 2 cos(2π/n)
//! ```
//!
//! M is integrated with classical RK4 ([`rk4_fixed`]) at a fixed number of steps per period,
//! both columns at once (one cos per right-hand side). The boundary error falls as h⁴
//! (measured ratio ≈ 16 per halving). Measured at 125/250/500/1000/2000 steps against 4000, the
//! k = −0.5 lower end is off by 3.6e-8 / 2.2e-9 / 1.4e-10 / 8.7e-12 / 5e-13; at 1000 steps the
//! ends at k = −0.5 … 0 move by ≤ 1.2e-11 when the steps are quadrupled (1.5e-10 at k = 0.6),
//! and det M meets e^{−2πδ} to ≤ 3e-10 relative. Hence the default [`DEFAULT_STEPS`] = 1000:
//! the reference's own error stays five orders below the best cheaper level on the inverted
//! windows (harmonic balance: 4e-6 … 3e-4 at k = −0.3, −0.5), at ≈ 28 µs per monodromy
//! (optimised host build).
//!
//! Window search ([`window`], [`Floquet::window`]): scan m upward from 0 in steps of
//! [`DEFAULT_SCAN_STEP`] up to [`DEFAULT_SCAN_LIMIT`], watching the two conditions
//! `1 + det − tr` and `1 + det + tr` separately. At most one of them is negative at any m (their
//! sum is 2(1 + det) > 0), and tr M changes continuously with m, so a window that lies entirely
//! between two scan points still shows up as both conditions changing sign in one step, and each
//! end is then bisected on its own condition. What the scan can miss is an *unstable* interval
//! (a tongue) narrower than the step inside a stable stretch.
//!
//! Resolution at tongue tips: undamped, at exactly k = j²/4 the hanging window has zero width,
//! but tr M leaves [−2, 2] only like m^(2j) there, so Floquet sees the instability only once that
//! rises above rounding: measured upper ends 4e-8 at k = 1/4 and 1.3e-3 at k = 1 (exact: 0;
//! the Mathieu and harmonic-balance levels give 0 there exactly).

mod search;

pub use search::{
    subharmonic_m, window, NEVER_STABLE, NOT_FLUTTER, STABLE_TO_LIMIT, TRACE_NOT_REACHED,
};

use super::{check_delta, check_k, check_m};
use crate::error::ParamError;
use crate::integrate::{rk4_fixed, Stats, System};
use crate::math;

/// Default RK4 steps per drive period (see the module doc for the measurement behind it).
pub const DEFAULT_STEPS: u32 = 1000;
/// Default scan step in m: well under the narrowest window of the reference table (physics §4.5) (k = −0.5: ≈ 0.03 wide).
pub const DEFAULT_SCAN_STEP: f64 = 0.002;
/// Default scan limit in m.
pub const DEFAULT_SCAN_LIMIT: f64 = 10.0;

/// How a Floquet computation is carried out: its step count and the window scan's grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Floquet {
    steps_per_period: u32,
    scan_step: f64,
    scan_limit: f64,
}

impl Default for Floquet {
    fn default() -> Self {
        Floquet {
            steps_per_period: DEFAULT_STEPS,
            scan_step: DEFAULT_SCAN_STEP,
            scan_limit: DEFAULT_SCAN_LIMIT,
        }
    }
}

impl Floquet {
    /// The default scan with `steps_per_period` RK4 steps (≥ 1).
    pub fn new(steps_per_period: u32) -> Result<Floquet, ParamError> {
        if steps_per_period == 0 {
            return Err(ParamError {
                name: "steps_per_period",
                value: 0.0,
                allowed: "an integer >= 1",
            });
        }
        Ok(Floquet {
            steps_per_period,
            ..Floquet::default()
        })
    }

    /// Sets the window scan's step (1e-4 ≤ step ≤ 1; the lower limit bounds a full scan to
    /// 250 000 monodromies) and limit (step ≤ limit ≤ [`super::M_MAX`]).
    pub fn with_scan(self, step: f64, limit: f64) -> Result<Floquet, ParamError> {
        if !(step.is_finite() && (1e-4..=1.0).contains(&step)) {
            return Err(ParamError {
                name: "scan_step",
                value: step,
                allowed: "a number in [1e-4, 1]",
            });
        }
        if !(limit.is_finite() && limit >= step && limit <= super::M_MAX) {
            return Err(ParamError {
                name: "scan_limit",
                value: limit,
                allowed: "a number in [scan_step, 25]",
            });
        }
        Ok(Floquet {
            scan_step: step,
            scan_limit: limit,
            ..self
        })
    }

    pub fn steps_per_period(&self) -> u32 {
        self.steps_per_period
    }

    /// The monodromy matrix at (k, δ, m).
    pub fn monodromy(&self, k: f64, delta: f64, m: f64) -> Result<Monodromy, ParamError> {
        let sys = Linearised {
            k: check_k(k)?,
            delta: check_delta(delta)?,
            m: check_m(m)?,
        };
        Ok(self.monodromy_unchecked(&sys))
    }

    /// The stability margin 1 + e^{−2πδ} − |tr M|: positive = stable.
    pub fn margin(&self, k: f64, delta: f64, m: f64) -> Result<f64, ParamError> {
        Ok(self.monodromy(k, delta, m)?.margin())
    }

    fn monodromy_unchecked(&self, sys: &Linearised) -> Monodromy {
        let mut stats = Stats::default();
        let y = rk4_fixed(
            sys,
            0.0,
            [1.0, 0.0, 0.0, 1.0],
            math::TAU,
            self.steps_per_period,
            &mut stats,
        );
        let matrix = [[y[0], y[2]], [y[1], y[3]]];
        Monodromy {
            matrix,
            trace: y[0] + y[3],
            det: y[0] * y[3] - y[2] * y[1],
            det_exact: math::exp(-math::TAU * sys.delta),
            stats,
        }
    }
}

/// The monodromy matrix of one drive period and what it costs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Monodromy {
    /// M = [[x₁, x₂], [x₁', x₂']](2π), columns from the unit initial states.
    pub matrix: [[f64; 2]; 2],
    pub trace: f64,
    /// det M as integrated: a check on the integration against `det_exact`.
    pub det: f64,
    /// e^{−2πδ} (Liouville's formula), used by the stability verdict.
    pub det_exact: f64,
    /// RK4 work (one right-hand side evaluation advances both columns).
    pub stats: Stats,
}

impl Monodromy {
    /// 1 + det M − |tr M| (det M exact): positive = stable, negative = unstable.
    pub fn margin(&self) -> f64 {
        1.0 + self.det_exact - self.trace.abs()
    }

    /// Strictly stable (margin > 0). Marginal cases (margin = 0) count as not stable.
    pub fn is_stable(&self) -> bool {
        self.margin() > 0.0
    }
}

/// The monodromy matrix with `steps_per_period` RK4 steps.
///
/// ```
/// use kapitza_core::stability::floquet;
/// // Hanging, undamped, no drive: M is a rotation by 2π√k, tr M = 2 cos(2π√k).
/// let mo = floquet::monodromy(0.09, 0.0, 0.0, 1000).unwrap();
/// let want = 2.0 * (std::f64::consts::TAU * 0.3).cos();
/// assert!((mo.trace - want).abs() < 1e-11);
/// assert!(mo.is_stable());
/// ```
pub fn monodromy(
    k: f64,
    delta: f64,
    m: f64,
    steps_per_period: u32,
) -> Result<Monodromy, ParamError> {
    Floquet::new(steps_per_period)?.monodromy(k, delta, m)
}

/// The stability margin with the default step count; positive = stable.
pub fn margin(k: f64, delta: f64, m: f64) -> Result<f64, ParamError> {
    Floquet::default().margin(k, delta, m)
}

/// A result with the work it took: monodromy matrices computed and RK4 work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured<T> {
    pub value: T,
    pub monodromies: u64,
    pub stats: Stats,
}

/// x'' + δ x' + (k − m cos τ) x = 0 for two solutions at once: y = (x₁, x₁', x₂, x₂').
struct Linearised {
    k: f64,
    delta: f64,
    m: f64,
}

impl System<4> for Linearised {
    fn rhs(&self, t: f64, y: &[f64; 4], dy: &mut [f64; 4]) {
        let s = self.k - self.m * math::cos(t);
        dy[0] = y[1];
        dy[1] = -self.delta * y[1] - s * y[0];
        dy[2] = y[3];
        dy[3] = -self.delta * y[3] - s * y[2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_oscillator_closed_form() {
        // m = 0, δ = 0, k > 0: M = rotation-like, tr M = 2 cos(2π√k) (closed form).
        // RK4 phase error at 1000 steps, ω = 0.5: ≈ 2π·(hω)⁵/120 ≈ 1e-12.
        let mo = monodromy(0.25 * 0.81, 0.0, 0.0, 1000).unwrap();
        assert!((mo.trace - 2.0 * math::cos(math::TAU * 0.45)).abs() < 1e-11);
        assert_eq!(mo.stats.steps, 1000);
        assert_eq!(mo.stats.rhs_evals, 4000);
        // k < 0, m = 0: tr M = 2 cosh(2π√−k) > 2, unstable (closed form).
        let mo = monodromy(-0.3, 0.0, 0.0, 1000).unwrap();
        let s = math::sqrt(0.3) * math::TAU;
        assert!((mo.trace - (math::exp(s) + math::exp(-s))).abs() < 1e-9 * mo.trace);
        assert!(!mo.is_stable());
    }

    #[test]
    fn rejects_bad_input() {
        assert!(monodromy(f64::NAN, 0.0, 0.0, 100).is_err());
        assert!(monodromy(0.1, -0.1, 0.0, 100).is_err());
        assert!(monodromy(0.1, 0.0, f64::INFINITY, 100).is_err());
        assert!(monodromy(0.1, 0.0, -0.5, 100).is_err());
        assert!(monodromy(0.1, 0.0, 0.5, 0).is_err());
        assert!(Floquet::default().with_scan(0.0, 1.0).is_err());
        assert!(Floquet::default().with_scan(1e-9, 1.0).is_err());
        assert!(Floquet::default().with_scan(0.01, 100.0).is_err());
    }

    #[test]
    fn extreme_inputs_stay_finite() {
        // The input limits keep M finite even with a single, hopelessly coarse step.
        for steps in [1, 3, 1000] {
            for (k, d, m) in [(-25.0, 25.0, 25.0), (25.0, 25.0, 25.0), (-25.0, 0.0, 25.0)] {
                let mo = monodromy(k, d, m, steps).unwrap();
                assert!(
                    mo.trace.is_finite() && mo.det.is_finite(),
                    "{k} {d} {m} {steps}"
                );
            }
        }
    }
}
