//! The simulator against closed forms and the averaged theory (physics §3–5).

use kapitza_core::cases;
use kapitza_core::math;
use kapitza_core::model::{equilibria, DriveAngle, Geometry};
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::{
    DriveFrequency, DriveSpec, Effects, Fidelity, FidelityChoice, RunLength, Viscous,
};
use kapitza_core::sim::{simulate, Format, Method, Options, Outcome, Scene};

/// The tilted example scene ([`cases::TILTED_135`]) for 3000 drive periods.
fn tilted() -> Scene {
    Scene::from_case(
        &cases::TILTED_135,
        RunLength::Periods(3000.0),
        Fidelity::Full,
    )
    .unwrap()
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
    // Averaged theory (physics §3): the stable equilibrium within 90° of θd = 135°.
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

/// An undamped averaged run: the symplectic methods and DOP853 agree on the end state.
fn undamped_averaged() -> Scene {
    let mut s = tilted();
    s.effects.viscous = None;
    s.fidelity = FidelityChoice::Fixed(Fidelity::Averaged);
    s.length = RunLength::Periods(500.0);
    s
}

#[test]
fn symplectic_methods_agree_with_dop853() {
    use kapitza_core::integrate::Symplectic;
    let scene = undamped_averaged();
    let quiet = |method| Options {
        method,
        classify: false,
        ..Options::default()
    };
    let reference = simulate(
        &scene,
        &quiet(Method::Dop853 {
            rtol: 1e-12,
            atol: 1e-12,
        }),
        &mut Discard,
    )
    .unwrap();
    // Halving the step must cut the error by 2^order (Verlet 2, Yoshida 4 and 6: the methods'
    // orders), measured against DOP853 at rtol 1e-12.
    // Steps per drive period chosen so each method is in its asymptotic regime (error < 1e-3).
    for (scheme, order, spp) in [
        (Symplectic::Verlet, 2, 8.0),
        (Symplectic::Yoshida4, 4, 2.0),
        (Symplectic::Yoshida6, 6, 1.0),
    ] {
        let err = |spp: f64| {
            let m = Method::Symplectic {
                scheme,
                steps_per_period: spp,
            };
            (simulate(&scene, &quiet(m), &mut Discard).unwrap().end.theta - reference.end.theta)
                .abs()
        };
        let (coarse, fine) = (err(spp), err(2.0 * spp));
        let measured = (coarse / fine).log2();
        std::println!("{scheme:?}: {coarse:.3e} -> {fine:.3e}, order {measured:.2}");
        assert!(
            (measured - order as f64).abs() < 0.3,
            "{scheme:?}: order {measured}"
        );
    }
}

#[test]
fn symplectic_refuses_damping() {
    use kapitza_core::integrate::Symplectic;
    let o = Options {
        method: Method::Symplectic {
            scheme: Symplectic::Verlet,
            steps_per_period: 20.0,
        },
        ..Options::default()
    };
    assert!(matches!(
        simulate(&tilted(), &o, &mut Discard),
        Err(kapitza_core::sim::SimError::Unsupported(_))
    ));
}

#[test]
fn one_turn_per_period_is_rotation() {
    // A hanging point pendulum spun at ω = 15 rad/s under a vertical drive locks into one turn per
    // drive period; its wrapped strobes are all equal, which must not read as rest.
    let scene = Scene {
        pendulum: Geometry::point_mass(0.2).unwrap(),
        drive: DriveSpec {
            amplitude: 0.06,
            frequency: DriveFrequency::Omega(15.0),
            angle: DriveAngle::from_deg(0.0).unwrap(),
        },
        gravity: 9.81,
        initial_angle: 0.0,
        initial_rate: 15.0,
        length: RunLength::Periods(600.0),
        fidelity: FidelityChoice::Fixed(Fidelity::Full),
        effects: Effects {
            viscous: Some(Viscous::Q(20.0)),
            ..Effects::default()
        },
    };
    let r = simulate(&scene, &Options::default(), &mut Discard).unwrap();
    assert!(
        matches!(
            r.outcome,
            Outcome::Rotation {
                turns: 1,
                periods: 1,
                ..
            }
        ),
        "{:?}",
        r.outcome
    );
    // `periods = 600` gives exactly 600 strobes (no loss to rounding).
    assert_eq!(r.strobes, 600);
}
