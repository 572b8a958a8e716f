//! The rig loop (`kapitza_core::station::RigLoop`): requests answered where they are decoded,
//! telemetry paced in control ticks, the bridge only while driving, an unknown e-stop read as
//! pressed, the command counter, a repeated configuration not stored again, frames dropped and
//! counted when nobody reads, and the link-silence timer on the link's own clock.

use kapitza_core::link::frame::{encode, receive_response, Header};
use kapitza_core::link::message::{Check, Fault, Mode};
use kapitza_core::link::{FrameReader, Request, Response, MAX_REQUEST_FRAME, MAX_RESPONSE_FRAME};
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::as5047::Diagnostics;
use kapitza_core::rig::bridge::Lines;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::fixed::{Angle, Duty};
use kapitza_core::station::drive::Drive;
use kapitza_core::station::{RigLoop, Sample, Tick};

const CFG: RigConfig = RigConfig::REFERENCE;

/// A crank that turns exactly at the speed the duty asks for (500 rad/s at full duty), so the
/// supervisor sees no stall.
struct Follow {
    angle: Angle,
    duty: f64,
}

impl Drive for Follow {
    fn crank_raw(&mut self) -> Angle {
        self.angle
    }
    fn current_counts(&mut self) -> u16 {
        0
    }
    fn set_duty(&mut self, d: Duty) {
        self.duty = d.to_num();
    }
    /// A healthy bridge: nFAULT high, no break (tests/rig_bridge.rs breaks it).
    fn bridge_lines(&mut self) -> Lines {
        Lines::default()
    }
    fn rearm(&mut self) {}
}

struct Bench {
    rig: RigLoop,
    crank: Follow,
    t_us: u32,
    link_us: u32,
    /// Link-clock µs per rig-clock µs (1: one clock).
    link_rate: u32,
    estop: Option<bool>,
    ticks: Vec<Tick>,
    /// The laptop reads the line after every control tick.
    reading: bool,
    line: Vec<u8>,
}

impl Bench {
    fn new(origin: ConfigOrigin) -> Self {
        Self {
            rig: RigLoop::new(CFG, origin, Angle::ZERO, 0, [0, 1, 0]),
            crank: Follow {
                angle: Angle::ZERO,
                duty: 0.0,
            },
            t_us: 0,
            link_us: 0,
            link_rate: 1,
            estop: Some(false),
            ticks: Vec::new(),
            reading: true,
            line: Vec::new(),
        }
    }

    /// `ms` of rig time, 10 samples per ms.
    fn run_ms(&mut self, ms: u32) {
        for _ in 0..ms * 10 {
            self.t_us = self.t_us.wrapping_add(100);
            self.link_us = self.link_us.wrapping_add(100 / self.link_rate.max(1));
            let due = self.rig.sample(Sample {
                t_us: self.t_us,
                count: 0,
                failed: false,
                late: false,
                sensor_failed: false,
                diagnostics: Some(Diagnostics::HEALTHY),
            });
            if due {
                let tick = self.rig.control(self.link_us, &mut self.crank, self.estop);
                let w = self.crank.duty * 500.0 * 1e-3;
                self.crank.angle += Angle::from_rad(w);
                self.ticks.push(tick);
                if self.reading {
                    let mut buf = [0u8; 256];
                    loop {
                        let n = self.rig.transmit(&mut buf);
                        if n == 0 {
                            break;
                        }
                        self.line.extend_from_slice(&buf[..n]);
                    }
                }
            }
        }
    }

    fn send(&mut self, seq: u8, req: &Request) {
        let mut f = [0u8; MAX_REQUEST_FRAME];
        let n = encode(Header::new(seq), req, &mut f).unwrap();
        self.rig.receive(&f[..n], self.link_us);
    }

    /// Every frame the loop has queued, decoded.
    fn drain(&mut self) -> Vec<(u8, Response)> {
        let mut reader = FrameReader::<MAX_RESPONSE_FRAME>::new();
        let mut got = Vec::new();
        let mut buf = [0u8; 100];
        loop {
            let n = self.rig.transmit(&mut buf);
            if n == 0 {
                break;
            }
            self.line.extend_from_slice(&buf[..n]);
        }
        for b in std::mem::take(&mut self.line) {
            if let Some(Ok(stuffed)) = reader.push(b) {
                let (h, r) = receive_response(stuffed).unwrap();
                got.push((h.seq, r));
            }
        }
        got
    }

