//! The simulator against closed forms and the averaged theory (SPEC §3–5).

use kapitza_core::math;
use kapitza_core::model::{equilibria, DriveAngle, Geometry};
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::{
    DriveFrequency, DriveSpec, Effects, Fidelity, FidelityChoice, RunLength, Viscous,
};
use kapitza_core::sim::{simulate, Format, Method, Options, Outcome, Scene};

/// The example: rod 0.20 m, A = 8.9 mm, ω = 330 rad/s, θd = 135°, Q = 50, from 100°.
fn tilted() -> Scene {
    Scene {
        pendulum: Geometry::rod(0.20).unwrap(),
        drive: DriveSpec {
            amplitude: 0.0089,
            frequency: DriveFrequency::Omega(330.0),
            angle: DriveAngle::from_deg(135.0).unwrap(),
        },
        gravity: 9.81,
        initial_angle: math::to_rad(100.0),
        initial_rate: 0.0,
        length: RunLength::Periods(3000.0),
        fidelity: FidelityChoice::Fixed(Fidelity::Full),
        effects: Effects {
            viscous: Some(Viscous::Q(20.0)),
            ..Effects::default()
        },
    }
}

fn rest_deg(o: Outcome) -> f64 {
    match o {
        Outcome::Rest { angle } => math::to_deg(angle),
        other => panic!("expected rest, got {other:?}"),
    }
}

#[test]
fn tilted_rest_matches_averaged_equilibrium() {
    let scene = tilted();
    let p = scene.physical().unwrap();
    // Averaged theory (SPEC §3): the stable equilibrium within 90° of θd = 135°.
    let eq = equilibria(p.r, scene.drive.angle).unwrap();
    let want = eq
        .stable()
        .find(|e| e.within_90_of_drive)
        .map(|e| math::to_deg(e.angle))
        .unwrap();
    let full = simulate(&scene, &Options::default(), &mut Discard).unwrap();
    let got = rest_deg(full.outcome);
    // Averaging error is O((ω0/ω)²) ≈ 7e-4 relative here (ω/ω0 ≈ 38): allow 0.3°.
    assert!(
        (got - want).abs() < 0.3,
        "full {got}° vs averaged theory {want}°"
    );
    // The averaged model itself must land on the theory's root to the classifier's resolution.
    let mut avg = scene;
    avg.fidelity = FidelityChoice::Fixed(Fidelity::Averaged);
    let a = simulate(&avg, &Options::default(), &mut Discard).unwrap();
    assert!((rest_deg(a.outcome) - want).abs() < 0.01, "{:?}", a.outcome);
    // ... at a fraction of the cost (no fast drive to resolve).
    assert!(
        a.work.rhs_evals * 5 < full.work.rhs_evals,
        "{} vs {}",
        a.work.rhs_evals,
        full.work.rhs_evals
    );
}

#[test]
fn rk4_and_f32_agree_on_the_outcome() {
    let scene = tilted();
    let reference = rest_deg(
        simulate(&scene, &Options::default(), &mut Discard)
            .unwrap()
            .outcome,
    );
    let rk4 = Options {
        method: Method::Rk4 {
            steps_per_period: 32.0,
        },
        ..Options::default()
    };
    let got = rest_deg(simulate(&scene, &rk4, &mut Discard).unwrap().outcome);
    assert!((got - reference).abs() < 0.01, "rk4 {got} vs {reference}");
    let f32 = Options {
        format: Format::F32,
        method: Method::Dop853 {
            rtol: 1e-6,
            atol: 1e-6,
        },
        ..Options::default()
    };
    let got = rest_deg(simulate(&scene, &f32, &mut Discard).unwrap().outcome);
    assert!((got - reference).abs() < 0.01, "f32 {got} vs {reference}");
}
