//! HC09 — bad parameters into the numerics.
//!
//! Risk: a NaN, an infinity, a zero or negative length, a zero frequency or an absurd amplitude
//! reaches an integrator or a root finder, which then panics, runs for ever, or returns a result
//! with a NaN or an infinity in it that looks like an answer.
//!
//! Guard: every entry point of the core API that takes a number checks it where it enters
//! (`error::ParamError`, `sim::scene::SceneError`, `IntegrateError::BadTolerance`,
//! `rig::safety::Refusal`) and names the parameter; derived quantities that could overflow
//! (R, ω0, c, ℓ) are checked too, so an accepted input gives a finite result.
//!
//! Criterion, for each entry point: fed NaN, ±∞, ±0, negatives, subnormals and ±1e300 / ±MAX
//! mixed with good values in the other arguments, it never panics, and returns either an error
//! whose message names the bad parameter, or a result in which every float is finite.
//!
//! The fixed-step integrators (`rk4_fixed`, `rk4_observe`, `symplectic_fixed`) have no error
//! channel: their callers check. For them the criterion is that they never panic and never hide
//! a non-finite input behind a finite output.
//!
//! One file per part of the API (`model`, `stability`, `integrate`, `sim`, `rig`), each with its
//! property tests and its hand-picked examples; the strategies and checks they share are here.

use proptest::prelude::*;

mod integrate;
mod model;
mod rig;
mod sim;
mod stability;

/// Values that break numerics: NaN, infinities, signed zeros, negatives, subnormals, extremes —
/// and, through `any::<f64>()`, everything else a float can be.
fn bad() -> impl Strategy<Value = f64> {
    prop_oneof![
        10 => specials(),
        1 => Just(f64::MIN_POSITIVE),
        1 => Just(5e-324), // the smallest subnormal
        1 => Just(1e-300),
        1 => -1e6..0.0f64,
        1 => any::<f64>(),
    ]
}

/// The values every strategy here includes (weighted as one value each): non-finite, signed
/// zeros, −1 and the ends of f64.
fn specials() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        -0.0,
        -1.0,
        1e300,
        -1e300,
        f64::MAX,
        f64::MIN,
    ])
}

/// A bad value, or (one time in three) a plausible one from `good`.
fn or_good(good: core::ops::Range<f64>) -> impl Strategy<Value = f64> {
    prop_oneof![2 => bad(), 1 => good]
}

/// Every float finite, else a failure naming the first that is not.
fn finite(what: &str, xs: &[f64]) -> Result<(), TestCaseError> {
    for (i, x) in xs.iter().enumerate() {
        prop_assert!(x.is_finite(), "{what}: value #{i} is {x} (all: {xs:?})");
    }
    Ok(())
}

/// The error's message names one of `names`.
fn names(err: &impl ToString, names: &[&str]) -> Result<(), TestCaseError> {
    let msg = err.to_string();
    prop_assert!(
        names.iter().any(|n| msg.contains(n)),
        "error {msg:?} names none of {names:?}"
    );
    Ok(())
}

fn cases(n: u32) -> ProptestConfig {
    ProptestConfig::with_cases(n)
}