    fn status(&mut self) -> kapitza_core::link::Status {
        self.send(200, &Request::GetStatus);
        match self.drain().pop() {
            Some((200, Response::Status(s))) => s,
            other => panic!("{other:?}"),
        }
    }
}

fn drive(r: f64, deg: f64) -> Request {
    Request::SetDrive {
        r: (r * 65_536.0) as i32,
        theta_d_deg: (deg * 65_536.0) as i32,
    }
}

#[test]
fn answers_at_once_with_the_request_s_seq() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.run_ms(1);
    b.send(7, &Request::GetVersion);
    b.send(8, &drive(2.0, 45.0));
    b.send(9, &drive(9.0, 45.0)); // above ω_max: refused
    let got = b.drain();
    assert_eq!(got.len(), 3);
    assert!(matches!(got[0], (7, Response::Version(_))));
    assert_eq!(got[1], (8, Response::Ok));
    assert!(matches!(got[2], (9, Response::Refused(_))));
    // One command carried out, the refused one not counted.
    assert_eq!(b.status().counters.commands, 1);
}

#[test]
fn telemetry_is_paced_in_control_ticks_and_carries_the_command_count() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.send(1, &Request::Telemetry { period_ms: 50 });
    b.drain();
    b.run_ms(1000);
    let tm: Vec<_> = b
        .drain()
        .into_iter()
        .filter_map(|(_, r)| match r {
            Response::Telemetry(t) => Some(t),
            _ => None,
        })
        .collect();
    // 1000 ms at one frame per 50 ms (50 control ticks at 1 kHz).
    assert_eq!(tm.len(), 20);
    assert!(tm.windows(2).all(|w| w[1].t_us - w[0].t_us == 50_000));
    // Shorter than the line can carry: raised to 20 ms.
    b.send(2, &Request::Telemetry { period_ms: 1 });
    b.drain();
    b.run_ms(200);
    assert_eq!(b.drain().len(), 10);
    // A snapshot after a command carries its count.
    b.send(3, &drive(1.0, 0.0));
    b.run_ms(40);
    let last = b
        .drain()
        .into_iter()
        .filter_map(|(_, r)| match r {
            Response::Telemetry(t) => Some(t),
            _ => None,
        })
        .next_back();
    assert_eq!(last.unwrap().commands, 1);
}

#[test]
fn the_bridge_is_on_only_while_driving() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.run_ms(10);
    assert!(b.ticks.iter().all(|t| !t.bridge));
    b.send(1, &drive(1.0, 0.0));
    // The pre-run check: 100 ms at rest with the bridge asleep, then its pulse and coast.
    b.run_ms(100);
    assert!(b.ticks[10..].iter().all(|t| !t.bridge));
    b.run_ms(10);
    assert!(b.ticks.last().unwrap().bridge);
    b.run_ms(500);
    assert_eq!(b.status().check, Some(Check::Passed));
    assert!(b.ticks.last().unwrap().bridge);
    b.send(2, &Request::Stop);
    b.run_ms(10);
    assert!(
        b.ticks.last().unwrap().bridge,
        "ramping down is still driving"
    );
    // Heard from the link throughout (one clock), the stop ends once the drive reaches zero.
    for _ in 0..100 {
        b.send(3, &Request::GetStatus);
        b.run_ms(50);
    }
    b.drain();
    assert!(!b.ticks.last().unwrap().bridge);
    assert_eq!(b.status().mode, Mode::Idle);
}

#[test]
fn an_unknown_estop_counts_as_pressed() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.estop = None;
    b.run_ms(2);
    assert_eq!(b.status().mode, Mode::Faulted(Fault::EStop));
    b.send(1, &drive(1.0, 0.0));
    assert!(matches!(b.drain()[0].1, Response::Refused(_)));
}

