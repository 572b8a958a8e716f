//! Bring-up mode against the simulated rig: open-loop duty under its cap, the servo jogged,
//! the sensors streamed raw (pendulum counts, crank encoder, ADC counts, the AS5047P's
//! diagnostics), and every way out of it — stop, link silence, a fault.

use kapitza_core::link::message::{Fault, Mode, RawTelemetry};
use kapitza_core::link::{Reason, Request, Response};
use kapitza_core::simrig::Params;
use kapitza_core::station::serve::BRING_UP_DUTY_MAX;
use kapitza_test_support::sim_bench::Bench;

/// A duty in I1F15 bits.
fn q15(d: f64) -> i16 {
    (d * 32_768.0).round() as i16
}

fn raws(b: &Bench) -> Vec<RawTelemetry> {
    b.streamed
        .iter()
        .filter_map(|r| match r {
            Response::Raw(t) => Some(*t),
            _ => None,
        })
        .collect()
}

/// The crank's travel (turns) between two raw frames, unwrapped by frames.
fn crank_turns(raws: &[RawTelemetry]) -> f64 {
    raws.windows(2)
        .map(|w| f64::from(w[1].crank.wrapping_sub(w[0].crank) as i32) / 4_294_967_296.0)
        .sum()
}

#[test]
fn open_loop_duty_turns_the_crank_and_streams_raw_sensors() {
    let mut b = Bench::healthy(Params::DEMO);
    assert_eq!(b.ask(Request::Telemetry { period_ms: 20 }), Response::Ok);
    assert_eq!(
        b.ask(Request::BringUp {
            duty: q15(0.1),
            theta_d_deg: 0
        }),
        Response::Ok
    );
    assert_eq!(b.status().bring_up, Some(q15(0.1)));
    b.streamed.clear();
    for _ in 0..10 {
        b.run(0.1);
        b.status(); // the keep-alive
    }
    let raw = raws(&b);
    // 1 s at one frame per 20 ms, none of them the estimator's telemetry.
    assert!((49..=51).contains(&raw.len()), "{}", raw.len());
    assert!(b
        .streamed
        .iter()
        .all(|r| !matches!(r, Response::Telemetry(_))));
    // The demo motor: 0.1 · 450 rad/s, τ = 60 ms; over the last 0.5 s it turns at full speed,
    // 45/(2π) = 7.16 turns a second, forwards (the encoder counts with the drive).
    let last = &raw[raw.len() - 26..];
    let rate = crank_turns(last) / 0.5;
    assert!((rate - 45.0 / std::f64::consts::TAU).abs() < 0.1, "{rate}");
    let r = raw.last().unwrap();
    assert_eq!(r.duty, q15(0.1));
    // The pendulum hangs at rest: its count near the sensor's zero (0), within the noise.
    let c = r.pendulum.unwrap();
    assert!(!(20..=16_384 - 20).contains(&c), "{c}");
    // The sensor's diagnostics: the simulated chip's AGC (0x60) and ready flag.
    let d = r.diagnostics.unwrap();
    assert_eq!((d.agc, d.ready, d.magnet_low), (0x60, true, false));
    // The motor draws current at speed: (12 V · 0.1 − 12/500 · 45) / 2 Ω = 0.06 A, ≈ 51 ADC
    // counts of 77/65536 A; the sense reads it.
    assert!((40..=60).contains(&r.current), "{}", r.current);
    // Stop leaves bring-up: the duty drops to 0, the bridge sleeps.
    assert_eq!(b.ask(Request::Stop), Response::Ok);
    assert_eq!(b.status().bring_up, None);
    b.streamed.clear();
    b.run(0.1);
    assert!(raws(&b).is_empty());
}

#[test]
fn the_duty_is_capped() {
    let mut b = Bench::healthy(Params::DEMO);
    let cap = q15(BRING_UP_DUTY_MAX);
    assert_eq!(
        b.ask(Request::BringUp {
            duty: -cap - 1,
            theta_d_deg: 0
        }),
        Response::Refused(Reason::DutyAboveCap {
            requested: -cap - 1,
            cap
        })
    );
    assert_eq!(b.status().bring_up, None);
    // A lower configured ceiling lowers the cap.
    let mut cfg = Params::DEMO.configured();
    cfg.limits.duty_max = 0.05;
    let mut b = Bench::new(Params::DEMO, cfg);
    assert!(matches!(
        b.ask(Request::BringUp {
            duty: q15(0.1),
            theta_d_deg: 0
        }),
        Response::Refused(Reason::DutyAboveCap { .. })
    ));
}

#[test]
fn the_servo_jogs_to_the_angle_asked_for() {
    let mut b = Bench::healthy(Params::DEMO);
    assert_eq!(
        b.ask(Request::BringUp {
            duty: 0,
            theta_d_deg: 5 << 16
        }),
        Response::Ok
    );
    // 30°/s slew: 5° in 0.17 s.
    b.run(0.3);
    let s = b.status();
    assert_eq!(s.theta_d_deg, 5 << 16);
    // Outside the travel: refused, nothing moves.
    assert!(matches!(
        b.ask(Request::BringUp {
            duty: 0,
            theta_d_deg: 300 << 16
        }),
        Response::Refused(Reason::DriveAngleOutOfRange { .. })
    ));
}

#[test]
fn link_silence_and_faults_end_it() {
    let mut b = Bench::healthy(Params::DEMO);
    b.ask(Request::BringUp {
        duty: q15(0.2),
        theta_d_deg: 0,
    });
    // Nothing heard for the link timeout (1 s): back to idle, duty 0.
    b.run(1.2);
    assert_eq!(b.status().bring_up, None);
    // The e-stop: faulted, out of bring-up.
    b.ask(Request::BringUp {
        duty: q15(0.2),
        theta_d_deg: 0,
    });
    b.sim.estop = true;
    b.run(0.05);
    let s = b.status();
    assert_eq!((s.mode, s.bring_up), (Mode::Faulted(Fault::EStop), None));
    // And it cannot be entered while faulted.
    assert_eq!(
        b.ask(Request::BringUp {
            duty: 0,
            theta_d_deg: 0
        }),
        Response::Refused(Reason::Faulted(Fault::EStop))
    );
}

#[test]
fn a_start_or_a_new_configuration_leaves_it() {
    let mut b = Bench::healthy(Params::DEMO);
    b.ask(Request::BringUp {
        duty: q15(0.1),
        theta_d_deg: 0,
    });
    // A start from bring-up: the pre-run check takes over (the crank coasting from the
    // bring-up duty settles during its rest phase), then the drive runs.
    let s = b.start();
    assert_eq!(s.check, Some(kapitza_core::link::message::Check::Passed));
    assert_eq!((s.mode, s.bring_up), (Mode::Running, None));
    // A new configuration while in bring-up: taken, and bring-up is over.
    let mut b = Bench::healthy(Params::DEMO);
    b.ask(Request::BringUp {
        duty: q15(0.1),
        theta_d_deg: 0,
    });
    let mut cfg = Params::DEMO.configured();
    cfg.calibration.pendulum_zero = 100;
    assert_eq!(b.ask(Request::SetConfig(cfg.into())), Response::Ok);
    assert_eq!(b.status().bring_up, None);
}
