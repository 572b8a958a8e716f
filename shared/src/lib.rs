//! `kapitza-core`: the physics of a pendulum whose pivot is shaken along a tilted line, its
//! stability theory and the numerics that support them. `no_std`, tested on the host.
//!
//! # Module map
//!
//! | module | concept |
//! |---|---|
//! | [`math`] | the one place float functions come from (libm), angle wrapping |
//! | [`error`] | parameter errors raised at the boundary of the API |
//! | [`model`] | geometry → equivalent length, drive, dimensionless groups, equations of motion, equilibria of the averaged motion, R inferred from a settled angle |
//! | [`stability`] | the four levels of stability theory: averaging, Mathieu series, harmonic balance, Floquet |
//! | [`integrate`] | the `System` trait, work statistics; RK4, DOP853 with dense output, Verlet and Yoshida compositions |
//! | [`poly`] | small real polynomials: arithmetic and robust real-root isolation |
//! | [`sim`] | the simulator: scenes, composed equations of motion, runs and outcomes |
//! | [`real`] | the number formats (f64, f32) behind one trait, math through libm |
//! | [`rig`] | the microcontroller's logic: drive generator, phase lock, fixed-point estimator, safety — tested on the host and on an emulated Cortex-M4 |
//! | [`link`] | the serial link: typed messages, COBS + CRC-32C frames, protocol version and compatibility policy, refusal reasons, the rig's side of the conversation |
//! | [`persist`] | the rig configuration as a checksummed flash record, with the fallback to safe defaults |
//! | [`station`] | the rig loop: one rig and its link end, hardware-free (samples, control ticks, bytes in → frames out), run by the firmware, the on-target tests and the simulated rig |
//! | [`simrig`] | the simulated rig: the pendulum's full equation on the crank's actual angle, motor, sensors, servo and e-stop, around a [`station::RigLoop`] |
//! | [`calib`] | calibration from what the rig reports: sensor zero and direction, crank direction, servo map, current offset, ℓ and damping from a ring-down, the stroke from the wobble |
//! | [`cases`] | canonical cases with known answers, shared by tests, benchmarks and scenes |
//!
//! # Conventions (SPEC §2–3)
//!
//! ```text
//! angles from the downward vertical, counter-clockwise positive; θ = 0 hangs, θ = π inverted
//! pivot:  r_p(t) = A cos(ωt) · (sin θd, −cos θd)
//! full:   θ'' = −(g/ℓ) sin θ − (A ω²/ℓ) sin(θ − θd) cos(ωt) − c θ'
//! groups: ω0 = √(g/ℓ),  R = A²ω²/(2gℓ),  ωc = √(2gℓ)/A,  m = A/ℓ,  k = ±g/(ℓω²),  Q = ω0/c
//! ```
//! SI units and radians throughout; degrees only at the user interface.
#![cfg_attr(not(test), no_std)]

#[cfg(feature = "std")]
extern crate std;

pub mod calib;
pub mod cases;
pub mod error;
pub mod integrate;
pub mod link;
pub mod math;
pub mod model;
pub mod persist;
pub mod poly;
pub mod real;
pub mod rig;
pub mod sim;
pub mod simrig;
pub mod stability;
pub mod station;

pub use error::ParamError;
pub use real::Real;
