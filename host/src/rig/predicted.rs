//! What the averaged theory expects of the configured pendulum at a given R and θd, set beside
//! a measurement: the same computation as `kapitza predict`.
//!
//! ```text
//! stable equilibria φ0 of R, θd, each with ωp = ω0 √(cos φ0 + R cos 2(φ0 − θd))   (physics §3)
//! measured slow angle φ:  the stable φ0 nearest to φ; the others listed
//! none measured yet:      the stable φ0 within 90° of θd (physics §3: the actuator body keeps
//!                         the rod from the others), the nearest to θd if there are two
//! outside_reach:          |φ − θd| > 90° (+ REACH_TOL_DEG): a rig without a body, a sensor
//!                         zero off
//! ```
//! A drive with a connecting rod moves each φ0 and ωp by its third-order push
//! (`kapitza_core::model::slider_crank`, physics §5.1): they come from the balance with its
//! terms, started at the sine's φ0, with R the drive strength asked for (R_e there).

use kapitza_core::math;
use kapitza_core::model::slider_crank;
use kapitza_core::rig::config::RigConfig;

use crate::cmd::predict::{self, Args};
use crate::input::GeometryArgs;

/// A measured angle beyond 90° from the blade by more than this (degrees) is outside reach: a
/// rod resting on the body reads at the band's edge, to within the period mean's resolution.
pub const REACH_TOL_DEG: f64 = 1.0;

/// One stable equilibrium and its slow frequency.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Stable {
    /// φ0 in (−180°, 180°].
    pub phi0_deg: f64,
    /// ωp (rad/s).
    pub omega_p: f64,
}

/// The equilibrium set beside a measurement, and the rest.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Prediction {
    /// φ0 in (−180°, 180°].
    pub phi0_deg: f64,
    /// ωp (rad/s).
    pub omega_p: f64,
    /// The other stable equilibria at this R and θd.
    pub other_stable: Vec<Stable>,
    /// The measured angle lies outside the reachable band (more than 90° from the blade).
    pub outside_reach: bool,
}

/// Every stable equilibrium of `cfg`'s pendulum at drive strength `r` and drive angle
/// `theta_d_deg`, each with whether it is within 90° of the drive.
pub fn stable(cfg: &RigConfig, r: f64, theta_d_deg: f64) -> Vec<(Stable, bool)> {
    let args = Args {
        r: Some(r),
        angle: Some(theta_d_deg),
        rest_angle: None,
        geometry: GeometryArgs {
            rod: None,
            point: None,
        },
        amplitude: None,
        omega: None,
        gravity: cfg.gravity,
        json: false,
    };
    let Ok(report) = predict::compute(&args) else {
        return Vec::new();
    };
    let omega0 = cfg.omega0();
    report
        .equilibria
        .iter()
        .filter(|e| e.stable)
        .filter_map(|e| {
            let s = match cfg.slider_crank() {
                None => Stable {
                    phi0_deg: e.angle_deg,
                    omega_p: e.omega_p_over_omega0? * omega0,
                },
                Some(crank) => {
                    let r1 = r / crank.strength_gain();
                    let theta_d = math::to_rad(theta_d_deg);
                    let guess = math::to_rad(e.angle_deg);
                    let phi0 = slider_crank::equilibrium_near(guess, theta_d, r1, Some(&crank))?;
                    let k = slider_crank::stiffness(phi0, theta_d, r1, Some(&crank));
                    if k <= 0.0 {
                        return None;
                    }
                    Stable {
                        phi0_deg: math::wrap_deg(math::to_deg(phi0)),
                        omega_p: omega0 * k.sqrt(),
                    }
                }
            };
            Some((s, e.within_90_of_drive))
        })
        .collect()
}

/// |φ − θd| folded to [0°, 180°].
fn apart(a_deg: f64, b_deg: f64) -> f64 {
    math::wrap_deg(a_deg - b_deg).abs()
}

/// The prediction for `cfg`'s pendulum at drive strength `r` and drive angle `theta_d_deg`,
/// beside the slow angle `measured_deg` if there is one: `None` when there is no stable
/// equilibrium to show (none measured, and none within 90° of the drive: the rod would fall
/// over).
pub fn predict(
    cfg: &RigConfig,
    r: f64,
    theta_d_deg: f64,
    measured_deg: Option<f64>,
) -> Option<Prediction> {
    let all = stable(cfg, r, theta_d_deg);
    let pick = match measured_deg {
        Some(m) => all
            .iter()
            .enumerate()
            .min_by(|a, b| apart(a.1 .0.phi0_deg, m).total_cmp(&apart(b.1 .0.phi0_deg, m))),
        None => all
            .iter()
            .enumerate()
            .filter(|(_, (_, reachable))| *reachable)
            .min_by(|a, b| {
                apart(a.1 .0.phi0_deg, theta_d_deg).total_cmp(&apart(b.1 .0.phi0_deg, theta_d_deg))
            }),
    };
    let (i, (best, _)) = pick?;
    Some(Prediction {
        phi0_deg: best.phi0_deg,
        omega_p: best.omega_p,
        other_stable: all
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, (s, _))| *s)
            .collect(),
        outside_reach: measured_deg.is_some_and(|m| outside_reach(m, theta_d_deg)),
    })
}

