//! Closed loop in virtual time: soft start, ramped change, soft stop, e-stop, link silence,
//! stall and over-current, with the rig logic driving the simulated motor and pendulum.

use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::safety::{Fault, Mode, Request, StopReason};
use kapitza_test_support::closed_loop::Sim;

fn sim() -> Sim {
    // Pendulum hanging, drive along 90°: the pendulum is irrelevant here, the motor is the point.
    let mut s = Sim::new(RigConfig::REFERENCE, 90.0, 0.8, 0.0, 0);
    s.hold = None;
    s
}

/// Crank speed now (rad/s), from the plant.
fn crank(s: &Sim) -> f64 {
    s.y[3]
}

#[test]
fn soft_start_ramps_at_the_limit_and_locks_phase() {
    // Start to 300 rad/s: the reference ramps at ≤ 60 rad/s² (the limit), so it takes
    // 300/60 = 5 s (+ the word rounding: the step is rounded down, 0.9 % slower at most);
    // the crank follows within the motor lag, and afterwards the phase error is small.
    let mut s = sim();
    s.rig.request(Request::Start { omega: 300.0 }).unwrap();
    let mut max_rate: f64 = 0.0;
    let mut prev = 0.0;
    let reached = s.run_until(10.0, |s| {
        let w: f64 = s.last.map_or(0.0, |r| r.ref_omega.to_num());
        max_rate = max_rate.max((w - prev) * 1000.0);
        prev = w;
        s.last.is_some_and(|r| r.steady)
    });
    assert!(reached);
    let t = s.seconds();
    assert!((5.0..5.1).contains(&t), "ramp took {t} s");
    assert!(max_rate <= 60.0 + 0.5, "reference rate {max_rate} rad/s²"); // ±1 LSB per ms
    s.run(2.0);
    assert!((crank(&s) - 300.0).abs() < 1.0, "crank {} rad/s", crank(&s));
    let e: f64 = s.last.unwrap().phase_error.to_num();
    assert!(e.abs() < 0.05, "phase error {e} rad");
}

#[test]
fn ramped_change_and_soft_stop() {
    let mut s = sim();
    s.rig.request(Request::Start { omega: 200.0 }).unwrap();
    s.run(5.0);
    s.rig.request(Request::SetOmega { omega: 260.0 }).unwrap();
    // 60 rad/s at 60 rad/s² takes 1 s: not there after 0.9 s, there after 1.2 s.
    s.run(0.9);
    let w: f64 = s.last.unwrap().ref_omega.to_num();
    assert!(w < 259.0, "{w}");
    s.run(0.3);
    let w: f64 = s.last.unwrap().ref_omega.to_num();
    assert!((w - 260.0).abs() < 0.01, "{w}");
    // A refused request changes nothing on the running rig.
    let before = *s.rig.supervisor();
    assert!(s.rig.request(Request::SetOmega { omega: 1e4 }).is_err());
    assert_eq!(*s.rig.supervisor(), before);
    // Soft stop: 260 rad/s at 60 rad/s² → 4.3 s to zero, then Idle.
    s.rig.request(Request::Stop).unwrap();
    s.run(4.0);
    assert_eq!(
        s.rig.supervisor().mode(),
        Mode::Stopping(StopReason::Requested)
    );
    s.run(1.0);
    assert_eq!(s.rig.supervisor().mode(), Mode::Idle);
    s.run(1.0);
    assert!(crank(&s).abs() < 5.0, "crank {}", crank(&s));
}

#[test]
fn estop_cuts_the_drive_at_once() {
    let mut s = sim();
    s.rig.request(Request::Start { omega: 250.0 }).unwrap();
    s.run(6.0);
    s.estop = true;
    s.run(0.002); // two control ticks
    let r = s.last.unwrap();
    assert_eq!(r.mode, Mode::Faulted(Fault::EStop));
    assert_eq!(r.duty.to_num::<f64>(), 0.0);
    assert_eq!(s.rig.dds().word(), 0);
    // The crank coasts down with the motor's lag only; the command stays 0 while pressed.
    s.run(1.0);
    assert!(crank(&s) < 250.0 * (-1.0f64 / 0.06).exp() + 1.0);
    assert!(s.rig.request(Request::ClearFault).is_err());
    assert!(s.rig.request(Request::Start { omega: 100.0 }).is_err());
    s.estop = false;
    s.run(0.01);
    s.rig.request(Request::ClearFault).unwrap();
    s.rig.request(Request::Start { omega: 100.0 }).unwrap();
    s.run(3.0);
    assert!((crank(&s) - 100.0).abs() < 2.0);
}

#[test]
fn silent_link_soft_stops() {
    let mut s = sim();
    s.rig.request(Request::Start { omega: 250.0 }).unwrap();
    s.run(5.0);
    s.heartbeat_every = None; // the laptop goes quiet
    s.run(1.05);
    assert_eq!(
        s.rig.supervisor().mode(),
        Mode::Stopping(StopReason::LinkSilent)
    );
    s.run(5.0);
    assert_eq!(s.rig.supervisor().mode(), Mode::Idle);
    assert_eq!(s.rig.supervisor().last_stop(), Some(StopReason::LinkSilent));
    s.heartbeat_every = Some(100); // back: it stays idle
    s.run(1.0);
    assert_eq!(s.rig.supervisor().mode(), Mode::Idle);
}

#[test]
fn jammed_crank_stops_by_over_current() {
    // A jammed crank draws V·duty/R = 12·0.5/2 = 3.0+ A (> 3 A) once the loop pushes the duty
    // up: the over-current stop (20 ms) fires before the stall stop (300 ms).
    let mut s = sim();
    s.rig.request(Request::Start { omega: 250.0 }).unwrap();
    s.run(6.0);
    s.plant.jammed = true;
    let stopped = s.run_until(1.0, |s| {
        matches!(s.rig.supervisor().mode(), Mode::Faulted(_))
    });
    assert!(stopped);
    assert_eq!(s.rig.supervisor().mode(), Mode::Faulted(Fault::OverCurrent));
}

#[test]
fn jammed_crank_at_low_speed_stops_by_stall() {
    // At 40 rad/s the loop's duty stays small (current < 3 A), so the stall guard fires:
    // crank < 30 % of the reference for 300 ms.
    let mut s = sim();
    s.rig.request(Request::Start { omega: 40.0 }).unwrap();
    s.run(3.0);
    s.plant.jammed = true;
    let t0 = s.seconds();
    let stopped = s.run_until(2.0, |s| {
        matches!(s.rig.supervisor().mode(), Mode::Faulted(_))
    });
    assert!(stopped);
    assert_eq!(s.rig.supervisor().mode(), Mode::Faulted(Fault::Stall));
    let dt = s.seconds() - t0;
    assert!((0.3..0.35).contains(&dt), "stall after {dt} s");
}
