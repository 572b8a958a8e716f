//! The simulator: scenes, the equations they compose, and what the pendulum ends up doing.
//!
//! | module | concept |
//! |---|---|
//! | [`scene`] | one experiment in SI units, checked once |
//! | [`signal`] | the drive: pivot acceleration and phase, with ramp, motor lag, slider-crank |
//! | [`eom`] | full, averaged and linearised equations, composed from the listed effects |
//! | [`fidelity`] | which equation a scene runs (`auto`: the cheapest valid one) and why |
//! | [`wobble`] | the fast wobble: full state to the averaged model's slow state and back |
//! | [`classify`] | the outcome from stroboscopic samples |
//! | [`sampling`] | strobes, period means, output and sensor samples between steps |
//! | [`sensor`] | the pivot encoder: sampled, noisy, quantised |
//! | [`noise`] | seeded, reproducible uniform and Gaussian noise |
//! | [`friction`] | Coulomb stick–slip as switched smooth segments |
//! | `periodic` | the full equation by RKN 8(6), a whole number of steps per drive period |
//! | `slow_series` | the averaged force as a power series about a step's start: no sin/cos per stage |
//! | `adaptive` | the full or averaged equation by an adaptive RKN pair (8(6), 12(10)), no libm sin/cos of the angle per evaluation |
//! | [`lyapunov`] | the finite-time Lyapunov exponent of the analysis window |
//! | `turns` | whole turns kept out of the integrated angle, so rotation never loses precision |
//! | [`run`] | `simulate`: compose, integrate, sample, classify |
//!
//! A run: the demo rod (L = 0.25 m, A = 12.7 mm) shaken horizontally at R = 1.75 comes to rest
//! at the averaged theory's arccos(1/R) = 55.15° (physics §3):
//!
//! ```
//! use kapitza_core::model::{DriveAngle, Geometry};
//! use kapitza_core::sim::sampling::Discard;
//! use kapitza_core::sim::scene::{
//!     DriveFrequency, DriveSpec, Effects, Fidelity, FidelityChoice, RunLength, Viscous,
//! };
//! use kapitza_core::sim::{simulate, Options, Outcome, Scene};
//!
//! let r = 1.75;
//! let scene = Scene {
//!     pendulum: Geometry::rod(0.25)?,
//!     drive: DriveSpec {
//!         amplitude: 0.0127,
//!         frequency: DriveFrequency::R(r),
//!         angle: DriveAngle::from_deg(90.0)?,
//!     },
//!     gravity: 9.81,
//!     initial_angle: 40f64.to_radians(),
//!     initial_rate: 0.0,
//!     length: RunLength::Periods(2000.0),
//!     fidelity: FidelityChoice::Fixed(Fidelity::Averaged),
//!     effects: Effects {
//!         viscous: Some(Viscous::Q(10.0)),
//!         ..Effects::default()
//!     },
//! };
//! let report = simulate(&scene, &Options::default(), &mut Discard).unwrap();
//! let Outcome::Rest { angle } = report.outcome else {
//!     panic!("{:?}", report.outcome);
//! };
//! // The averaged model lands on the theory's root to well within the classifier's resolution.
//! assert!((angle - (1.0 / r).acos()).abs() < 2e-4, "{}", angle.to_degrees());
//! # Ok::<(), kapitza_core::ParamError>(())
//! ```

mod adaptive;
pub mod classify;
pub mod eom;
pub mod fidelity;
mod friction;
mod lyapunov;
pub mod noise;
mod periodic;
pub mod run;
pub mod sampling;
pub mod scene;
pub mod sensor;
pub mod signal;
mod slow_series;
mod turns;
pub mod wobble;

pub use classify::Outcome;
pub use run::{
    simulate, Controller, EndState, Format, Method, Options, PlannedRun, Report, SimError,
};
pub use sampling::Recorder;
pub use scene::Scene;