/// The angle `phi_deg` lies outside the band the body leaves the rod at drive angle
/// `theta_d_deg`.
pub fn outside_reach(phi_deg: f64, theta_d_deg: f64) -> bool {
    apart(phi_deg, theta_d_deg) > 90.0 + REACH_TOL_DEG
}

#[cfg(test)]
mod tests {
    use super::*;
    use kapitza_core::simrig::Params;

    #[test]
    fn closed_forms() {
        let cfg = Params::DEMO.configured();
        // physics §3: θd = 90°, R > 1 → φ0 = arccos(1/R) = 55.15° at R = 1.75.
        let p = predict(&cfg, 1.75, 90.0, None).unwrap();
        assert!((p.phi0_deg - (1.0f64 / 1.75).acos().to_degrees()).abs() < 1e-6);
        // physics §3: θd = 180°: inverted, ωp = ω0 √(R − 1); rod ω0 = √(3g/(2L)).
        let p = predict(&cfg, 2.2, 180.0, None).unwrap();
        let w0 = (3.0 * 9.81 / (2.0 * 0.25f64)).sqrt();
        assert!((p.phi0_deg.abs() - 180.0).abs() < 1e-6);
        assert!((p.omega_p - w0 * 1.2f64.sqrt()).abs() < 1e-9 * w0);
        // physics §3: at rest (R = 0) the pendulum hangs, ωp = ω0.
        let p = predict(&cfg, 0.0, 90.0, None).unwrap();
        assert!(p.phi0_deg.abs() < 1e-9 && (p.omega_p - w0).abs() < 1e-9 * w0);
        // physics §3: R_sn(150°) = (0.5^(2/3) + 0.866^(2/3))^(3/2) = 1.908 > 1.75, so only two
        // equilibria; the equilibrium condition changes sign between φ = −30° (−0.5) and 0°
        // (+0.758), so the stable one hangs there, more than 90° from the drive.
        assert!(predict(&cfg, 1.75, 150.0, None).is_none());
    }

    #[test]
    fn a_connecting_rod_moves_the_prediction_by_its_push() {
        // The demo rod on a 60 mm connecting rod at R = 1.75 (as asked: R_e), θd = 90°: the
        // balance with the rod's terms (model::slider_crank, checked there against the full
        // equation) rests 0.30° past arccos(1/R) = 55.15°, the push of its third order.
        let mut cfg = Params::DEMO.configured();
        cfg.connecting_rod = 0.06;
        let p = predict(&cfg, 1.75, 90.0, None).unwrap();
        let sine = (1.0f64 / 1.75).acos().to_degrees();
        assert!((p.phi0_deg - sine - 0.30).abs() < 0.01, "{}", p.phi0_deg);
        // ωp from the same balance stays within 1 % of the sine's: the push is third order.
        let q = predict(&Params::DEMO.configured(), 1.75, 90.0, None).unwrap();
        assert!((p.omega_p / q.omega_p - 1.0).abs() < 0.01);
    }

    #[test]
    fn beside_a_measurement_the_nearest_stable_one_and_the_others() {
        let cfg = Params::DEMO.configured();
        // physics §3, θd = 90°, R = 1.75: stable at ±arccos(1/R) = ±55.15°; only + is within
        // 90° of the drive. Tolerance: rounding of the closed-form roots.
        let a = (1.0f64 / 1.75).acos().to_degrees();
        let none = predict(&cfg, 1.75, 90.0, None).unwrap();
        assert!((none.phi0_deg - a).abs() < 1e-6 && !none.outside_reach);
        assert_eq!(none.other_stable.len(), 1);
        assert!((none.other_stable[0].phi0_deg + a).abs() < 1e-6);
        // Measured at −50°: the −55.15° one, outside reach (140° from the blade), the other listed.
        let p = predict(&cfg, 1.75, 90.0, Some(-50.0)).unwrap();
        assert!((p.phi0_deg + a).abs() < 1e-6, "{p:?}");
        assert!(p.outside_reach);
        assert!((p.other_stable[0].phi0_deg - a).abs() < 1e-6);
        // ωp is the same at both by symmetry: ω0 √(R − 1/R) (physics §3, θd = 90°).
        let w0 = (3.0 * 9.81 / (2.0 * 0.25f64)).sqrt();
        let wp = w0 * (1.75 - 1.0 / 1.75f64).sqrt();
        assert!((p.omega_p - wp).abs() < 1e-9 * wp);
        assert!((p.other_stable[0].omega_p - wp).abs() < 1e-9 * wp);
        // Measured at 60°: within reach, the reachable one.
        let p = predict(&cfg, 1.75, 90.0, Some(60.0)).unwrap();
        assert!((p.phi0_deg - a).abs() < 1e-6 && !p.outside_reach);
        // The band's edge: 90° from the blade (a rod on the body) is within reach, 92° is not.
        assert!(!outside_reach(0.0, 90.0) && !outside_reach(180.0, 90.0));
        assert!(outside_reach(-2.0, 90.0) && outside_reach(-178.0, 90.0));
        // R_sn(150°) = 1.908 > 1.75: no reachable stable equilibrium (see closed_forms), but
        // beside a measured hanging rod the stable one near it is shown, outside reach.
        let p = predict(&cfg, 1.75, 150.0, Some(-10.0)).unwrap();
        assert!(p.outside_reach && p.other_stable.is_empty(), "{p:?}");
    }
}
