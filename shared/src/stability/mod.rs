//! Stability theory of the vertically driven pendulum (physics §4): four levels, each cheaper one
//! less accurate.
//!
//! All four study the equation linearised about the hanging or the inverted position, in
//! dimensionless time τ = ωt (physics §3):
//!
//! ```text
//! x'' + δ x' + (k − m cos τ) x = 0
//!   δ = c/ω                      damping per radian of drive phase
//!   m = A/ℓ ≥ 0                  drive amplitude over equivalent length
//!   k = +g/(ℓω²)  hanging,  k = −g/(ℓω²)  inverted        ("signed k")
//! Mathieu form (z = τ/2):  y'' + (a − 2q cos 2z) y = 0,   a = 4k,  q = 2m
//! ```
//!
//! | module | level | what it gives | valid when |
//! |---|---|---|---|
//! | [`averaging`] | 1 | inverted stable iff m > √(−2k); no upper end | fast drive, \|k\| ≪ 1, m ≪ 1 |
//! | [`mathieu`] | 2 | boundaries from the small-q series of a0, b1, a1, b2 | \|q\| ≤ [`mathieu::Q_VALID`] |
//! | [`harmonic_balance`] | 3 | Butikov's truncated Fourier systems: lower, flutter, order-n thresholds | the window's neighbourhood; error measured against Floquet |
//! | [`floquet`] | 4 | the monodromy matrix over one period: exact for the linear equation | always (the independent check) |
//! | [`hill`] | 4 | the same verdict and boundaries from Hill's tridiagonal eigenproblems (Sturm counts), damping mapped on exactly | always (the reference `kapitza boundary` reports) |
//!
//! What each level costs and how far it is from Floquet (measured; tests in
//! `tests/stability_agreement.rs` and `tests/stability_reference.rs`; times on the development
//! host, optimised build, indicative only):
//!
//! | level | k = −0.3: lower, upper (Floquet 0.868094, 0.928677) | k = −0.5 (Floquet 1.191816, 1.222613) | cost |
//! |---|---|---|---|
//! | averaging | −0.0935, none | −0.192, none | ≈ 3 ns |
//! | Mathieu series | −0.046, −1.0e-3 (q > 1: flagged) | −0.18, −4.8e-3 (flagged) | ≈ 2 µs |
//! | harmonic balance | +6.9e-5, +4.3e-6 (truncated formula +1.6e-3) | +2.6e-4, +1.7e-5 (+3.9e-3) | ≈ 4 µs |
//! | Floquet, monodromy | reference (own error ≈ 1e-11) | reference | ≈ 28 µs per monodromy, ≈ 500 per window (15 ms) |
//! | Floquet, Hill | agrees with the monodromy to 1e-9 | the same | ≈ 1 µs per window below the first tongue, ≤ 17 µs above it (CPU), no integration |
//!
//! A stability *window* is an interval of m at fixed k (and δ) in which the position is stable:
//! for the hanging position (k > 0) it starts at m = 0 and ends where the first resonance tongue
//! begins; for the inverted position (k < 0) it has two ends. Each level returns a [`Window`]
//! whose ends are either values or the reason there is none, so that "this criterion predicts no
//! upper end" is never confused with "not computed" or a NaN.
//!
//! Inputs are checked at every public function: k, m and δ must be finite, with
//! |k| ≤ [`K_MAX`], 0 ≤ m ≤ [`M_MAX`], 0 ≤ δ ≤ [`DELTA_MAX`]. The limits keep every monodromy
//! matrix finite whatever the step count (RK4's growth per period is at most
//! e^(2π·(|k| + m + δ)) ≤ e^(2π·75) ≈ 1e204), and are far beyond the rig's range (|k| ≪ 1).

pub mod averaging;
pub mod criterion;
pub mod floquet;
pub mod harmonic_balance;
pub mod hill;
pub mod mathieu;

use crate::error::ParamError;
pub use criterion::{Criterion, Position};

/// Largest |k| accepted.
pub const K_MAX: f64 = 25.0;
/// Largest m accepted.
pub const M_MAX: f64 = 25.0;
/// Largest δ accepted.
pub const DELTA_MAX: f64 = 25.0;

/// One end of a stability window in m: a value, or the reason there is none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum End {
    Value(f64),
    Missing(&'static str),
}

impl End {
    /// The value, if there is one.
    pub fn value(self) -> Option<f64> {
        match self {
            End::Value(v) => Some(v),
            End::Missing(_) => None,
        }
    }
}

/// A stability window in m at fixed k: its two ends, and a note on how far to trust them
/// (e.g. that the Mathieu series was used outside its range).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    pub lower: End,
    pub upper: End,
    pub note: Option<&'static str>,
}

impl Window {
    /// Whether m lies strictly inside the window; `None` if an end is missing in a way that
    /// leaves the answer open (a missing upper end counts as "no upper end").
    pub fn contains(&self, m: f64) -> Option<bool> {
        let lower = self.lower.value()?;
        Some(m > lower && self.upper.value().is_none_or(|u| m < u))
    }
}

pub(crate) fn check_k(k: f64) -> Result<f64, ParamError> {
    if k.is_finite() && k.abs() <= K_MAX {
        Ok(k)
    } else {
        Err(ParamError {
            name: "k",
            value: k,
            allowed: "a finite number with |k| <= 25",
        })
    }
}

pub(crate) fn check_m(m: f64) -> Result<f64, ParamError> {
    if m.is_finite() && (0.0..=M_MAX).contains(&m) {
        Ok(m)
    } else {
        Err(ParamError {
            name: "m",
            value: m,
            allowed: "a finite number in [0, 25]",
        })
    }
}

pub(crate) fn check_delta(delta: f64) -> Result<f64, ParamError> {
    if delta.is_finite() && (0.0..=DELTA_MAX).contains(&delta) {
        Ok(delta)
    } else {
        Err(ParamError {
            name: "delta",
            value: delta,
            allowed: "a finite number in [0, 25]",
        })
    }
}

pub(crate) fn check_tol(tol: f64) -> Result<f64, ParamError> {
    crate::error::positive("tol", tol)
}

/// Largest subharmonic order accepted (far past where the threshold meets the lower end).
pub const ORDER_MAX: u32 = 1_000_000;

/// Subharmonic order: 2 ≤ n ≤ [`ORDER_MAX`].
pub(crate) fn check_order(n: u32) -> Result<u32, ParamError> {
    if (2..=ORDER_MAX).contains(&n) {
        Ok(n)
    } else {
        Err(ParamError {
            name: "n",
            value: f64::from(n),
            allowed: "an integer in [2, 1000000]",
        })
    }
}
