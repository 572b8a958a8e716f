//! The safety supervisor: scripted cases (refusals, link silence, e-stop, stall, over-current, the
//! θd slew) and, as a state machine under random command and input sequences (proptest), no
//! sequence pushes the rig past its limits and a refused request changes nothing.

use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::dds::{word_from_omega, Dds};
use kapitza_core::rig::fixed::{Amps, Angle, RadPerSec};
use kapitza_core::rig::safety::{
    Fault, Inputs, Mode, Output, Refusal, Request, StopReason, Supervisor,
};
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Event {
    Req(Request),
    /// Control ticks with these inputs; `link` sends a message first.
    Ticks {
        n: u32,
        estop: bool,
        amps: f64,
        crank_frac: f64,
        link: bool,
    },
}

fn request() -> impl Strategy<Value = Request> {
    prop_oneof![
        (-50.0f64..600.0).prop_map(|omega| Request::Start { omega }),
        (-50.0f64..600.0).prop_map(|omega| Request::SetOmega { omega }),
        (-90.0f64..300.0).prop_map(|deg| Request::SetDriveAngle { deg }),
        Just(Request::Stop),
        Just(Request::ClearFault),
        Just(Request::Start { omega: f64::NAN }),
    ]
}

fn event() -> impl Strategy<Value = Event> {
    prop_oneof![
        request().prop_map(Event::Req),
        (
            1u32..2_000,
            prop::bool::weighted(0.05),
            0.0f64..4.0,
            0.0f64..1.2,
            prop::bool::weighted(0.8)
        )
            .prop_map(|(n, estop, amps, crank_frac, link)| Event::Ticks {
                n,
                estop,
                amps,
                crank_frac,
                link
            }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn limits_hold_and_refusals_change_nothing(
        t0: u32,
        events in prop::collection::vec(event(), 1..40),
    ) {
        let cfg = RigConfig::REFERENCE;
        let d = cfg.derived();
        let omega_max_word = word_from_omega(cfg.limits.omega_max).unwrap();
        let theta_step = (cfg.limits.drive_angle_rate_max_deg / 1000.0 / 360.0 * 4_294_967_296.0) as i64 + 1;
        let mut sup = Supervisor::new(&cfg, Angle::from_deg(90.0), t0);
        let mut dds = Dds::new(cfg.sample_hz, d.dds_step);
        let mut t: u32 = t0; // any start: the µs clock may wrap anywhere in the run
        let mut last_link: u32 = t0;
        for ev in events {
            match ev {
                Event::Req(r) => {
                    let before = sup;
                    if let Err(why) = sup.request(r) {
                        prop_assert_eq!(sup, before, "refused {:?} ({}) changed state", r, why);
                    }
                }
                Event::Ticks { n, estop, amps, crank_frac, link } => {
                    for _ in 0..n {
                        t = t.wrapping_add(1000);
                        if link {
                            sup.heard_from_link(t);
                            last_link = t;
                        }
                        let theta_before = sup.theta_d();
                        let inp = Inputs {
                            estop,
                            current: Amps::from_num(amps),
                            crank_speed: RadPerSec::saturating_from_num(dds.omega().to_num::<f64>() * crank_frac),
                            ref_omega: dds.omega(),
                            drive_stopped: dds.is_stopped(),
                            sensor_failed: false,
                            phase_error: RadPerSec::ZERO,
                            duty_saturated: false,
                            ramping: false,
                            link_us: t,
                            nfault_low: false,
                            bridge: None,
                            sensor_not_ready: false,
                        };
                        let out = sup.check(t, &inp);
                        if out.halt { dds.halt() } else { dds.set_target(out.target_word) }
                        let w_before = dds.word();
                        for _ in 0..d.samples_per_control { dds.tick(); }
                        // ω never above its limit; its change per tick never above the rate limit.
                        prop_assert!(out.target_word <= omega_max_word);
                        prop_assert!(dds.word() <= omega_max_word.max(w_before));
                        prop_assert!(u64::from(dds.word().abs_diff(w_before)) <= u64::from(d.dds_step) * u64::from(d.samples_per_control) || out.halt);
                        // θd slews at most one step per tick and stays in the mount's travel.
                        let dth = i64::from((out.theta_d - theta_before).to_bits()).abs();
                        prop_assert!(dth <= theta_step, "θd jumped {}", dth);
                        let deg = out.theta_d.to_deg();
                        let deg = if deg < cfg.limits.drive_angle_min_deg - 1e-6 { deg + 360.0 } else { deg };
                        prop_assert!(deg >= cfg.limits.drive_angle_min_deg - 1e-6 && deg <= cfg.limits.drive_angle_max_deg + 1e-6, "θd {}", deg);
                        // The e-stop halts at once, and the drive may not run while it is pressed.
                        if estop {
                            prop_assert!(out.halt && !out.active);
                            prop_assert_eq!(sup.mode(), Mode::Faulted(Fault::EStop));
                        }
                        // Silent link: never running more than the timeout after the last message.
                        if t.wrapping_sub(last_link) > cfg.limits.link_timeout_ms * 1000 {
                            prop_assert!(sup.mode() != Mode::Running);
                        }
                    }
                }
            }
        }
    }
}

// ---- scripted cases
/// One control tick at `t`, the link's clock the same as the rig's.
fn check(s: &mut Supervisor, t: u32, inp: &Inputs) -> Output {
    s.check(t, &Inputs { link_us: t, ..*inp })
}

fn quiet(ref_omega: f64, crank: f64, stopped: bool) -> Inputs {
    Inputs {
        estop: false,
        current: Amps::ZERO,
        crank_speed: RadPerSec::from_num(crank),
        ref_omega: RadPerSec::from_num(ref_omega),
        drive_stopped: stopped,
        sensor_failed: false,
        phase_error: RadPerSec::ZERO,
        duty_saturated: false,
        ramping: false,
        link_us: 0,
        nfault_low: false,
        bridge: None,
        sensor_not_ready: false,
    }
}

#[test]
fn refusals_name_the_reason_and_change_nothing() {
    let mut s = Supervisor::new(&RigConfig::REFERENCE, Angle::ZERO, 0);
    let before = s;
    assert_eq!(
        s.request(Request::Start { omega: 500.0 }),
        Err(Refusal::OmegaAboveLimit {
            requested: 500.0,
            limit: 420.0
        })
    );
    assert_eq!(
        s.request(Request::SetDriveAngle { deg: 200.0 }),
        Err(Refusal::DriveAngleOutOfRange {
            requested: 200.0,
            min: -10.0,
            max: 190.0
        })
    );
    assert_eq!(
        s.request(Request::SetOmega { omega: 100.0 }),
        Err(Refusal::WrongMode(Mode::Idle))
    );
    assert!(s.request(Request::Start { omega: f64::NAN }).is_err());
    assert_eq!(s, before);
}

#[test]
fn link_silence_soft_stops_and_never_restarts() {
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    s.request(Request::Start { omega: 300.0 }).unwrap();
    let mut t = 0u32;
    for _ in 0..1000 {
        t += 1000;
        check(&mut s, t, &quiet(300.0, 300.0, false));
    }
    assert_eq!(s.mode(), Mode::Running); // exactly 1 s of silence is not yet "more than"
    t += 1000;
    let out = check(&mut s, t, &quiet(300.0, 300.0, false));
    assert_eq!(s.mode(), Mode::Stopping(StopReason::LinkSilent));
    assert!(out.active && !out.halt && out.target_word == 0); // ramp down, not a halt
    t += 1000;
    check(&mut s, t, &quiet(0.0, 0.0, true));
    assert_eq!(s.mode(), Mode::Idle);
    assert_eq!(s.last_stop(), Some(StopReason::LinkSilent));
    s.heard_from_link(t);
    t += 1000;
    check(&mut s, t, &quiet(0.0, 0.0, true));
    assert_eq!(s.mode(), Mode::Idle); // no automatic restart
}

#[test]
fn estop_halts_at_once_and_latches() {
    let mut s = Supervisor::new(&RigConfig::REFERENCE, Angle::ZERO, 0);
    s.request(Request::Start { omega: 300.0 }).unwrap();
    let mut inp = quiet(300.0, 300.0, false);
    inp.estop = true;
    let out = check(&mut s, 1000, &inp);
    assert!(out.halt && !out.active);
    assert_eq!(s.mode(), Mode::Faulted(Fault::EStop));
    assert_eq!(
        s.request(Request::ClearFault),
        Err(Refusal::EStopStillActive)
    );
    check(&mut s, 2000, &quiet(0.0, 0.0, true));
    assert_eq!(
        s.request(Request::Start { omega: 1.0 }),
        Err(Refusal::Faulted(Fault::EStop))
    );
    s.request(Request::ClearFault).unwrap();
    assert_eq!(s.mode(), Mode::Idle);
}

#[test]
fn drive_angle_slews_within_the_travel() {
    // From 185° to −5° (travel [−10°, 190°]): the shortest way (+170° through 270°) would
    // leave the travel; the slew goes back through 90° at 30°/s: 190° in 6.33 s.
    let mut s = Supervisor::new(&RigConfig::REFERENCE, Angle::from_deg(185.0), 0);
    s.request(Request::SetDriveAngle { deg: -5.0 }).unwrap();
    let mut t = 0;
    let mut passed_90 = false;
    for _ in 0..7000 {
        t += 1000;
        let th = check(&mut s, t, &quiet(0.0, 0.0, true)).theta_d.to_deg();
        let th = if th < -10.0 - 1e-6 { th + 360.0 } else { th };
        assert!((-10.0 - 1e-6..=190.0 + 1e-6).contains(&th), "θd {th}");
        passed_90 |= (th - 90.0).abs() < 0.1;
    }
    assert!(passed_90);
    assert!((s.theta_d().to_deg() + 5.0).abs() < 1e-6);
}

/// 300 control ticks (1 ms apart, the link alive) on `inp` leave the rig running; the 301st
/// halts it (the REFERENCE stall debounce: 300 ms).
fn latches_after_300_ticks(s: &mut Supervisor, t: &mut u32, inp: &Inputs) {
    for _ in 0..300 {
        *t += 1000;
        s.heard_from_link(*t);
        check(s, *t, inp);
        assert_eq!(s.mode(), Mode::Running, "t = {t}");
    }
    *t += 1000;
    assert!(check(s, *t, inp).halt);
}

#[test]
fn stall_and_over_current_stop_after_their_debounce() {
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    s.request(Request::Start { omega: 300.0 }).unwrap();
    // Crank at 10 % of the reference: stall after 300 ms, not before.
    let mut t = 0;
    latches_after_300_ticks(&mut s, &mut t, &quiet(100.0, 10.0, false));
    assert_eq!(s.mode(), Mode::Faulted(Fault::Stall));
    s.request(Request::ClearFault).unwrap();
    s.request(Request::Start { omega: 300.0 }).unwrap();
    let mut inp = quiet(100.0, 100.0, false);
    inp.current = Amps::from_num(5);
    for _ in 0..20 {
        t += 1000;
        s.heard_from_link(t);
        check(&mut s, t, &inp);
    }
    assert_eq!(s.mode(), Mode::Running);
    t += 1000;
    check(&mut s, t, &inp);
    assert_eq!(s.mode(), Mode::Faulted(Fault::OverCurrent));
}

#[test]
fn a_crank_turning_backwards_faults_after_the_stall_debounce() {
    // Swapped encoder channels or motor leads: the crank follows the drive at full speed, but
    // backwards. |speed| is above the stall bar, so only the sign can catch it; the debounce is
    // the stall's (REFERENCE: 300 ms at 1 kHz ticks, so 300 ticks pass and the 301st latches).
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    s.request(Request::Start { omega: 300.0 }).unwrap();
    let mut t = 0;
    latches_after_300_ticks(&mut s, &mut t, &quiet(100.0, -100.0, false));
    assert_eq!(s.mode(), Mode::Faulted(Fault::WrongDirection));
    assert_eq!(
        s.request(Request::Start { omega: 300.0 }),
        Err(Refusal::Faulted(Fault::WrongDirection))
    );
    // Backwards but slower than the bar (30 % of 100 rad/s): a stall, not a wrong direction.
    s.request(Request::ClearFault).unwrap();
    s.request(Request::Start { omega: 300.0 }).unwrap();
    for _ in 0..301 {
        t += 1000;
        s.heard_from_link(t);
        check(&mut s, t, &quiet(100.0, -20.0, false));
    }
    assert_eq!(s.mode(), Mode::Faulted(Fault::Stall));
    // Forwards at speed: neither.
    s.request(Request::ClearFault).unwrap();
    s.request(Request::Start { omega: 300.0 }).unwrap();
    for _ in 0..1000 {
        t += 1000;
        s.heard_from_link(t);
        check(&mut s, t, &quiet(100.0, 100.0, false));
    }
    assert_eq!(s.mode(), Mode::Running);
}

#[test]
fn a_failed_sensor_latches_in_any_mode_and_refuses_a_start() {
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    let mut inp = quiet(0.0, 0.0, true);
    inp.sensor_failed = true;
    assert!(check(&mut s, 1000, &inp).halt);
    assert_eq!(s.mode(), Mode::Faulted(Fault::Sensor));
    assert_eq!(
        s.request(Request::Start { omega: 100.0 }),
        Err(Refusal::Faulted(Fault::Sensor))
    );
    // Once the sensor is back, the fault clears and a start is taken.
    check(&mut s, 2000, &quiet(0.0, 0.0, true));
    s.request(Request::ClearFault).unwrap();
    s.request(Request::Start { omega: 100.0 }).unwrap();
    assert_eq!(s.mode(), Mode::Running);
    // While running: halted at once.
    s.heard_from_link(3000);
    let mut inp = quiet(50.0, 50.0, false);
    inp.sensor_failed = true;
    assert!(check(&mut s, 3000, &inp).halt);
    assert_eq!(s.last_stop(), Some(StopReason::Fault(Fault::Sensor)));
}

#[test]
fn the_i2t_limit_trips_when_the_closed_form_says() {
    // A constant current I from rest: the exponential mean of i² is I²(1 − e^(−t/τ)), which
    // reaches the limit (0.6·I_max)² at t = −τ ln(1 − (0.6·I_max/I)²). REFERENCE: I_max = 3 A,
    // so the RMS limit is 1.8 A; at I = 2.5 A (below the 3 A peak trip) t = −ln(1 − 0.5184) s
    // = 0.7306 s. The discrete mean at 1 kHz (weight h/τ = 1e-3 per tick) follows
    // 1 − (1 − 1e-3)^n, which reaches 0.5184 at n = ln(0.4816)/ln(0.999) = 730.2 ticks: the
    // trip tick is 731 (±1 for the Q16 rounding of 2.5 A, which is exact).
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    let mut inp = quiet(0.0, 0.0, true);
    inp.current = Amps::from_num(2.5);
    let mut tripped = None;
    for k in 1..=2000u32 {
        check(&mut s, k * 1000, &inp);
        if s.mode() == Mode::Faulted(Fault::OverCurrentRms) {
            tripped = Some(k);
            break;
        }
    }
    let k = tripped.expect("the I²t limit trips");
    assert!((730..=732).contains(&k), "tripped at tick {k}");
    // 1.7 A, below the RMS limit, never trips.
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    inp.current = Amps::from_num(1.7);
    for k in 1..=10_000u32 {
        check(&mut s, k * 1000, &inp);
    }
    assert_eq!(s.mode(), Mode::Idle);
}

#[test]
fn two_cycle_slips_within_a_second_lose_the_phase_lock() {
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    s.request(Request::Start { omega: 300.0 }).unwrap();
    let mut t = 0u32;
    let mut tick = |s: &mut Supervisor, e: f64| {
        t += 1000;
        s.heard_from_link(t);
        let mut inp = quiet(100.0, 100.0, false);
        inp.phase_error = RadPerSec::from_num(e);
        check(s, t, &inp);
    };
    // Large errors that do not wrap are no slip.
    for _ in 0..100 {
        tick(&mut s, 3.0);
        tick(&mut s, 1.0);
    }
    assert_eq!(s.mode(), Mode::Running);
    // One slip (+3 → −3 rad: the wrap at π), then another 1.5 s later: still running.
    tick(&mut s, 3.0);
    tick(&mut s, -3.0);
    for _ in 0..1500 {
        tick(&mut s, 0.0);
    }
    tick(&mut s, -3.0);
    tick(&mut s, 3.0);
    assert_eq!(s.mode(), Mode::Running);
    // A third slip 0.5 s after the second: lost.
    for _ in 0..500 {
        tick(&mut s, 0.0);
    }
    tick(&mut s, 3.0);
    tick(&mut s, -3.0);
    assert_eq!(s.mode(), Mode::Faulted(Fault::PhaseLockLost));
}

#[test]
fn a_drive_held_at_the_duty_ceiling_faults_after_the_stall_debounce() {
    // The phase lock clamped at duty_max on every tick while running: the motor cannot hold the
    // speed within the duty it may use. Debounced like a stall (REFERENCE: 300 ms at 1 kHz).
    let cfg = RigConfig::REFERENCE;
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    s.request(Request::Start { omega: 300.0 }).unwrap();
    let mut t = 0;
    let mut at_ceiling = quiet(100.0, 100.0, false);
    at_ceiling.duty_saturated = true;
    latches_after_300_ticks(&mut s, &mut t, &at_ceiling);
    assert_eq!(s.mode(), Mode::Faulted(Fault::DutyCeiling));
    assert_eq!(
        s.request(Request::Start { omega: 300.0 }),
        Err(Refusal::Faulted(Fault::DutyCeiling))
    );
    // Touching the ceiling now and then is no fault: the debounce restarts each time.
    s.request(Request::ClearFault).unwrap();
    s.request(Request::Start { omega: 300.0 }).unwrap();
    for k in 0..2000 {
        t += 1000;
        s.heard_from_link(t);
        let mut inp = quiet(100.0, 100.0, false);
        inp.duty_saturated = k % 200 != 0;
        check(&mut s, t, &inp);
    }
    assert_eq!(s.mode(), Mode::Running);
    // Idle at the ceiling (nothing drives): nothing to latch.
    let mut s = Supervisor::new(&cfg, Angle::ZERO, 0);
    for _ in 0..1000 {
        t += 1000;
        s.heard_from_link(t);
        check(&mut s, t, &at_ceiling);
    }
    assert_eq!(s.mode(), Mode::Idle);
}

#[test]
fn a_bridge_fault_latches_and_its_clear_waits_for_nfault() {
    use kapitza_core::rig::bridge::Line;
    let mut s = Supervisor::new(&RigConfig::REFERENCE, Angle::ZERO, 0);
    s.request(Request::Start { omega: 100.0 }).unwrap();
    let run = quiet(100.0, 100.0, false);
    let out = check(&mut s, 1000, &run);
    assert!(out.active && !out.halt);
    // The tick that is told of it latches it and halts the drive.
    let seen = Inputs {
        nfault_low: true,
        bridge: Some(Line::NFault),
        ..run
    };
    let out = check(&mut s, 2000, &seen);
    assert_eq!(s.mode(), Mode::Faulted(Fault::Bridge(Line::NFault)));
    assert!(out.halt && !out.active);
    // nFAULT still low: refused, nothing changed.
    let low = Inputs {
        nfault_low: true,
        ..quiet(0.0, 0.0, true)
    };
    check(&mut s, 3000, &low);
    let before = s;
    assert_eq!(
        s.request(Request::ClearFault),
        Err(Refusal::BridgeFaultActive)
    );
    assert_eq!(s, before);
    // High again: cleared.
    check(&mut s, 4000, &quiet(0.0, 0.0, true));
    assert_eq!(s.request(Request::ClearFault), Ok(()));
    assert_eq!(s.mode(), Mode::Idle);
}

#[test]
fn a_sensor_not_ready_is_a_fault_only_while_driving() {
    let mut s = Supervisor::new(&RigConfig::REFERENCE, Angle::ZERO, 0);
    let unready = |i: Inputs| Inputs {
        sensor_not_ready: true,
        ..i
    };
    // Idle for a second: no fault (the pre-run check refuses the start instead).
    for k in 1..=1000 {
        check(&mut s, k * 1000, &unready(quiet(0.0, 0.0, true)));
    }
    assert_eq!(s.mode(), Mode::Idle);
    s.request(Request::Start { omega: 100.0 }).unwrap();
    s.heard_from_link(1_001_000);
    check(&mut s, 1_001_000, &quiet(100.0, 100.0, false));
    assert_eq!(s.mode(), Mode::Running);
    // Running: the first tick that is told of it latches it.
    check(&mut s, 1_002_000, &unready(quiet(100.0, 100.0, false)));
    assert_eq!(s.mode(), Mode::Faulted(Fault::Sensor));
}
