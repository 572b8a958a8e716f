//! Every equilibrium of the averaged motion, with its stability (physics §3).
//!
//! ```text
//! equilibrium:  f(φ) = sin φ + (R/2) sin 2(φ − θd) = 0
//! margin:       s(φ) = f'(φ) = cos φ + R cos 2(φ − θd)     stable iff s > 0
//! slow freq.:   ωp = ω0 √s
//! ```
//! f is a degree-2 trigonometric polynomial, so [`super::trig`] finds all its roots (two to four)
//! without sampling. Where two roots merge — on the saddle-node curve
//! `R_sn(θd) = (|sin θd|^(2/3) + |cos θd|^(2/3))^(3/2)` — the margin is zero and the answer is
//! [`Stability::Marginal`].
//!
//! Resolution: the inputs are known only to rounding, so roots closer than [`MERGE_RAD`] are one
//! equilibrium, and a margin below [`MARGIN_TOL`]·(1 + R) is zero.

use super::drive::DriveAngle;
use super::trig::TrigPoly2;
use crate::error::{non_negative, ParamError};
use crate::math;

/// Roots closer than this (rad) are reported as one (marginal) equilibrium.
pub const MERGE_RAD: f64 = 1e-6;
/// A stability margin with |s| ≤ MARGIN_TOL·(1 + R) is reported as marginal.
pub const MARGIN_TOL: f64 = 1e-9;
/// A critical point of f with |f| ≤ TOUCH_TOL·scale is a multiple root.
const TOUCH_TOL: f64 = 1e-13;
/// Largest R accepted. Beyond it gravity's term sin φ falls toward the rounding of the drive's
/// (ε·R ≥ 2e-4) and the answer is that of R = ∞; far beyond it (R ≈ 1e308) the margin overflows.
pub const R_MAX: f64 = 1e12;

/// Stability of an equilibrium of the averaged motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stability {
    Stable,
    Unstable,
    /// Zero margin: two or three equilibria merge here.
    Marginal,
}

/// One equilibrium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Equilibrium {
    /// φ0 in radians, in (−π, π].
    pub angle: f64,
    pub stability: Stability,
    /// s = cos φ0 + R cos 2(φ0 − θd).
    pub margin: f64,
    /// ωp/ω0 = √s for a stable equilibrium.
    pub omega_p_over_omega0: Option<f64>,
    /// Within 90° of the drive direction θd, i.e. reachable on an apparatus whose actuator body
    /// sits on the other side of the pivot (physics §3).
    pub within_90_of_drive: bool,
}

/// Two to four equilibria, in increasing angle.
#[derive(Debug, Clone, Copy)]
pub struct Equilibria {
    items: [Option<Equilibrium>; 4],
    len: usize,
}

impl Equilibria {
    pub fn as_slice(&self) -> impl Iterator<Item = &Equilibrium> {
        self.items[..self.len].iter().flatten()
    }
    pub fn len(&self) -> usize {
        self.len
    }
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// The stable equilibria.
    pub fn stable(&self) -> impl Iterator<Item = &Equilibrium> {
        self.as_slice().filter(|e| e.stability == Stability::Stable)
    }
}

/// The equilibrium condition f(φ) as a trigonometric polynomial.
///
/// ```text
/// sin 2(φ − θd) = sin 2φ cos 2θd − cos 2φ sin 2θd
/// ```
pub fn equilibrium_poly(r: f64, theta_d: DriveAngle) -> TrigPoly2 {
    let (s2, c2) = theta_d.sin_cos_2();
    TrigPoly2 {
        a1: 0.0,
        b1: 1.0,
        a2: -0.5 * r * s2,
        b2: 0.5 * r * c2,
    }
}

/// The stability margin s(φ) = cos φ + R cos 2(φ − θd).
pub fn margin(r: f64, theta_d: DriveAngle, phi: f64) -> f64 {
    equilibrium_poly(r, theta_d).derivative().eval(phi)
}

