//! The link client against an in-memory rig that runs the firmware's request handling
//! (`kapitza_core::link::serve::RigServer`) behind the same framing: every method, refusals
//! kept apart from line failures, retries over a noisy line, a dead line, version skew.

use std::collections::VecDeque;
use std::io::{self, Read, Write};
use std::time::Duration;

use kapitza::link::{Client, Error, LineError};
use kapitza_core::link::frame::{encode, receive_request, Header};
use kapitza_core::link::message::Mode;
use kapitza_core::link::serve::{Effect, RigServer};
use kapitza_core::link::{
    FrameReader, Reason, Request, Response, MAX_REQUEST_FRAME, PROTOCOL_VERSION,
};
use kapitza_core::persist::{ConfigOrigin, Fallback};
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::estimator::Tuning;
use kapitza_core::rig::fixed::Angle;
use kapitza_core::rig::safety;

const CFG: RigConfig = RigConfig::REFERENCE;

/// A rig on the other end of an in-memory line. `damage(n)` decides whether the n-th frame
/// from the host arrives with a byte flipped; `speaks` is the rig's protocol version.
struct SimRig {
    server: RigServer,
    reader: FrameReader<MAX_REQUEST_FRAME>,
    out: VecDeque<u8>,
    frames_in: u32,
    damage: fn(u32) -> bool,
    speaks: u8,
    t_us: u32,
    telemetry: bool,
}

impl SimRig {
    fn new() -> Self {
        Self {
            server: RigServer::new(
                CFG,
                ConfigOrigin::Defaults(Fallback::Missing),
                Tuning::DEFAULT,
                Angle::ZERO,
                0,
                [0, 1, 0],
            ),
            reader: FrameReader::new(),
            out: VecDeque::new(),
            frames_in: 0,
            damage: |_| false,
            speaks: PROTOCOL_VERSION,
            t_us: 0,
            telemetry: false,
        }
    }

    fn reply(&mut self, seq: u8, resp: &Response) {
        let mut buf = [0u8; 512];
        let n = encode(
            Header {
                version: self.speaks,
                seq,
            },
            resp,
            &mut buf,
        )
        .unwrap();
        self.out.extend(&buf[..n]);
    }

    fn frame(&mut self, stuffed: &mut [u8]) {
        self.frames_in += 1;
        if (self.damage)(self.frames_in) {
            stuffed[stuffed.len() / 2] ^= 0x10;
        }
        self.t_us += 1000;
        let (seq, got) = receive_request(stuffed);
        let resp = match got {
            // A rig of another version understands only GetVersion.
            Ok(req) if self.speaks != PROTOCOL_VERSION && req != Request::GetVersion => {
                Response::Refused(Reason::VersionMismatch {
                    rig: self.speaks,
                    frame: PROTOCOL_VERSION,
                })
            }
            Ok(req) => {
                let (resp, effect) = self.server.respond(req, self.t_us, false, self.t_us / 1000);
                match effect {
                    Effect::StoreConfig(_) => self.server.config_saved(true),
                    Effect::Telemetry { period_ms } => self.telemetry = period_ms > 0,
                    Effect::None => {}
                }
                resp
            }
            Err(reason) => Response::Refused(reason),
        };
        self.reply(seq, &resp);
    }
}

