//! The pendulum model (SPEC §2–3).
//!
//! | module | concept |
//! |---|---|
//! | [`geometry`] | rod, point mass or general body → equivalent length ℓ |
//! | [`drive`] | the shaking: amplitude A, angular frequency ω, drive angle θd |
//! | [`groups`] | the dimensionless groups R, ωc, ω0, k, m, Q |
//! | [`equations`] | the full and averaged equations of motion, the effective potential |
//! | [`trig`] | degree-2 trigonometric polynomials and all their roots on the circle |
//! | [`equilibria`] | every equilibrium of the averaged motion, with its stability |
//! | [`infer`] | R inferred from a settled angle |

pub mod drive;
pub mod equations;
pub mod equilibria;
pub mod geometry;
pub mod groups;
pub mod infer;
pub mod trig;

pub use drive::{Drive, DriveAngle};
pub use equations::{AveragedModel, FullModel};
pub use equilibria::{equilibria, Equilibria, Equilibrium, Stability};
pub use geometry::Geometry;
pub use groups::Groups;
pub use infer::{infer_r, RInference, RMethod};
