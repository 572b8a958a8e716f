//! Calibration: pure functions a host runs on what the rig reports, to find out what the rig
//! really is — the pendulum sensor's zero and direction, the crank's direction, the servo's
//! map, the current sensor's offset, the pendulum's equivalent length ℓ and damping, and the
//! stroke A. Each takes samples (slices, no allocation) and returns its measurement or a named
//! refusal ([`CalibError`]) when the samples cannot support one.
//!
//! | module | concept |
//! |---|---|
//! | [`error`] | [`CalibError`]: why a measurement was refused |
//! | [`period`] | the period of a free pendulum at finite amplitude (arithmetic–geometric mean) |
//! | [`swing`] | a free oscillation's turning points and the crossings of each half-swing's midline |
//! | [`decay`] | the envelope's decay: viscous (geometric), Coulomb (linear) or both, and which |
//! | [`ringdown`] | system identification from a ring-down with the drive off: zero, ω0, ℓ, Q, μ |
//! | [`stroke`] | the stroke A from the fast wobble's amplitude, hanging at θd = 90° |
//! | [`plumb`] | the mount's true drive angle from the hanging pendulum's lean |
//! | [`direction`] | the sensor's direction from a counter-clockwise nudge; the crank's from a pulse |
//! | [`servo_fit`] | the servo's pulse → angle line from jog-to-mark pairs, and its travel |
//! | [`current`] | the current sensor's offset at rest |
//! | [`tolerance`] | how accurate ℓ and A must be for the settle angle to be right within 0.5° |
//!
//! The order of a calibration: direction and zero first (every later angle is read through
//! them), then the crank, the servo and the current sensor, then ℓ and the damping from a
//! ring-down, and last the stroke, whose formula needs ℓ and ω0.

pub mod current;
pub mod decay;
pub mod direction;
pub mod error;
pub mod period;
pub mod plumb;
pub mod ringdown;
pub mod servo_fit;
pub mod stroke;
pub mod swing;
pub mod tolerance;

#[cfg(test)]
mod bench_rig;

pub use error::CalibError;
