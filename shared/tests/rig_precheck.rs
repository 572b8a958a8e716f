//! The pre-run check against the simulated rig (`simrig`): a healthy bench starts after it;
//! each bench fault a lab meets on first power-up — the pendulum sensor's line stuck low, the
//! crank encoder reversed, the motor jammed, the current sense offset — is refused with its
//! verdict and the drive never starts; a calibration that matches the fault lets it pass.

use kapitza_core::link::message::{Check, Fault, Mode, Verdict};
use kapitza_core::link::{Request, Response};
use kapitza_core::simrig::sensor::Line;
use kapitza_core::simrig::Params;

use kapitza_test_support::sim_bench::Bench;

#[test]
fn a_healthy_bench_passes_and_starts() {
    let mut b = Bench::healthy(Params::DEMO);
    let s = b.start();
    assert_eq!(s.check, Some(Check::Passed));
    assert_eq!(s.mode, Mode::Running);
    // The whole check is 600 ms of rig time (precheck: 100 + 300 + 200 ms).
    let t = b.sim.seconds();
    assert!((0.64..0.67).contains(&t), "{t}");
}

#[test]
fn a_reversed_crank_encoder_is_refused_and_a_calibrated_sign_passes() {
    let mut p = Params::DEMO;
    p.crank_sign = -1.0;
    let mut b = Bench::healthy(p);
    let s = b.start();
    // The demo motor turns 0.1 · 450 = 45 rad/s under the test pulse: read backwards.
    match s.check {
        Some(Check::Failed(Verdict::CrankReversed { speed })) => {
            let w = f64::from(speed) / 65_536.0;
            assert!((-46.0..-40.0).contains(&w), "{w}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(s.mode, Mode::Idle);
    let mut cfg = p.configured();
    cfg.calibration.crank_sign = -1;
    assert_eq!(Bench::new(p, cfg).start().check, Some(Check::Passed));
}

#[test]
fn swapped_motor_leads_are_refused_as_reversed() {
    let mut p = Params::DEMO;
    p.motor.direction = -1.0;
    let s = Bench::healthy(p).start();
    assert!(
        matches!(s.check, Some(Check::Failed(Verdict::CrankReversed { .. }))),
        "{s:?}"
    );
}

#[test]
fn a_jammed_motor_is_refused_as_stalled() {
    let mut p = Params::DEMO;
    p.stalled = true;
    let s = Bench::healthy(p).start();
    assert_eq!(
        s.check,
        Some(Check::Failed(Verdict::CrankStalled { speed: 0 }))
    );
    assert_eq!(s.mode, Mode::Idle);
}

#[test]
fn a_current_offset_is_refused_until_calibrated() {
    // 0.5 A at rest against the reference 3 A trip: beyond the 0.3 A a check accepts.
    let mut p = Params::DEMO;
    p.current_offset = 0.5;
    let s = Bench::healthy(p).start();
    match s.check {
        Some(Check::Failed(Verdict::CurrentOffset { amps })) => {
            // 0.5 A in the ADC's 1.17 mA counts (Calibration::DEFAULT's scale).
            let a = f64::from(amps) / 65_536.0;
            assert!((a - 0.5).abs() < 2e-3, "{a}");
        }
        other => panic!("{other:?}"),
    }
    // The offset in counts, as a calibration would measure it: 0.5 A / (77/65536 A a count).
    let mut cfg = p.configured();
    cfg.calibration.current_offset = 0.5 / (77.0 / 65_536.0);
    assert_eq!(Bench::new(p, cfg).start().check, Some(Check::Passed));
}

#[test]
fn a_sensor_line_stuck_low_is_refused_as_not_ready() {
    // A cut cable with MISO floating low reads 0x0000: valid frames, angle 0 — but no
    // diagnostics say the sensor is ready.
    let mut p = Params::DEMO;
    p.sensor_line = Line::CutPulledDown;
    let s = Bench::healthy(p).start();
    assert_eq!(s.check, Some(Check::Failed(Verdict::SensorNotReady)));
}

#[test]
fn a_sensor_that_stops_answering_during_the_check_fails_it() {
    // Cut (MISO pulled up, as on the board) while the check rests: the sensor's driver fails
    // after 32 samples and latches the sensor fault, which aborts the check.
    let mut b = Bench::healthy(Params::DEMO);
    assert_eq!(
        b.ask(Request::SetDrive {
            r: 2 << 16,
            theta_d_deg: 0
        }),
        Response::Ok
    );
    b.sim.run(0.02);
    b.sim.sensor().line = Line::CutPulledUp;
    b.sim.run(0.7);
    let s = b.status();
    assert_eq!(s.check, Some(Check::Failed(Verdict::Aborted)));
    assert_eq!(s.mode, Mode::Faulted(Fault::Sensor));
}

#[test]
fn a_missing_sensor_refuses_the_start_at_once() {
    // No sensor at power-up (MISO pulled up): the sensor fault is latched before any start,
    // so the start is refused with it and no check runs.
    let mut p = Params::DEMO;
    p.sensor_line = Line::CutPulledUp;
    let mut b = Bench::healthy(p);
    let r = b.ask(Request::SetDrive {
        r: 2 << 16,
        theta_d_deg: 0,
    });
    assert_eq!(
        r,
        Response::Refused(kapitza_core::link::Reason::Faulted(Fault::Sensor))
    );
    assert_eq!(b.status().check, None);
}

#[test]
fn a_stop_aborts_the_check() {
    let mut b = Bench::healthy(Params::DEMO);
    b.ask(Request::SetDrive {
        r: 2 << 16,
        theta_d_deg: 0,
    });
    b.sim.run(0.2);
    assert_eq!(b.ask(Request::Stop), Response::Ok);
    b.sim.run(0.6);
    let s = b.status();
    assert_eq!(s.check, Some(Check::Failed(Verdict::Aborted)));
    assert_eq!(s.mode, Mode::Idle);
}
