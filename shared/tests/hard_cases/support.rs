//! Scenes and helpers shared by the cases.

use kapitza_core::math;
use kapitza_core::model::{DriveAngle, Geometry};
use kapitza_core::sim::scene::{
    DriveFrequency, DriveSpec, Effects, Fidelity, FidelityChoice, RunLength,
};
use kapitza_core::sim::Scene;

/// A scene with the given pendulum and drive, full model, no effects, from rest.
pub fn scene(geometry: Geometry, amplitude: f64, omega: f64, drive_deg: f64) -> Scene {
    Scene {
        pendulum: geometry,
        drive: DriveSpec {
            amplitude,
            frequency: DriveFrequency::Omega(omega),
            angle: DriveAngle::from_deg(drive_deg).unwrap(),
        },
        gravity: 9.81,
        initial_angle: 0.0,
        initial_rate: 0.0,
        length: RunLength::Periods(1000.0),
        fidelity: FidelityChoice::Fixed(Fidelity::Full),
        effects: Effects::default(),
    }
}

/// a − b as an angle, in (−π, π].
pub fn angle_diff(a: f64, b: f64) -> f64 {
    math::wrap_pi(a - b)
}