/// All equilibria of the averaged motion for drive strength 0 ≤ R ≤ [`R_MAX`] at drive angle θd.
///
/// A horizontal drive (θd = 90°) factors the condition: f(φ) = sin φ (1 − R cos φ), so above
/// R = 1 the rod rests at ±arccos(1/R) with margin s = R − 1/R, and hanging and inverted are
/// unstable (physics §3):
///
/// ```
/// use kapitza_core::model::{equilibria, DriveAngle};
///
/// let r = 1.75;
/// let eq = equilibria(r, DriveAngle::from_deg(90.0)?)?;
/// assert_eq!(eq.len(), 4);
/// assert_eq!(eq.stable().count(), 2);
/// // Of the two, the one on the drive's side: +arccos(1/R) = 55.15°.
/// let rest = eq.stable().find(|e| e.within_90_of_drive).unwrap();
/// // Tolerance: rounding of the closed-form roots (the root finder is exact for this f).
/// assert!((rest.angle - (1.0 / r).acos()).abs() < 1e-12);
/// assert!((rest.margin - (r - 1.0 / r)).abs() < 1e-12);
/// # Ok::<(), kapitza_core::ParamError>(())
/// ```
pub fn equilibria(r: f64, theta_d: DriveAngle) -> Result<Equilibria, ParamError> {
    let r = non_negative("R", r)?;
    if r > R_MAX {
        return Err(ParamError {
            name: "R",
            value: r,
            allowed: "at most 1e12 (beyond it the answer is that of R = infinity)",
        });
    }
    let f = equilibrium_poly(r, theta_d);
    let fp = f.derivative();
    let roots = f.roots(TOUCH_TOL);
    let roots = roots.as_slice();

    // Merge numerical twins (cyclically: a root at 2π − ε is next to one at 0).
    let mut out = Equilibria {
        items: [None; 4],
        len: 0,
    };
    let mut used = [false; 4];
    for i in 0..roots.len() {
        if used[i] {
            continue;
        }
        let mut twins = 1;
        let mut touch = roots[i].touch;
        let mut angle = roots[i].angle;
        for j in i + 1..roots.len() {
            if !used[j] && math::wrap_pi(roots[j].angle - roots[i].angle).abs() < MERGE_RAD {
                used[j] = true;
                twins += 1;
                if roots[j].touch {
                    touch = true;
                    angle = roots[j].angle; // a critical point locates a multiple root best
                }
            }
        }
        let s = if touch || twins > 1 {
            0.0
        } else {
            fp.eval(angle)
        };
        let stability = if s.abs() <= MARGIN_TOL * (1.0 + r) {
            Stability::Marginal
        } else if s > 0.0 {
            Stability::Stable
        } else {
            Stability::Unstable
        };
        let angle = math::wrap_pi(angle);
        out.items[out.len] = Some(Equilibrium {
            angle,
            stability,
            margin: s,
            omega_p_over_omega0: (stability == Stability::Stable).then(|| math::sqrt(s)),
            within_90_of_drive: math::wrap_pi(angle - theta_d.rad()).abs()
                <= math::FRAC_PI_2 + 1e-12,
        });
        out.len += 1;
    }
    out.items[..out.len].sort_unstable_by(|a, b| {
        let key = |e: &Option<Equilibrium>| e.map_or(f64::INFINITY, |e| e.angle);
        key(a).total_cmp(&key(b))
    });
    Ok(out)
}

/// The saddle-node curve R_sn(θd) = (|sin θd|^(2/3) + |cos θd|^(2/3))^(3/2): below it there are
/// two equilibria, above it four (an astroid in the plane of R sin θd, R cos θd).
pub fn saddle_node_r(theta_d: DriveAngle) -> f64 {
    let (a, b) = (
        math::cbrt(theta_d.sin().abs()),
        math::cbrt(theta_d.cos().abs()),
    );
    let t = a * a + b * b;
    t * math::sqrt(t)
}

/// The effective potential per m g z: v(φ) = −[cos φ + (R/4) cos 2(φ − θd)].
pub fn effective_potential(r: f64, theta_d: DriveAngle, phi: f64) -> f64 {
    // φ − θd wrapped first: doubling a huge φ would overflow to ∞ and give cos = NaN.
    -(math::cos(phi) + 0.25 * r * math::cos(2.0 * math::wrap_pi(phi - theta_d.rad())))
}