#[test]
fn the_servo_is_told_only_when_theta_d_moves() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.run_ms(5);
    // The power-up position once, then nothing while θd holds.
    let told: Vec<_> = b.ticks.iter().filter_map(|t| t.servo_deg).collect();
    assert_eq!(told.len(), 1);
    // 0° to the angle's resolution (2^-32 turn = 8.4e-8°).
    assert!(told[0].abs() < 1e-7, "{told:?}");
    // R = 0 moves θd alone, at once (a start would wait for its pre-run check).
    b.send(1, &drive(0.0, 10.0));
    b.run_ms(100);
    let moved = b.ticks.iter().filter(|t| t.servo_deg.is_some()).count();
    // 30°/s slew at 1 kHz: 0.03° per tick, so 10° takes 334 ticks; 100 ticks moved so far.
    assert_eq!(moved, 1 + 100);
}

#[test]
fn the_servo_pulse_comes_from_the_configured_map() {
    // A servo whose middle (1500 µs) points at θd = 100° over 180° of range, 1000–2000 µs:
    // θd = 10° is 90° below the centre, 90 · 1000/180 = 500 µs below 1500 µs.
    let mut cfg = CFG;
    cfg.calibration.servo = kapitza_core::rig::servo::ServoMap {
        min_us: 1000,
        max_us: 2000,
        range_deg: 180.0,
        centre_deg: 100.0,
    };
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.rig = RigLoop::new(
        cfg,
        ConfigOrigin::Stored,
        Angle::from_deg(10.0),
        0,
        [0, 1, 0],
    );
    b.run_ms(2);
    let us: Vec<f64> = b.ticks.iter().filter_map(|t| t.servo_us).collect();
    assert_eq!(us.len(), 1);
    assert!((us[0] - 1000.0).abs() < 1e-6, "{us:?}");
}

#[test]
fn a_new_servo_map_moves_the_mount_where_theta_d_holds() {
    // Calibration corrects the map while θd stays where it was (the stroke step leaves it at
    // 90°, and `set --angle 90` asks for 90° again): the pulse for the same θd through the new
    // map is sent at once. REFERENCE: 7.407 µs a degree about 1500 µs at 90°; the centre moved
    // 2.5° the other way is 2.5 · 2000/270 = 18.52 µs lower at θd = 0°.
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.run_ms(2);
    let first: Vec<f64> = b.ticks.iter().filter_map(|t| t.servo_us).collect();
    assert_eq!(first.len(), 1);
    let mut cfg = CFG;
    cfg.calibration.servo.centre_deg += 2.5;
    b.ticks.clear();
    b.send(1, &Request::SetConfig(cfg.into()));
    b.run_ms(2);
    assert_eq!(b.drain()[0], (1, Response::Ok));
    let us: Vec<f64> = b.ticks.iter().filter_map(|t| t.servo_us).collect();
    assert_eq!(us.len(), 1, "{us:?}");
    assert!(
        (first[0] - us[0] - 2.5 * 2000.0 / 270.0).abs() < 1e-9,
        "{first:?} {us:?}"
    );
    let deg: Vec<f64> = b.ticks.iter().filter_map(|t| t.servo_deg).collect();
    assert!(deg[0].abs() < 1e-7, "{deg:?}");
}

#[test]
fn the_same_configuration_is_not_stored_again() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.send(1, &Request::SetConfig(CFG.into()));
    b.run_ms(2);
    assert_eq!(b.drain()[0], (1, Response::Ok));
    assert!(b.ticks.iter().all(|t| t.store.is_none()));
    // A different one is stored once.
    let mut new = CFG;
    new.amplitude = 0.011;
    b.send(2, &Request::SetConfig(new.into()));
    b.run_ms(2);
    assert_eq!(b.ticks.iter().filter(|t| t.store.is_some()).count(), 1);
    // On safe defaults the flash holds nothing usable: the same values are stored.
    let mut b = Bench::new(ConfigOrigin::Defaults(
        kapitza_core::persist::Fallback::Missing,
    ));
    b.send(1, &Request::SetConfig(CFG.into()));
    b.run_ms(2);
    assert_eq!(b.ticks.iter().filter(|t| t.store.is_some()).count(), 1);
}

