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
        Ok(Self::Rod {
            length: positive("length", length)?,
        })
    }

    pub fn point_mass(length: f64) -> Result<Self, ParamError> {
        Ok(Self::PointMass {
            length: positive("length", length)?,
        })
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
        Ok(Self::General { inertia, mass, com })
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
        // Closed forms, SPEC §2: rod ℓ = 2L/3, point mass ℓ = l.
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
