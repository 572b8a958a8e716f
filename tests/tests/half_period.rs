//! θd and θd + 180° are the same shaking line half a drive period apart (physics §3: only 2θd
//! enters), so with a purely sinusoidal drive and no ramp a settled outcome must not change its
//! kind between them. The scenes here are the shipped ones whose attractor does not depend on
//! the release phase (measured: `kapitza simulate FILE --set drive.angle_deg=θd±180 --json`;
//! subharmonic-4 is left out because there the shifted release lands in a rotation, another
//! attractor of the same equation, and coulomb-stick because its resting angle depends on
//! where the pendulum happens to stop within the sticking band).

mod shipped;

use serde_json::Value;

fn run(file: &str, angle_deg: f64) -> Value {
    shipped::simulate(file, &[&format!("drive.angle_deg={angle_deg}")])
}

/// Angle difference in degrees, wrapped to [−180, 180).
fn wrapped(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

#[test]
fn outcome_kind_is_the_same_half_a_period_later() {
    for (file, angle) in [
        ("flutter.toml", 180.0),
        ("kapitza-inverted.toml", 180.0),
        ("horizontal-r1.75.toml", 90.0),
        ("tilted-135.toml", 135.0),
        ("rotation.toml", 180.0),
    ] {
        let (a, b) = (run(file, angle), run(file, angle - 180.0));
        assert_eq!(
            a["outcome"]["kind"],
            b["outcome"]["kind"],
            "{file}: {} at {angle}°, {} at {}°",
            a["outcome"],
            b["outcome"],
            angle - 180.0
        );
        if let (Some(x), Some(y)) = (
            a["outcome"]["angle_deg"].as_f64(),
            b["outcome"]["angle_deg"].as_f64(),
        ) {
            // Same attractor: the centre agrees to the classifier's resolution, 2e-3 rad
            // (0.115°, kapitza_core::sim::classify::TOL).
            assert!(wrapped(x, y).abs() < 0.115, "{file}: {x}° against {y}°");
        }
    }
}

#[test]
fn shipped_flutter_scene_flutters_about_180_at_drive_angle_0() {
    // The flutter scene's expectation (flutter about 180°, physics §4 upper boundary) holds for the
    // same shaking line strobed half a period later.
    let v = run("flutter.toml", 0.0);
    assert_eq!(v["outcome"]["kind"], "flutter", "{}", v["outcome"]);
    let centre = v["outcome"]["angle_deg"].as_f64().unwrap();
    // The scene's own tolerance, expect.tolerance_deg = 0.5.
    assert!(wrapped(centre, 180.0).abs() < 0.5, "{centre}");
}
