//! The pendulum model (physics §2–3). Its equations of motion — full, averaged, linearised, composed
//! from a scene's effects — are in [`crate::sim::eom`].
//!
//! | module | concept |
//! |---|---|
//! | [`geometry`] | rod, point mass or general body → equivalent length ℓ |
//! | [`drive`] | the shaking: amplitude A, angular frequency ω, drive angle θd |
//! | [`groups`] | the dimensionless groups R, ωc, ω0, k, m, Q |
//! | [`trig`] | degree-2 trigonometric polynomials and all their roots on the circle |
//! | [`equilibria`] | every equilibrium of the averaged motion, with its stability; the effective potential and energy |
//! | [`infer`] | R inferred from a settled angle |
//! | [`slider_crank`] | the slider-crank's second harmonic in the averaged theory |

pub mod drive;
pub mod equilibria;
pub mod geometry;
pub mod groups;
pub mod infer;
pub mod slider_crank;
pub mod trig;

pub use drive::{Drive, DriveAngle};
pub use equilibria::{equilibria, Equilibria, Equilibrium, Stability};
pub use geometry::Geometry;
pub use groups::Groups;
pub use infer::{infer_r, RInference, RMethod};
