//! The link client against the simulated rig (`kapitza_core::simrig`, the firmware's rig loop
//! on simulated hardware) over an in-memory line: every method, refusals kept apart from line
//! failures, retries over a noisy line, a dead line, version skew.

use std::io::{self, Read, Write};
use std::time::Duration;

use kapitza::link::{Client, Error, LineError};
use kapitza_core::link::message::Mode;
use kapitza_core::link::{Reason, PROTOCOL_VERSION};
use kapitza_core::persist::{ConfigOrigin, Fallback};
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::fixed::Angle;
use kapitza_core::rig::safety;
use kapitza_core::simrig::sensor::Line as SensorLine;
use kapitza_core::simrig::{Params, SimRig};

const CFG: RigConfig = RigConfig::REFERENCE;

/// The simulated rig on the other end of an in-memory line. `damage(n)` decides whether the
/// n-th frame from the host arrives with a byte flipped, `lose(n)` whether the n-th frame from
/// the rig is lost on the way back. Every read lets 1 ms of rig time pass.
struct Line {
    rig: SimRig,
    partial: Vec<u8>,
    frames_in: u32,
    damage: fn(u32) -> bool,
    out_partial: Vec<u8>,
    frames_out: u32,
    lose: fn(u32) -> bool,
}

impl Line {
    fn new() -> Self {
        Self::on(SimRig::new(
            Params::DEMO,
            CFG,
            ConfigOrigin::Defaults(Fallback::Missing),
            [0, 1, 0],
        ))
    }

    fn on(rig: SimRig) -> Self {
        Self {
            rig,
            partial: Vec::new(),
            frames_in: 0,
            damage: |_| false,
            out_partial: Vec::new(),
            frames_out: 0,
            lose: |_| false,
        }
    }
}

