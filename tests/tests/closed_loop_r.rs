//! Closed-loop R in virtual time (`kapitza_test_support::closed_loop`): a stroke typed in 1.6 %
//! short (12.5 mm for the true 12.7 mm) makes every R 3.2 % high open loop; with the loop on, the
//! rig trims ω until the R it measures in situ is the one asked for, and off it returns to open
//! loop.

use kapitza_core::math;
use kapitza_core::rig::closed_loop::ClosedLoopR as Settings;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::dds::{omega_of_word, word_from_omega};
use kapitza_core::rig::safety::Request;
use kapitza_test_support::closed_loop::Sim;

const TRUE_A: f64 = 0.0127;
const R: f64 = 1.75;

/// The reference rod on a stroke configured as 12.5 mm while the plant's is 12.7 mm, at θd = 90°,
/// driven at R = 1.75 (as configured) from near its equilibrium, settled.
fn settled_open_loop(omega_max: f64) -> (Sim, RigConfig) {
    let mut cfg = RigConfig {
        amplitude: 0.0125,
        ..RigConfig::REFERENCE
    };
    cfg.limits.omega_max = omega_max;
    let mut sim = Sim::new(cfg, 90.0, 0.8, math::to_rad(55.0), 0);
    sim.plant.amplitude = TRUE_A;
    let omega = cfg.omega_for_r(R).unwrap();
    sim.rig.r_asked(R);
    sim.rig.request(Request::Start { omega }).unwrap();
    assert!(sim.run_until(20.0, |s| s.last.is_some_and(|r| r.steady)));
    sim.run(0.5);
    sim.hold = None;
    assert!(sim.run_until(60.0, |s| s.rig.estimate().settled
        && s.rig.estimate().r.is_some()));
    (sim, cfg)
}

fn phi0_deg(sim: &Sim) -> f64 {
    math::to_deg(sim.rig.estimate().equilibrium.unwrap().to_rad())
}

fn r_in_situ(sim: &Sim) -> f64 {
    sim.rig.estimate().r.unwrap().0.to_num()
}

#[test]
fn trims_a_misconfigured_stroke_to_the_asked_r_and_back_to_open_loop() {
    // Truth (physics §3, θd = 90°): φ0 = arccos(1/R). Open loop the true R is 1.75·(12.7/12.5)² =
    // 1.806 (the DDS's quantised ω adds < 1e-6), φ0 = 56.39° instead of 55.15°.
    let (mut sim, cfg) = settled_open_loop(RigConfig::REFERENCE.limits.omega_max);
    let r_open = R * (TRUE_A / cfg.amplitude).powi(2);
    let want = math::to_deg(math::acos(1.0 / R));
    let open = phi0_deg(&sim);
    assert!(
        (open - math::to_deg(math::acos(1.0 / r_open))).abs() < 0.2,
        "{open}"
    );
    assert!((open - want).abs() > 1.0, "open loop {open}° vs {want}°");
    let on = Settings {
        enabled: true,
        band: 0.005,
        rate_max: 0.1,
    };
    sim.rig.set_closed_loop(on, sim.t_us());
    // Trims wait for the pendulum to settle after each step (about 3 s each).
    sim.run(40.0);
    assert!(sim.rig.estimate().settled);
    let closed = phi0_deg(&sim);
    // Within the band: |R − 1.75| ≤ 0.005 (plus the in-situ R's own 2e-4, estimator::settle),
    // which is 0.12° of φ0 at R = 1.75 (calib::tolerance's sensitivity).
    assert!((r_in_situ(&sim) - R).abs() < 0.006, "R {}", r_in_situ(&sim));
    assert!(
        (closed - want).abs() < 0.2,
        "closed loop {closed}° vs {want}°"
    );
    // The R_cmd it settled on is the one the true stroke needs, R·(12.5/12.7)².
    let cmd = sim.rig.r_trim().commanded();
    assert!(
        (cmd / (R / (r_open / R)) - 1.0).abs() < 0.005,
        "R_cmd {cmd}"
    );
    eprintln!(
        "open loop φ0 {open:.3}°, closed loop {closed:.3}° (theory {want:.3}°), R in situ {:.4}, \
         R_cmd {cmd:.4}",
        r_in_situ(&sim)
    );
    // Off: back to the open-loop ω of R = 1.75.
    sim.rig.set_closed_loop(
        Settings {
            enabled: false,
            ..on
        },
        sim.t_us(),
    );
    let open_word = word_from_omega(cfg.omega_for_r(R).unwrap()).unwrap();
    assert_eq!(sim.rig.supervisor().target_word(), open_word);
    sim.run(15.0);
    assert_eq!(sim.rig.supervisor().target_word(), open_word);
    assert!((phi0_deg(&sim) - open).abs() < 0.2, "{}", phi0_deg(&sim));
}

#[test]
fn never_trims_past_the_omega_limit() {
    // ω_max just above the open-loop ω (144.7·√1.75 = 191.4 rad/s): a stroke configured too
    // *large* would need ω up, so configure 12.9 mm for the true 12.7 mm and cap ω at 192.
    let mut cfg = RigConfig {
        amplitude: 0.0129,
        ..RigConfig::REFERENCE
    };
    let omega = cfg.omega_for_r(R).unwrap();
    cfg.limits.omega_max = omega + 1.0;
    let mut sim = Sim::new(cfg, 90.0, 0.8, math::to_rad(55.0), 0);
    sim.plant.amplitude = TRUE_A;
    sim.rig.r_asked(R);
    sim.rig.request(Request::Start { omega }).unwrap();
    sim.rig.set_closed_loop(
        Settings {
            enabled: true,
            band: 0.005,
            rate_max: 0.1,
        },
        0,
    );
    sim.run(4.0);
    sim.hold = None;
    let mut highest: f64 = 0.0;
    sim.run_until(40.0, |s| {
        highest = highest.max(omega_of_word(s.rig.supervisor().target_word()));
        highest = highest.max(s.rig.dds().omega().to_num());
        false
    });
    assert!(highest <= cfg.limits.omega_max + 1e-3, "{highest}");
    // It did trim up, to the limit.
    assert!(highest > omega + 0.5, "{highest} vs {omega}");
}