impl Write for SimRig {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        for &b in buf {
            if let Some(Ok(stuffed)) = self.reader.push(b) {
                let mut f = stuffed.to_vec();
                self.frame(&mut f);
            }
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Read for SimRig {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.out.is_empty() && self.telemetry {
            let t = kapitza_core::link::Telemetry {
                t_us: self.t_us,
                ..Default::default()
            };
            self.reply(7, &Response::Telemetry(t));
        }
        let n = buf.len().min(self.out.len());
        for (i, b) in self.out.drain(..n).enumerate() {
            buf[i] = b;
        }
        if n == 0 {
            return Err(io::ErrorKind::TimedOut.into());
        }
        Ok(n)
    }
}

fn client(rig: SimRig) -> Client<SimRig> {
    Client::new(rig).with_timeout(Duration::from_millis(50))
}

#[test]
fn every_command() {
    let mut c = client(SimRig::new());
    let v = c.version().unwrap();
    assert_eq!((v.protocol, v.firmware), (PROTOCOL_VERSION, [0, 1, 0]));
    let s = c.status().unwrap();
    assert_eq!(s.mode, Mode::Idle);
    assert_eq!(s.config, ConfigOrigin::Defaults(Fallback::Missing));

    c.set_drive(3.0, 180.0).unwrap();
    assert_eq!(c.status().unwrap().mode, Mode::Running);
    c.stop().unwrap();
    assert!(matches!(c.status().unwrap().mode, Mode::Stopping(_)));
    c.clear_fault().unwrap();

    // A refusal is the rig's word, not a line failure, and changes nothing.
    let before = c.status().unwrap();
    // R = 6 needs ω = ωc √6 = 442.9 rad/s (ωc = 180.8 rad/s, RigConfig::REFERENCE) > 420.
    match c.set_drive(6.0, 90.0) {
        Err(Error::Refused(Reason::OmegaAboveLimit { .. })) => {}
        other => panic!("{other:?}"),
    }
    let after = c.status().unwrap();
    assert_eq!(
        (after.mode, after.omega_target),
        (before.mode, before.omega_target)
    );
    // Not even sent: a NaN.
    assert!(matches!(c.set_drive(f64::NAN, 0.0), Err(Error::Invalid(_))));

    c.stream_telemetry(20).unwrap();
    let t = c.telemetry().unwrap();
    assert!(t.t_us > 0);
    c.stream_telemetry(0).unwrap();
}

#[test]
fn configuration_round_trip() {
    let mut c = client(SimRig::new());
    let mut new = CFG;
    new.amplitude = 0.012;
    new.limits.omega_max = 400.0;
    c.set_config(&new).unwrap();
    assert_eq!(c.config().unwrap(), new);
    assert_eq!(
        c.status().unwrap().config,
        ConfigOrigin::Received { saved: true }
    );
    // R = 6 needs ω = ωc √6 = 369.1 rad/s with A = 12 mm (ωc = √(2gℓ)/A = 150.7 rad/s), below
    // the new 400 rad/s limit; R = 8 needs 426.2 rad/s, above it.
    c.set_drive(6.0, 0.0).unwrap();
    assert!(matches!(
        c.set_drive(8.0, 0.0),
        Err(Error::Refused(Reason::OmegaAboveLimit { .. }))
    ));
    c.stop().unwrap();
    let rig = c.into_inner();
    assert_eq!(rig.server.cfg, new);
    let mut c = client(rig);
    // Invalid values are refused with the field named.
    let mut bad = new;
    bad.gravity = -1.0;
    match c.set_config(&bad) {
        Err(Error::Refused(r @ Reason::ConfigInvalid { .. })) => {
            assert!(r.to_string().contains("gravity"), "{r}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_noisy_line_is_retried_and_never_misapplied() {
    // Every other frame from the host arrives damaged.
    let mut rig = SimRig::new();
    rig.damage = |n| n % 2 == 1;
    let mut c = client(rig);
    c.set_drive(2.0, 45.0).unwrap();
    let rig = c.into_inner();
    // The damaged copy was refused (BadCrc) and changed nothing; the retry applied exactly R, θd.
    assert_eq!(rig.frames_in, 2);
    let sup = rig.server.rig.supervisor();
    assert_eq!(sup.mode(), safety::Mode::Running);
    let w = kapitza_core::rig::dds::omega_of_word(sup.target_word());
    assert!((w - CFG.omega_for_r(2.0).unwrap()).abs() < 1e-3);
    assert_eq!(sup.theta_d_target(), Angle::from_deg(45.0));
    // Damaged every time: the line failed, with the reason.
    let mut rig = SimRig::new();
    rig.damage = |_| true;
    let mut c = client(rig).with_tries(3);
    match c.set_drive(2.0, 45.0) {
        Err(Error::Line(LineError::Link(Reason::BadCrc))) => {}
        other => panic!("{other:?}"),
    }
    assert_eq!(
        c.into_inner().server.rig.supervisor().mode(),
        safety::Mode::Idle
    );
}

/// A line that swallows everything.
struct Dead;
impl Read for Dead {
    fn read(&mut self, _: &mut [u8]) -> io::Result<usize> {
        Ok(0)
    }
}
impl Write for Dead {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[test]
fn a_dead_line_times_out() {
    let mut c = Client::new(Dead)
        .with_timeout(Duration::from_millis(5))
        .with_tries(2);
    assert!(matches!(c.status(), Err(Error::Line(LineError::Timeout))));
}

#[test]
fn version_skew_is_reported_not_guessed() {
    let mut rig = SimRig::new();
    rig.speaks = PROTOCOL_VERSION + 1;
    let mut c = client(rig);
    // The frozen exchange still works...
    assert_eq!(c.version().unwrap().protocol, PROTOCOL_VERSION);
    // ...everything else is a version mismatch, at once.
    match c.status() {
        Err(e @ Error::Line(LineError::VersionMismatch(_))) => {
            assert!(e.to_string().contains("flash the firmware"), "{e}")
        }
        other => panic!("{other:?}"),
    }
}
