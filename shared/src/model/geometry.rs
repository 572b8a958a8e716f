//! Pendulum geometries and their equivalent length.
//!
//! ```text
//! ℓ = I / (m z)          (I about the pivot, centre of mass at distance z)
//! uniform rod, length L:  I = m L²/3, z = L/2   →  ℓ = 2L/3
//! point mass on light rod: I = m l², z = l      →  ℓ = l
//! ```

use crate::error::{positive, ParamError};

/// The swinging body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Geometry {
    /// A thin uniform rod of the given length (m), pivoted at one end.
    Rod { length: f64 },
    /// A point mass on a massless rod of the given length (m).
    PointMass { length: f64 },
    /// Any rigid body: moment of inertia about the pivot (kg m²), mass (kg), pivot-to-centre-of-mass
    /// distance (m).
    General { inertia: f64, mass: f64, com: f64 },
}

impl Geometry {
    pub fn rod(length: f64) -> Result<Self, ParamError> {
        Self::Rod {
            length: positive("length", length)?,
        }
        .with_finite_length()
    }

    pub fn point_mass(length: f64) -> Result<Self, ParamError> {
        Self::PointMass {
            length: positive("length", length)?,
        }
        .with_finite_length()
    }

    /// A general body. The parallel-axis theorem requires I ≥ m z², i.e. ℓ ≥ z.
    pub fn general(inertia: f64, mass: f64, com: f64) -> Result<Self, ParamError> {
        let inertia = positive("inertia", inertia)?;
        let mass = positive("mass", mass)?;
        let com = positive("com", com)?;
        if inertia < mass * com * com * (1.0 - 1e-12) {
            return Err(ParamError {
                name: "inertia",
                value: inertia,
                allowed: "at least mass * com^2 (parallel-axis theorem)",
            });
        }
        Self::General { inertia, mass, com }.with_finite_length()
    }

    /// Checks a body built as a literal — the variants' fields are public, and a decoded rig
    /// configuration builds them directly — exactly as its constructor would.
    pub fn validate(self) -> Result<Self, ParamError> {
        match self {
            Self::Rod { length } => Self::rod(length),
            Self::PointMass { length } => Self::point_mass(length),
            Self::General { inertia, mass, com } => Self::general(inertia, mass, com),
        }
    }

    /// Accepted parts can still give ℓ = ∞ (a rod of f64::MAX: 2L overflows; I/(m z) with a
    /// tiny m z) or ℓ = 0 (a subnormal rod): refused, so that no ω0 = √(g/ℓ) is 0 or ∞.
    fn with_finite_length(self) -> Result<Self, ParamError> {
        positive("equivalent length", self.equivalent_length())?;
        Ok(self)
    }

    /// The equivalent length ℓ = I/(m z) in metres: the length of the point-mass pendulum with the
    /// same dynamics.
    pub fn equivalent_length(&self) -> f64 {
        match *self {
            Self::Rod { length } => 2.0 * length / 3.0,
            Self::PointMass { length } => length,
            Self::General { inertia, mass, com } => inertia / (mass * com),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equivalent_lengths() {
        // Closed forms, physics §2: rod ℓ = 2L/3, point mass ℓ = l.
        assert!((Geometry::rod(0.3).unwrap().equivalent_length() - 0.2).abs() < 1e-15);
        assert_eq!(Geometry::point_mass(0.7).unwrap().equivalent_length(), 0.7);
        // A rod described as a general body (I = mL²/3, z = L/2) must agree with the rod.
        let (m, l) = (0.05, 0.25);
        let g = Geometry::general(m * l * l / 3.0, m, l / 2.0).unwrap();
        assert!((g.equivalent_length() - 2.0 * l / 3.0).abs() < 1e-15);
    }

    #[test]
    fn rejects_bad_bodies() {
        assert!(Geometry::rod(0.0).is_err());
        assert!(Geometry::rod(f64::NAN).is_err());
        assert!(Geometry::point_mass(-1.0).is_err());
        // I below m z² is physically impossible.
        assert_eq!(
            Geometry::general(0.001, 1.0, 0.1).unwrap_err().name,
            "inertia"
        );
    }
}
