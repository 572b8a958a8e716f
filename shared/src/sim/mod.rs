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
pub use run::{simulate, Controller, Format, Method, Options, Report, SimError};
pub use sampling::Recorder;
pub use scene::Scene;