/// The energy of the averaged motion per I ω0²: E = φ'²/(2ω0²) + v(φ), conserved without damping
/// (the averaged equation is φ'' = −ω0² v'(φ)).
pub fn averaged_energy(r: f64, theta_d: DriveAngle, omega0: f64, phi: f64, rate: f64) -> f64 {
    0.5 * rate * rate / (omega0 * omega0) + effective_potential(r, theta_d, phi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eq(r: f64, deg: f64) -> Equilibria {
        equilibria(r, DriveAngle::from_deg(deg).unwrap()).unwrap()
    }

    fn stable_deg(e: &Equilibria) -> impl Iterator<Item = f64> + '_ {
        e.stable().map(|e| math::to_deg(e.angle))
    }

    #[test]
    fn vertical_drive_closed_forms() {
        // physics §3: θd = 0 → φ0 = 0 stable with ωp = ω0 √(1 + R); for R > 1 also cos φ = −1/R.
        let e = eq(0.5, 0.0);
        assert_eq!(e.len(), 2);
        let hang = e.as_slice().find(|e| e.angle.abs() < 1e-12).unwrap();
        assert!((hang.omega_p_over_omega0.unwrap() - 1.5f64.sqrt()).abs() < 1e-12);
        // physics §3: θd = 180° → inverted stable iff R > 1, ωp = ω0 √(R − 1).
        let e = eq(3.0, 180.0);
        assert_eq!(e.len(), 4);
        let inv = e
            .as_slice()
            .find(|e| (e.angle - math::PI).abs() < 1e-12)
            .unwrap();
        assert_eq!(inv.stability, Stability::Stable);
        assert!((inv.omega_p_over_omega0.unwrap() - 2f64.sqrt()).abs() < 1e-12);
        let e = eq(0.9, 180.0);
        let inv = e
            .as_slice()
            .find(|e| (e.angle - math::PI).abs() < 1e-12)
            .unwrap();
        assert_eq!(inv.stability, Stability::Unstable);
    }

    #[test]
    fn horizontal_drive() {
        // physics §4.5: R = 1.75, θd = 90° → stable φ0 = ±arccos(1/R) = ±55.15°.
        let c = crate::cases::HORIZONTAL_1_75;
        let e = eq(c.r, c.drive_angle_deg);
        let want = math::to_deg(math::acos(1.0 / c.r));
        assert!((want - c.stable_deg.value).abs() < c.stable_deg.half_ulp);
        let s: [f64; 2] = {
            let mut it = stable_deg(&e);
            [it.next().unwrap(), it.next().unwrap()]
        };
        assert!(
            (s[0] + want).abs() < 1e-9 && (s[1] - want).abs() < 1e-9,
            "{s:?}"
        );
        // Only +55° lies within 90° of the drive direction.
        let within: usize = e.stable().filter(|e| e.within_90_of_drive).count();
        assert_eq!(within, 1);
        // R < 1: hanging, and exactly 90° from the drive counts as within (not "more than 90°").
        let e = eq(0.5, 90.0);
        let hang = e.stable().next().unwrap();
        assert_eq!(hang.angle, 0.0);
        assert!(hang.within_90_of_drive);
    }

    #[test]
    fn merging_points_are_marginal() {
        // R_sn(135°) = 2 and R_sn(90°) = 1 (closed form of the astroid, physics §3).
        let d135 = DriveAngle::from_deg(135.0).unwrap();
        assert!((saddle_node_r(d135) - 2.0).abs() < 1e-12);
        let e = eq(2.0, 135.0);
        assert_eq!(
            e.len(),
            3,
            "{:?}",
            e.as_slice().collect::<std::vec::Vec<_>>()
        );
        assert_eq!(
            e.as_slice()
                .filter(|e| e.stability == Stability::Marginal)
                .count(),
            1
        );
        // Three roots meet at φ = 0 when R = 1, θd = 90°: one marginal equilibrium there.
        let e = eq(1.0, 90.0);
        assert_eq!(e.len(), 2);
        let zero = e.as_slice().find(|e| e.angle.abs() < 1e-6).unwrap();
        assert_eq!(zero.stability, Stability::Marginal);
    }

    #[test]
    fn no_drive_hangs() {
        let e = eq(0.0, 37.0);
        assert_eq!(e.len(), 2);
        assert_eq!(e.stable().count(), 1);
        assert_eq!(e.stable().next().unwrap().angle, 0.0);
    }

    #[test]
    fn rejects_negative_r() {
        assert!(equilibria(-1.0, DriveAngle::from_deg(0.0).unwrap()).is_err());
        assert!(equilibria(f64::NAN, DriveAngle::from_deg(0.0).unwrap()).is_err());
    }
}
