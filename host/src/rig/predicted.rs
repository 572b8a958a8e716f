//! What the averaged theory expects of the configured pendulum at a given R and θd: the same
//! computation as `kapitza predict`, narrowed to the equilibrium a demo rig can reach.
//!
//! ```text
//! φ0: the stable equilibrium within 90° of the drive direction θd (physics §3: the actuator body
//!     keeps the rod from the others); the nearest to θd if there are two
//! ωp = ω0 √(cos φ0 + R cos 2(φ0 − θd))      (physics §3)
//! ```
//! A drive with a connecting rod moves both by its third-order push
//! (`kapitza_core::model::slider_crank`, physics §5.1): φ0 and ωp then come from the balance with
//! its terms, started at the sine's φ0, with R the drive strength asked for (R_e there).

use kapitza_core::math;
use kapitza_core::model::slider_crank;
use kapitza_core::rig::config::RigConfig;

use crate::cmd::predict::{self, Args};
use crate::input::GeometryArgs;

/// The reachable stable equilibrium and its slow frequency.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Prediction {
    /// φ0 in (−180°, 180°].
    pub phi0_deg: f64,
    /// ωp (rad/s).
    pub omega_p: f64,
}

/// The prediction for `cfg`'s pendulum at drive strength `r` and drive angle `theta_d_deg`;
/// `None` when no stable equilibrium is within 90° of the drive (the rod would fall over).
pub fn predict(cfg: &RigConfig, r: f64, theta_d_deg: f64) -> Option<Prediction> {
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
    let report = predict::compute(&args).ok()?;
    let omega0 = cfg.omega0();
    report
        .equilibria
        .iter()
        .filter(|e| e.stable && e.within_90_of_drive)
        .min_by(|a, b| {
            let da = math::wrap_deg(a.angle_deg - theta_d_deg).abs();
            let db = math::wrap_deg(b.angle_deg - theta_d_deg).abs();
            da.total_cmp(&db)
        })
        .and_then(|e| match cfg.slider_crank() {
            None => Some(Prediction {
                phi0_deg: e.angle_deg,
                omega_p: e.omega_p_over_omega0? * omega0,
            }),
            Some(crank) => {
                let r1 = r / crank.strength_gain();
                let theta_d = math::to_rad(theta_d_deg);
                let guess = math::to_rad(e.angle_deg);
                let phi0 = slider_crank::equilibrium_near(guess, theta_d, r1, Some(&crank))?;
                let k = slider_crank::stiffness(phi0, theta_d, r1, Some(&crank));
                (k > 0.0).then(|| Prediction {
                    phi0_deg: math::wrap_deg(math::to_deg(phi0)),
                    omega_p: omega0 * k.sqrt(),
                })
            }
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use kapitza_core::simrig::Params;

    #[test]
    fn closed_forms() {
        let cfg = Params::DEMO.configured();
        // physics §3: θd = 90°, R > 1 → φ0 = arccos(1/R) = 55.15° at R = 1.75.
        let p = predict(&cfg, 1.75, 90.0).unwrap();
        assert!((p.phi0_deg - (1.0f64 / 1.75).acos().to_degrees()).abs() < 1e-6);
        // physics §3: θd = 180°: inverted, ωp = ω0 √(R − 1); rod ω0 = √(3g/(2L)).
        let p = predict(&cfg, 2.2, 180.0).unwrap();
        let w0 = (3.0 * 9.81 / (2.0 * 0.25f64)).sqrt();
        assert!((p.phi0_deg.abs() - 180.0).abs() < 1e-6);
        assert!((p.omega_p - w0 * 1.2f64.sqrt()).abs() < 1e-9 * w0);
        // physics §3: at rest (R = 0) the pendulum hangs, ωp = ω0.
        let p = predict(&cfg, 0.0, 90.0).unwrap();
        assert!(p.phi0_deg.abs() < 1e-9 && (p.omega_p - w0).abs() < 1e-9 * w0);
        // physics §3: R_sn(150°) = (0.5^(2/3) + 0.866^(2/3))^(3/2) = 1.908 > 1.75, so only two
        // equilibria; the equilibrium condition changes sign between φ = −30° (−0.5) and 0°
        // (+0.758), so the stable one hangs there, more than 90° from the drive.
        assert!(predict(&cfg, 1.75, 150.0).is_none());
    }

    #[test]
    fn a_connecting_rod_moves_the_prediction_by_its_push() {
        // The demo rod on a 60 mm connecting rod at R = 1.75 (as asked: R_e), θd = 90°: the
        // balance with the rod's terms (model::slider_crank, checked there against the full
        // equation) rests 0.30° past arccos(1/R) = 55.15°, the push of its third order.
        let mut cfg = Params::DEMO.configured();
        cfg.connecting_rod = 0.06;
        let p = predict(&cfg, 1.75, 90.0).unwrap();
        let sine = (1.0f64 / 1.75).acos().to_degrees();
        assert!((p.phi0_deg - sine - 0.30).abs() < 0.01, "{}", p.phi0_deg);
        // ωp from the same balance stays within 1 % of the sine's: the push is third order.
        let q = predict(&Params::DEMO.configured(), 1.75, 90.0).unwrap();
        assert!((p.omega_p / q.omega_p - 1.0).abs() < 0.01);
    }
}
