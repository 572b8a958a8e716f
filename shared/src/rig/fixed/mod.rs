//! Number formats of the rig logic: named Q-formats, the wrapping angle, and the one place every
//! approximation comes from.
//!
//! # Q-formats and overflow policy
//!
//! ```text
//! name        type          range            resolution     policy      holds
//! Angle       i32 (newtype) one turn = 2^32  1.46e-9 rad    wrapping    θ, φ, drive and crank phase, θd
//! Rad         I4F28         [−8, 8) rad      3.7e-9 rad     saturating  angle differences in radians
//! Unit        I2F30         [−2, 2)          9.3e-10        saturating  sin, cos, ratios near 1
//! RadPerSec   I16F16        ±32768 rad/s     1.5e-5 rad/s   saturating  ω, ωp, σ, crank speed, ω0²…
//! Ratio       I16F16        ±32768           1.5e-5         saturating  R, gains
//! Amps        I16F16        ±32768 A         1.5e-5 A       saturating  motor current
//! Duty        I1F15         [−1, 1)          3.1e-5         saturating  H-bridge command
//! time        u32 µs        wraps 71.6 min   1 µs           wrapping    sample stamps; only differences used
//! ```
//! Angles and phases wrap by construction: [`Angle`]'s arithmetic is modulo one turn, so an angle
//! that grows without bound (a rotating pendulum, a drive running for months) never loses
//! precision. Physical quantities saturate: a value beyond its format sticks at the end of the
//! range rather than wrapping into a plausible wrong number. Conversions from f64 happen only at
//! the boundary (configuration, requests) and are checked there.
//!
//! # Approximations and their bounds (tested against f64 in this module's tests)
//!
//! | function | method | bound |
//! |---|---|---|
//! | [`trig::sin_cos`] | quadrant reduction in integers, Taylor to x⁹ / x¹⁰ on ±π/4 in Q30 | 4e-9 |
//! | [`trig::sin_cos_table`] | 257-entry quarter-wave table, linear interpolation | 5e-6 |
//! | [`trig::sin_cos_f32_poly`] | same reduction, Taylor to x⁷ / x⁸ in f32 | 4e-7 |
//! | [`trig::sin_cos_f32_micromath`] | `micromath` (crude, for comparison only) | 2e-3 |
//! | [`trig::sin_cos_cordic_model`] | software model of the G4's CORDIC: 24 iterations, 24-bit datapath (comparison only) | 2e-6 |
//! | [`approx::ln_ratio`] | exponent by leading zeros, 2·atanh series to u⁷ | 1e-7 (abs.) |
//! | [`approx::sqrt`] | `fixed`'s exact integer square root, truncating | 1 LSB |
//! | [`approx::sqrt_micromath`] | bit trick, **crude** (√2 → 1.5); not used by the rig | 6 % rel. |
//! | [`approx::div_round`] | exact integer division (M4 SDIV/UDIV or the 64-bit helper), rounded | ½ LSB |

mod angle;
pub mod approx;
pub mod trig;

pub use angle::Angle;

/// Radians for angle differences: I4F28, saturating.
pub type Rad = fixed::types::I4F28;
/// Sines, cosines and ratios near one: I2F30, saturating.
pub type Unit = fixed::types::I2F30;
/// Angular rates (rad/s), rates of decay (1/s), squared rates over small scales: I16F16.
pub type RadPerSec = fixed::types::I16F16;
/// Dimensionless ratios (R) and gains: I16F16.
pub type Ratio = fixed::types::I16F16;
/// Motor current (A): I16F16, saturating.
pub type Amps = fixed::types::I16F16;
/// H-bridge duty in [−1, 1): I1F15.
pub type Duty = fixed::types::I1F15;

/// Microseconds between two wrapping 32-bit µs stamps (valid for gaps < 71.6 min).
#[inline]
pub fn elapsed_us(from: u32, to: u32) -> u32 {
    to.wrapping_sub(from)
}
