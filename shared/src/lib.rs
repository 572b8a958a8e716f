//! `kapitza-core`: the physics of a pendulum whose pivot is shaken along a tilted line, its
//! stability theory and the numerics that support them. `no_std`, tested on the host.
//!
//! # Module map
//!
//! Ordered bottom-up: a module imports only from rows above its own (`tests/layering.rs` checks
//! it), so there is no cycle between modules.
//!
//! | module | concept |
//! |---|---|
//! | [`math`] | the one place float functions come from (libm), angle wrapping, bisection |
//! | [`real`] | the number formats (f64, f32) behind one trait, math through libm |
//! | [`error`] | parameter errors raised at the boundary of the API |
//! | [`checksum`] | CRC-32C, the one checksum of frames, the flash record and retained state |
//! | [`cases`] | canonical cases with known answers, shared by tests, benchmarks and scenes |
//! | [`poly`] | small real polynomials: arithmetic and robust real-root isolation |
//! | [`model`] | geometry → equivalent length, drive, dimensionless groups, equilibria of the averaged motion, R inferred from a settled angle |
//! | [`integrate`] | the `System` trait, work statistics; RK4, DOP853 with dense output, RKN pairs, Verlet and Yoshida compositions |
//! | [`stability`] | the four levels of stability theory: averaging, Mathieu series, harmonic balance, Floquet (Hill/Sturm) |
//! | [`sim`] | the simulator: scenes, the equations of motion composed from a scene's effects (`sim::eom`), runs and outcomes |
//! | [`rig`] | the microcontroller's logic: drive generator, phase lock, fixed-point estimator, safety, calibration — tested on the host and on an emulated Cortex-M4 |
//! | [`link`] | the serial link's wire: typed messages, COBS + CRC-32C frames, protocol version and compatibility policy, refusal reasons |
//! | [`persist`] | the rig configuration as a checksummed flash record, with migration and the fallback to safe defaults |
//! | [`station`] | the rig loop: one rig and its link end, hardware-free (samples, control ticks, bytes in → frames out), with the server that answers requests and the pre-run check; run by the firmware, the on-target tests and the simulated rig |
//! | [`simrig`] | the simulated rig: the pendulum's full equation on the crank's actual angle, motor, sensors, servo and e-stop, around a [`station::RigLoop`] |
//! | [`calib`] | calibration from what the rig reports: sensor zero and direction, crank direction, servo map, current offset, ℓ and damping from a ring-down, the stroke from the wobble |
//! | [`selftest`] | deterministic scenarios with digests, run on the host and on the emulated MCU |
//!
//! # Conventions (physics §2–3)
//!
//! ```text
//! angles from the downward vertical, counter-clockwise positive; θ = 0 hangs, θ = π inverted
//! pivot:  r_p(t) = A cos(ωt) · (sin θd, −cos θd)
//! full:   θ'' = −(g/ℓ) sin θ − (A ω²/ℓ) sin(θ − θd) cos(ωt) − c θ'
//! groups: ω0 = √(g/ℓ),  R = A²ω²/(2gℓ),  ωc = √(2gℓ)/A,  m = A/ℓ,  k = ±g/(ℓω²),  Q = ω0/c
//! ```
//! SI units and radians throughout; degrees only at the user interface. "physics §N" in the
//! docs of this crate is section N of the repository's `docs/physics.md`; its sources are in
//! `docs/references.md`.
#![cfg_attr(not(test), no_std)]

#[cfg(feature = "std")]
extern crate std;

pub mod calib;
pub mod cases;
pub mod checksum;
pub mod error;
pub mod integrate;
pub mod link;
pub mod math;
pub mod model;
pub mod persist;
pub mod poly;
pub mod real;
pub mod rig;
pub mod selftest;
pub mod sim;
pub mod simrig;
pub mod stability;
pub mod station;

pub use error::ParamError;
pub use real::Real;
