//! Canonical cases with known answers: the reference table of physics §4 as named values, shared by
//! tests, benchmarks and scenes. Each printed value carries the tolerance its printed digits imply
//! (half a unit in the last place), so a test can say "agrees with the reference as printed (physics §4.5)".

/// A number as printed in a reference, with half a unit in its last printed place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Printed {
    pub value: f64,
    pub half_ulp: f64,
}

impl Printed {
    /// Whether `x` rounds to the printed value.
    pub fn matches(&self, x: f64) -> bool {
        (x - self.value).abs() <= self.half_ulp * (1.0 + 1e-9)
    }
}

const fn printed(value: f64, decimals: i32) -> Printed {
    let mut half = 0.5;
    let mut i = 0;
    while i < decimals {
        half /= 10.0;
        i += 1;
    }
    Printed {
        value,
        half_ulp: half,
    }
}

/// Stability boundaries in m = A/ℓ at one signed k (point-mass form), as printed in physics §4.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryCase {
    pub k: f64,
    /// Averaging: √(−2k).
    pub conventional_lower: Option<Printed>,
    /// Harmonic balance: 2√(k(k−1)(k−4)/(3k−8)).
    pub improved_lower: Option<Printed>,
    /// Flutter boundary from the 3×3 determinant.
    pub upper_cubic: Option<Printed>,
    /// Flutter boundary from the truncated formula ¼[√((4k−9)(20k−13)) + 4k − 9].
    pub upper_truncated: Option<Printed>,
    /// An order-n subharmonic threshold from the 5×5 harmonic balance: (n, m).
    pub subharmonic: Option<(u32, Printed)>,
}

/// k = −0.3: 0.775 / 0.868 / 0.929 and the order-8 subharmonic 0.8773.
pub const K_MINUS_0_3: BoundaryCase = BoundaryCase {
    k: -0.3,
    conventional_lower: Some(printed(0.775, 3)),
    improved_lower: Some(printed(0.868, 3)),
    upper_cubic: Some(printed(0.929, 3)),
    upper_truncated: None,
    subharmonic: Some((8, printed(0.8773, 4))),
};

/// k = −0.5: improved lower 1.19208 (printed elsewhere as 1.1920), upper 1.2226 / 1.2265.
pub const K_MINUS_0_5: BoundaryCase = BoundaryCase {
    k: -0.5,
    conventional_lower: None,
    improved_lower: Some(printed(1.19208, 5)),
    upper_cubic: Some(printed(1.2226, 4)),
    upper_truncated: Some(printed(1.2265, 4)),
    subharmonic: None,
};

/// k = 0: upper 3(√13 − 3)/4 = 0.45416 (truncated) and 0.4540 (3×3 determinant).
pub const K_ZERO: BoundaryCase = BoundaryCase {
    k: 0.0,
    conventional_lower: None,
    improved_lower: None,
    upper_cubic: Some(printed(0.4540, 4)),
    upper_truncated: Some(printed(0.45416, 5)),
    subharmonic: None,
};

/// A physical rod and drive with its R.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodCase {
    pub length: f64,
    pub amplitude: f64,
    pub omega: f64,
    pub gravity: f64,
    pub r: Printed,
}

/// Rod L = 0.25 m, A = 0.0127 m, ω = 188 rad/s, g = 9.81 → R = 1.7433 (printed as ≈ 1.75).
pub const DEMO_ROD: RodCase = RodCase {
    length: 0.25,
    amplitude: 0.0127,
    omega: 188.0,
    gravity: 9.81,
    r: printed(1.7433, 4),
};

/// A stable tilted equilibrium of the averaged motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TiltCase {
    pub r: f64,
    pub drive_angle_deg: f64,
    pub stable_deg: Printed,
}

/// R = 1.75, θd = 90° → φ0 = arccos(1/R) = 55.15°.
pub const HORIZONTAL_1_75: TiltCase = TiltCase {
    r: 1.75,
    drive_angle_deg: 90.0,
    stable_deg: printed(55.15, 2),
};

/// Landau & Lifshitz's lower bound on the pivot amplitude for a point mass: g = 9.81, l = 1 m,
/// ω = 9 rad/s, no damping → amplitude a > √(2g/l)·l/ω = 0.492 m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LandauCase {
    pub gravity: f64,
    pub length: f64,
    pub omega: f64,
    pub lower_amplitude: Printed,
}

pub const LANDAU: LandauCase = LandauCase {
    gravity: 9.81,
    length: 1.0,
    omega: 9.0,
    lower_amplitude: printed(0.492, 3),
};

/// A shipped scene's pendulum (a uniform rod), drive, start and damping as numbers, for code
/// that builds the scene rather than reading its file ([`crate::sim::Scene::from_case`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneCase {
    /// Length of the rod (m).
    pub rod_length: f64,
    /// Drive amplitude A (m).
    pub amplitude: f64,
    /// Drive frequency ω (rad/s).
    pub omega: f64,
    pub drive_angle_deg: f64,
    pub gravity: f64,
    pub initial_angle_deg: f64,
    pub initial_rate: f64,
    /// Viscous damping as a quality factor.
    pub q: f64,
}

/// `scenes/tilted-135.toml`: rod 0.20 m, A = 8.9 mm, ω = 330 rad/s, θd = 135°, Q = 20, from
/// 100° at rest; R ≈ 3.3, and averaged theory puts the reachable stable rest at 118.98°.
pub const TILTED_135: SceneCase = SceneCase {
    rod_length: 0.20,
    amplitude: 0.0089,
    omega: 330.0,
    drive_angle_deg: 135.0,
    gravity: 9.81,
    initial_angle_deg: 100.0,
    initial_rate: 0.0,
    q: 20.0,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn printed_tolerance() {
        assert!((K_MINUS_0_3.subharmonic.unwrap().1.half_ulp - 5e-5).abs() < 1e-18);
        assert!(printed(0.775, 3).matches(0.7746));
        assert!(!printed(0.775, 3).matches(0.7744));
    }
}