/// A second `SetConfig` while the first is being stored: the first store's "saved" says
/// nothing of the second configuration, so the status stays "not saved" until the second's
/// own outcome arrives.
#[test]
fn only_the_newest_store_s_outcome_counts() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    let mut first = CFG;
    first.amplitude = 0.011;
    b.send(1, &Request::SetConfig(first.into()));
    b.run_ms(2);
    let mut second = CFG;
    second.amplitude = 0.012;
    b.send(2, &Request::SetConfig(second.into()));
    b.run_ms(2);
    let stores: Vec<_> = b.ticks.iter().filter_map(|t| t.store).collect();
    assert_eq!(stores.len(), 2);
    assert_eq!(stores[0].cfg.amplitude, 0.011);
    assert_eq!(stores[1].cfg.amplitude, 0.012);
    assert_ne!(stores[0].tag, stores[1].tag);
    b.drain();
    // The first store finishes: ignored.
    b.rig.config_saved(stores[0].tag, true);
    assert_eq!(b.status().config, ConfigOrigin::Received { saved: false });
    // The second one's outcome counts, whichever it is.
    b.rig.config_saved(stores[1].tag, false);
    assert_eq!(b.status().config, ConfigOrigin::Received { saved: false });
    b.rig.config_saved(stores[1].tag, true);
    assert_eq!(b.status().config, ConfigOrigin::Received { saved: true });
    // A late outcome of the first store changes nothing any more.
    b.rig.config_saved(stores[0].tag, false);
    assert_eq!(b.status().config, ConfigOrigin::Received { saved: true });
}

#[test]
fn nobody_reading_drops_telemetry_never_the_loop() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.reading = false;
    b.send(1, &Request::Telemetry { period_ms: 20 });
    b.run_ms(2000);
    // 100 telemetry frames in 2 s: the outbox holds a few, the rest were dropped and counted.
    assert!(b.rig.pending() <= 4 * MAX_RESPONSE_FRAME);
    let dropped = b.rig.counters().frames_dropped;
    let queued = b.drain();
    assert_eq!(queued[0], (1, Response::Ok));
    assert_eq!(
        queued.len() - 1 + dropped as usize,
        100,
        "{dropped} dropped"
    );
    // Telemetry leaves one largest frame's room free in the 4-frame outbox, so at most
    // 3·MAX_RESPONSE_FRAME bytes of it wait; a telemetry frame is at least 24 bytes (its 20
    // fields at one byte each, header, CRC and the COBS bytes).
    let most_queued = 3 * MAX_RESPONSE_FRAME / 24;
    assert!(
        queued.len() - 1 <= most_queued,
        "{} queued",
        queued.len() - 1
    );
    assert!(dropped as usize >= 100 - most_queued, "{dropped}");
    // An answer still gets through once the line is read.
    assert_eq!(b.status().counters.frames_dropped, dropped);
}

#[test]
fn link_silence_runs_on_the_link_clock() {
    // The rig's clock runs 20× faster than the link's (a simulated rig at --speed 20): 10 s
    // of rig time is 0.5 s of the laptop's, under the 1 s timeout, so the drive keeps running.
    let mut b = Bench::new(ConfigOrigin::Stored);
    b.link_rate = 20;
    b.send(1, &drive(1.0, 0.0));
    b.run_ms(10_000);
    b.drain();
    assert!(b.ticks.last().unwrap().report.mode == kapitza_core::rig::safety::Mode::Running);
    // Another 15 s of rig time (0.75 s of link time, 1.25 s since the command): soft stop.
    b.run_ms(15_000);
    assert!(matches!(
        b.ticks.last().unwrap().report.mode,
        kapitza_core::rig::safety::Mode::Stopping(_) | kapitza_core::rig::safety::Mode::Idle
    ));
}

#[test]
fn a_damaged_frame_is_refused_and_counted() {
    let mut b = Bench::new(ConfigOrigin::Stored);
    let mut f = [0u8; MAX_REQUEST_FRAME];
    let n = encode(Header::new(5), &drive(1.0, 0.0), &mut f).unwrap();
    // Changed, but never to the frame delimiter 0.
    f[n / 2] = if f[n / 2] == 0xFF { 0xFE } else { f[n / 2] + 1 };
    b.rig.receive(&f[..n], 0);
    let got = b.drain();
    assert_eq!(got.len(), 1);
    assert!(matches!(got[0], (0, Response::Refused(_))));
    let s = b.status();
    assert_eq!((s.counters.frames_bad, s.counters.commands), (1, 0));
    assert_eq!(s.mode, Mode::Idle);
}