impl Write for Line {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        for &b in buf {
            self.partial.push(b);
            if b == 0 {
                self.frames_in += 1;
                let mut frame = std::mem::take(&mut self.partial);
                if (self.damage)(self.frames_in) {
                    let mid = frame.len() / 2;
                    frame[mid] ^= 0x10;
                }
                self.rig.receive(&frame, None);
            }
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Read for Line {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.rig.run(1e-3);
        let mut sent = vec![0u8; buf.len()];
        let n = self.rig.transmit(&mut sent);
        let mut kept = 0;
        for &b in &sent[..n] {
            self.out_partial.push(b);
            if b == 0 {
                self.frames_out += 1;
                let frame = std::mem::take(&mut self.out_partial);
                if !(self.lose)(self.frames_out) {
                    buf[kept..kept + frame.len()].copy_from_slice(&frame);
                    kept += frame.len();
                }
            }
        }
        match kept {
            0 => Err(io::ErrorKind::TimedOut.into()),
            n => Ok(n),
        }
    }
}

/// Waits out a start's pre-run check (0.6 s of rig time; each status poll lets ≥ 1 ms pass)
/// and returns the mode after it.
fn after_check(c: &mut Client<Line>) -> Mode {
    loop {
        let m = c.status().unwrap().mode;
        if m != Mode::Checking {
            return m;
        }
    }
}

/// The line runs rig time only as it is read (1 ms a read, a read that finds nothing sleeps
/// 1 ms), so a 20 ms telemetry frame costs ≥ 20 ms of wall time, more on a loaded machine: the
/// wall-clock timeout is generous so that only a rig that never answers reaches it.
fn client(rig: Line) -> Client<Line> {
    Client::new(rig).with_timeout(Duration::from_secs(2))
}

#[test]
fn every_command() {
    let mut c = client(Line::new());
    let v = c.version().unwrap();
    assert_eq!((v.protocol, v.firmware), (PROTOCOL_VERSION, [0, 1, 0]));
    let s = c.status().unwrap();
    assert_eq!(s.mode, Mode::Idle);
    assert_eq!(s.config, ConfigOrigin::Defaults(Fallback::Missing));

    c.set_drive(3.0, 180.0).unwrap();
    assert_eq!(c.status().unwrap().mode, Mode::Checking);
    assert_eq!(after_check(&mut c), Mode::Running);
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
    let mut c = client(Line::new());
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
    assert_eq!(after_check(&mut c), Mode::Running);
    assert!(matches!(
        c.set_drive(8.0, 0.0),
        Err(Error::Refused(Reason::OmegaAboveLimit { .. }))
    ));
    c.stop().unwrap();
    let rig = c.into_inner();
    assert_eq!(*rig.rig.rig().config(), new);
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
    let mut rig = Line::new();
    rig.damage = |n| n % 2 == 1;
    let mut c = client(rig);
    c.set_drive(2.0, 45.0).unwrap();
    let rig = c.into_inner();
    // The damaged copy was refused (BadCrc) and changed nothing; the retry applied exactly R, θd
    // (once its pre-run check passed).
    assert_eq!(rig.frames_in, 2);
    let mut rig = rig;
    rig.rig.run(0.7);
    let sup = rig.rig.rig().server().rig.supervisor();
    assert_eq!(sup.mode(), safety::Mode::Running);
    let w = kapitza_core::rig::dds::omega_of_word(sup.target_word());
    assert!((w - CFG.omega_for_r(2.0).unwrap()).abs() < 1e-3);
    assert_eq!(sup.theta_d_target(), Angle::from_deg(45.0));
    // Damaged every time: the line failed, with the reason.
    let mut rig = Line::new();
    rig.damage = |_| true;
    let mut c = client(rig).with_tries(3);
    match c.set_drive(2.0, 45.0) {
        Err(Error::Line(LineError::Link(Reason::BadCrc))) => {}
        other => panic!("{other:?}"),
    }
    assert_eq!(
        c.into_inner().rig.rig().server().rig.supervisor().mode(),
        safety::Mode::Idle
    );
}

/// A client whose tries are short: the in-memory rig answers at the first read after a
/// request, so only a lost answer waits a try out.
fn quick(rig: Line) -> Client<Line> {
    Client::new(rig).with_timeout(Duration::from_millis(50))
}

#[test]
fn a_lost_answer_is_asked_again_and_the_command_carried_out_once() {
    let mut rig = Line::new();
    rig.lose = |n| n == 1;
    let mut c = quick(rig);
    // The start is carried out at its first copy (its pre-run check begins); the second copy,
    // under the same seq, is answered from that answer. Carried out again it would be refused:
    // a check is running.
    c.set_drive(2.0, 45.0).unwrap();
    let rig = c.into_inner();
    assert!(rig.frames_in >= 2, "sent {} times", rig.frames_in);
    let srv = rig.rig.rig().server();
    assert_eq!(srv.counters.commands, 1);
    assert_eq!(srv.check, Some(kapitza_core::link::message::Check::Running));
    // The next command is a new one (the next seq), carried out: a stop aborts the check.
    let mut c = quick(rig);
    c.stop().unwrap();
    assert_eq!(c.status().unwrap().mode, Mode::Idle);
    assert_eq!(c.into_inner().rig.rig().server().counters.commands, 2);
}

#[test]
fn the_handshake_survives_a_lost_answer() {
    let mut rig = Line::new();
    rig.lose = |n| n == 1;
    let mut c = quick(rig);
    let v = c.version().unwrap();
    assert_eq!((v.protocol, v.firmware), (PROTOCOL_VERSION, [0, 1, 0]));
    assert!(c.into_inner().frames_in >= 2);
}

#[test]
fn answers_lost_every_time_fail_the_line_within_the_window() {
    let mut rig = Line::new();
    rig.lose = |_| true;
    let mut c = Client::new(rig)
        .with_timeout(Duration::from_millis(10))
        .with_tries(4);
    assert_eq!(c.window(), Duration::from_millis(40));
    let t = std::time::Instant::now();
    assert!(matches!(c.stop(), Err(Error::Line(LineError::Timeout))));
    // The window, 4 tries of 10 ms, is waited out (a bound below; above, only the machine's
    // load), and nothing comes back to ask again at once for: one copy a try at most.
    assert!(t.elapsed() >= Duration::from_millis(40));
    let rig = c.into_inner();
    assert!((1..=4).contains(&rig.frames_in), "{}", rig.frames_in);
    // The stop was carried out once, whatever the host could tell.
    assert_eq!(rig.rig.rig().server().counters.commands, 1);
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
    let mut rig = Line::new();
    rig.rig = rig.rig.speaking(PROTOCOL_VERSION + 1);
    let mut c = client(rig);
    // The frozen exchange still works and says what the rig speaks...
    assert_eq!(c.version().unwrap().protocol, PROTOCOL_VERSION + 1);
    // ...everything else is a version mismatch, at once.
    match c.status() {
        Err(e @ Error::Line(LineError::VersionMismatch(_))) => {
            assert!(e.to_string().contains("flash the firmware"), "{e}")
        }
        other => panic!("{other:?}"),
    }
}

/// A rig on `params` with its sensor line as given, after `ms` of polling its status (each poll
/// lets ≥ 1 ms of rig time pass), or earlier once it faults.
fn faulted_within(params: Params, wire: SensorLine, start: bool, ms: u32) -> (Client<Line>, Mode) {
    let mut rig = SimRig::new(params, CFG, ConfigOrigin::Stored, [0, 1, 0]);
    rig.sensor().line = wire;
    let mut c = client(Line::on(rig));
    if start {
        c.set_drive(3.0, 0.0).unwrap();
        after_check(&mut c);
    }
    let mut mode = c.status().unwrap().mode;
    for _ in 0..ms {
        if matches!(mode, Mode::Faulted(_)) {
            break;
        }
        mode = c.status().unwrap().mode;
    }
    (c, mode)
}

#[test]
fn bench_faults_latch_with_their_reason_and_refuse_a_start() {
    use kapitza_core::link::message::Fault;
    // A cut sensor cable (MISO pulled up): faulted while idle, within FAULT_AFTER samples.
    let (mut c, mode) = faulted_within(Params::DEMO, SensorLine::CutPulledUp, false, 50);
    assert_eq!(mode, Mode::Faulted(Fault::Sensor));
    match c.set_drive(3.0, 0.0) {
        Err(Error::Refused(Reason::Faulted(Fault::Sensor))) => {}
        other => panic!("{other:?}"),
    }
    // Swapped crank-encoder channels, and swapped motor leads: the crank turns against the
    // drive. The pre-run check's test pulse sees it before any start and refuses it (the
    // WrongDirection fault is for a reversal while running: rig_safety, closed_loop_safety).
    for params in [
        Params {
            crank_sign: -1.0,
            ..Params::DEMO
        },
        Params {
            motor: kapitza_core::simrig::plant::MotorModel {
                direction: -1.0,
                ..kapitza_core::simrig::plant::MotorModel::DEFAULT
            },
            ..Params::DEMO
        },
    ] {
        let (mut c, mode) = faulted_within(params, SensorLine::Connected, true, 3000);
        assert_eq!(mode, Mode::Idle);
        assert!(matches!(
            c.status().unwrap().check,
            Some(kapitza_core::link::message::Check::Failed(
                kapitza_core::link::message::Verdict::CrankReversed { .. }
            ))
        ));
    }
    // A motor too weak for the set ω: 300 rad/s at full duty (back-EMF matched, so its current
    // stays low) against ω = ωc√3 = 313 rad/s. The crank runs at ≥ 96 % of ω, no stall, but
    // slips a cycle every 2π/13 s ≈ 0.48 s once the ramp (313/60 ≈ 5.2 s) is over: two slips
    // within 1 s lose the lock ≈ 6.2 s after the start; 10 s is the bound.
    let weak = Params {
        motor: kapitza_core::simrig::plant::MotorModel {
            omega_per_duty: 300.0,
            ke: 12.0 / 300.0,
            ..kapitza_core::simrig::plant::MotorModel::DEFAULT
        },
        ..Params::DEMO
    };
    let (_, mode) = faulted_within(weak, SensorLine::Connected, true, 10_000);
    assert_eq!(mode, Mode::Faulted(Fault::PhaseLockLost));
    // The same rig wired right runs.
    let (_, mode) = faulted_within(Params::DEMO, SensorLine::Connected, true, 2000);
    assert_eq!(mode, Mode::Running);
}

#[test]
fn bring_up_streams_the_raw_sensors() {
    let mut c = client(Line::new());
    c.bring_up(0.1, 0.0).unwrap();
    assert_eq!(c.status().unwrap().bring_up, Some(3_277));
    c.stream_telemetry(20).unwrap();
    // Let the motor reach its speed (τ = 60 ms), then 0.5 s of frames: the crank turns
    // forwards at 0.1 · 450 rad/s (the demo motor), 45/(2π) · 0.5 = 3.58 turns, summed frame
    // by frame (a 20 ms frame is 0.14 turn, well inside the half turn a wrapped difference
    // holds).
    let mut a = c.raw_telemetry().unwrap();
    while c.raw_telemetry().unwrap().t_us.wrapping_sub(a.t_us) < 300_000 {}
    a = c.raw_telemetry().unwrap();
    let (start, mut b, mut turns) = (a, a, 0.0);
    while b.t_us.wrapping_sub(start.t_us) < 500_000 {
        let n = c.raw_telemetry().unwrap();
        turns += f64::from(n.crank.wrapping_sub(b.crank) as i32) / 4_294_967_296.0;
        b = n;
    }
    let secs = f64::from(b.t_us.wrapping_sub(start.t_us)) * 1e-6;
    let rate = turns / secs;
    assert!(
        (rate - 45.0 / std::f64::consts::TAU).abs() < 0.1,
        "{rate} turns/s"
    );
    assert_eq!(b.duty, 3_277);
    assert!(b.pendulum.is_some() && b.diagnostics.is_some_and(|d| d.ready));
    // Above the cap: refused by the rig; not a number: not even sent.
    assert!(matches!(
        c.bring_up(0.5, 0.0),
        Err(Error::Refused(Reason::DutyAboveCap { .. }))
    ));
    assert!(matches!(c.bring_up(f64::NAN, 0.0), Err(Error::Invalid(_))));
    c.stop().unwrap();
    assert_eq!(c.status().unwrap().bring_up, None);
}
