//! The rig loop: one rig and its end of the serial link, free of hardware. The firmware, the
//! on-target tests and the simulated rig all run a rig through this one type, so every rig
//! decision — when the control tick runs, when the H-bridge may be on, how a request reaches
//! the rig and when it is answered, telemetry pacing, the counters — is made here, once.
//!
//! ```text
//! caller (firmware, simulator)          RigLoop
//! every pendulum sample  sample(s)   →  DDS tick, estimator; failed / late samples counted;
//!                                       true when a control tick is due (every fs/fc samples)
//! control tick  control(link_us, motor, e-stop)
//!                                    →  bridge lines (nFAULT, BIF: rig::bridge), safety, DDS,
//!                                       phase lock → duty; a rearm; Tick: bridge on only
//!                                       while running or stopping, θd for the servo when it
//!                                       moved, a configuration to store; telemetry queued when due
//! bytes from the laptop  receive(…)  →  frames checked and answered at once, in order;
//!                                       the answers queued behind earlier frames
//! the line can take bytes  transmit  →  queued frame bytes, oldest first
//! flash written  config_saved(tag, ok)
//!                                 →  counts only for the newest store asked for
//! ```
//!
//! **Requests are answered where they are decoded**, in the caller's control context, so there
//! is no queue between the link and the rig and no timeout: a request is either carried out
//! and answered `Ok`, or refused and changes nothing — it can never be reported as not taken
//! and then carried out, and every answer carries its own request's sequence number. The
//! caller calls `receive` from the same context as `control` (the firmware: at the control
//! tick, with the bytes its UART task collected), which keeps the rig single-owner.
//!
//! **A repeat is answered, not carried out again** ([`repeat`]): the host resends a request
//! whose answer it did not get under the same sequence number, and the same seq and bytes as
//! the last request are answered with the answer already given.
//!
//! **The output never blocks the loop.** Frames wait in a fixed outbox until the caller's line
//! takes them. Telemetry is queued only while room for one answer is left behind it; a frame
//! that does not fit is dropped and counted (`Counters::frames_dropped`).
//!
//! **An unknown e-stop line counts as pressed**: the rig cannot start blind.
//!
//! **The hardware is read raw and calibrated here** ([`drive`]): the pendulum sensor's count,
//! the crank encoder and the current sense's ADC counts pass through the configuration's
//! [`crate::rig::calibration::Calibration`], so a calibration set over the link is in use from
//! the next sample, on the firmware and the simulated rig alike.
//!
//! **Every request is answered by [`serve::RigServer`]**: commands all or nothing, status and
//! telemetry built from the rig's state.
//!
//! **A start from idle waits for its pre-run check** ([`precheck`]): the status shows it
//! running, then its verdict; the drive starts only on a pass. **Bring-up mode** drives the
//! crank open loop at a capped duty and streams the sensors raw ([`Response::Raw`]).

pub mod clock;
pub mod drive;
pub mod precheck;
pub mod repeat;
pub mod serve;

use crate::link::convert::to_q16;
use crate::link::frame::{decode_request_as, encode, open, Header};
use crate::link::message::{Check, Counters, RawTelemetry, ResetInfo, Verdict};
use crate::link::{FrameReader, Request, Response, MAX_REQUEST_FRAME, MAX_RESPONSE_FRAME};
use crate::persist::ConfigOrigin;
use crate::rig::as5047::Diagnostics;
use crate::rig::bridge::Watch;
use crate::rig::config::RigConfig;
use crate::rig::controller::ControlReport;
use crate::rig::estop::EStop;
use crate::rig::fixed::{elapsed_us, Amps, Angle};
use crate::rig::phase_lock::Motor;
use crate::rig::safety::Mode;
use crate::rig::servo::ServoMap;
use drive::{Calibrated, Drive};
use precheck::{SensorView, Step};
use repeat::FrameId;
use serve::{apply, Activity, Clock, Effect, RigServer};

/// The shortest telemetry period (ms): a telemetry frame is ≤ 100 bytes, 8.7 ms at 115200 baud.
pub const MIN_TELEMETRY_MS: u16 = 20;

/// Room for this many of the largest frames in the outbox.
const OUTBOX_FRAMES: usize = 4;
const OUTBOX: usize = OUTBOX_FRAMES * MAX_RESPONSE_FRAME;

/// One pendulum-sensor sample, as read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sample {
    /// When it was read (µs on the rig's clock, wrapping).
    pub t_us: u32,
    /// The sensor's count, 2^14 a turn (the last good one if this read failed); the rig loop
    /// turns it into the pendulum angle with the calibration.
    pub count: u16,
    /// The read failed (bus error, parity, or the sensor's error flag).
    pub failed: bool,
    /// Taken more than half a sample period late.
    pub late: bool,
    /// The sensor's driver counts the sensor as failed (too many reads in a row without an
    /// angle, or its magnet out of range: [`crate::rig::as5047::Health::failed`]).
    pub sensor_failed: bool,
    /// The sensor's last diagnostics read, if any yet.
    pub diagnostics: Option<Diagnostics>,
}

/// What the caller must do after a control tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tick {
    /// The H-bridge may be awake: only while the drive runs or ramps down, the pre-run
    /// check pulses, or bring-up mode drives.
    pub bridge: bool,
    /// θd moved, or the servo's map changed: the servo's new position, degrees along the
    /// mount's travel.
    pub servo_deg: Option<f64>,
    /// The same as the servo's pulse width (µs, unrounded), through the calibrated map.
    pub servo_us: Option<f64>,
    /// A configuration was accepted: write it to flash, then call [`RigLoop::config_saved`]
    /// with its tag. Its sample rate is in use from the next sample on.
    pub store: Option<StoreRequest>,
    /// What the control tick did.
    pub report: ControlReport,
}

/// A configuration to store, tagged so that its outcome is told apart from an earlier store's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StoreRequest {
    pub tag: u32,
    pub cfg: RigConfig,
}

/// Frame bytes waiting for the line: a byte ring of fixed size.
#[derive(Debug, Clone)]
struct Outbox {
    buf: [u8; OUTBOX],
    head: usize,
    len: usize,
}

impl Outbox {
    const fn new() -> Self {
        Self {
            buf: [0; OUTBOX],
            head: 0,
            len: 0,
        }
    }

    fn free(&self) -> usize {
        OUTBOX - self.len
    }

    /// Queues a whole frame, or nothing if it does not fit.
    fn push(&mut self, frame: &[u8]) -> bool {
        if frame.len() > self.free() {
            return false;
        }
        for &b in frame {
            self.buf[(self.head + self.len) % OUTBOX] = b;
            self.len += 1;
        }
        true
    }

    fn pop(&mut self, out: &mut [u8]) -> usize {
        let n = out.len().min(self.len);
        for o in &mut out[..n] {
            *o = self.buf[self.head];
            self.head = (self.head + 1) % OUTBOX;
        }
        self.len -= n;
        n
    }
}

/// One rig and its link: see the [module doc](self).
#[derive(Debug, Clone)]
pub struct RigLoop {
    srv: RigServer,
    reader: FrameReader<MAX_REQUEST_FRAME>,
    out: Outbox,
    samples_per_control: u32,
    since_control: u32,
    /// The telemetry period asked for (ms; 0: off), the same in control ticks, and the ticks
    /// since the last frame.
    telemetry_ms: u16,
    telemetry_every: u32,
    since_telemetry: u32,
    telemetry_seq: u8,
    /// The e-stop line at the last control tick, debounced.
    estop: bool,
    estop_line: EStop,
    /// The θd and the servo map of the last pulse sent: a new map (calibration) resends it.
    servo: Option<(Angle, ServoMap)>,
    store: Option<StoreRequest>,
    /// The tag of the newest store asked for: only its outcome counts.
    store_tag: u32,
    last: Sample,
    uptime_us: u64,
    current: Amps,
    /// The last tick's raw crank reading and ADC counts, for the raw telemetry.
    raw_crank: Angle,
    counts: u16,
    /// The bridge's nSLEEP as driven, to ignore nFAULT while it sleeps and wakes.
    bridge: Watch,
    /// A `ClearFault` was accepted: re-arm the bridge's outputs at the next tick.
    rearm: bool,
}

impl RigLoop {
    /// A stopped rig on `cfg` (validated; [`crate::persist::store::load`] gives one), θd at
    /// `theta_d0`, both clocks at `now_us`.
    pub fn new(
        cfg: RigConfig,
        origin: ConfigOrigin,
        theta_d0: Angle,
        now_us: u32,
        firmware: [u16; 3],
    ) -> Self {
        let srv = RigServer::new(cfg, origin, theta_d0, Clock::single(now_us, 0), firmware);
        Self {
            samples_per_control: per_control(&cfg),
            srv,
            reader: FrameReader::new(),
            out: Outbox::new(),
            since_control: 0,
            telemetry_ms: 0,
            telemetry_every: 0,
            since_telemetry: 0,
            telemetry_seq: 0,
            estop: true,
            estop_line: EStop::new(),
            servo: None,
            store: None,
            store_tag: 0,
            last: Sample {
                t_us: now_us,
                count: cfg.calibration.pendulum_zero,
                failed: false,
                late: false,
                sensor_failed: false,
                diagnostics: None,
            },
            uptime_us: 0,
            current: Amps::ZERO,
            raw_crank: Angle::ZERO,
            counts: 0,
            bridge: Watch::new(),
            rearm: false,
        }
    }

    /// The same rig after a reset of `cause`, reported in the status.
    pub fn after_reset(mut self, reset: ResetInfo) -> Self {
        self.srv.reset = reset;
        self
    }

    /// The same rig speaking protocol `version` on the link: for tests of what a host does
    /// about version skew, never on a real rig.
    pub fn speaking(mut self, version: u8) -> Self {
        self.srv.protocol = version;
        self
    }

    /// One pendulum sample. Returns `true` when a control tick is due now.
    pub fn sample(&mut self, s: Sample) -> bool {
        let c = &mut self.srv.counters;
        if s.failed {
            c.sensor_errors = c.sensor_errors.saturating_add(1);
        }
        if s.late {
            c.overruns = c.overruns.saturating_add(1);
        }
        self.uptime_us += u64::from(s.t_us.wrapping_sub(self.last.t_us));
        self.last = s;
        self.srv.rig.sensor_failed(s.sensor_failed);
        self.srv
            .rig
            .sensor_not_ready(s.diagnostics.is_some_and(|d| !d.ready));
        let angle = self.srv.cfg.calibration.pendulum_angle(s.count);
        self.srv.rig.sample(s.t_us, angle);
        if let Activity::Checking { check, .. } = &mut self.srv.activity {
            check.sample(s.failed);
        }
        self.since_control += 1;
        if self.since_control < self.samples_per_control {
            return false;
        }
        self.since_control = 0;
        true
    }

    /// The control tick, at the time of the last sample. `link_us` is the link's clock (the
    /// rig's own on hardware); `drive` the crank motor's hardware, read raw and calibrated
    /// here; `estop` the e-stop line as read now, `None` while it is unknown (pressed),
    /// debounced here ([`crate::rig::estop`]). The bridge's fault lines are read first: a
    /// fault they show is latched at this tick ([`crate::rig::bridge`]); the outputs are
    /// re-armed after an accepted `ClearFault`, or after a break the loop ignored while no
    /// fault is latched, and only while nFAULT reads high.
    pub fn control<D: Drive>(&mut self, link_us: u32, drive: &mut D, estop: Option<bool>) -> Tick {
        self.estop = self.estop_line.update(estop);
        let t = self.last.t_us;
        let lines = drive.bridge_lines();
        let seen = self.bridge.check(t, lines);
        self.srv.rig.bridge(lines.nfault_low, seen.fault);
        let cal = self.srv.cfg.calibration;
        let mut m = Calibrated::new(drive, &cal);
        let mut report = self.srv.rig.control_at(t, link_us, &mut m, self.estop);
        let extra = self.activity(&mut m, &report, link_us);
        report.duty = m.duty;
        report.mode = self.srv.rig.supervisor().mode();
        self.current = m.current;
        self.raw_crank = m.raw_crank;
        self.counts = m.counts;
        let told = Some((report.theta_d, cal.servo));
        let servo_deg = (self.servo != told).then(|| {
            self.servo = told;
            crate::link::convert::deg_along_travel(
                report.theta_d,
                self.srv.cfg.limits.drive_angle_min_deg,
            )
        });
        if self.telemetry_every > 0 {
            self.since_telemetry += 1;
            if self.since_telemetry >= self.telemetry_every {
                self.since_telemetry = 0;
                let resp = if let Activity::BringUp { .. } = self.srv.activity {
                    Response::Raw(self.raw(&report))
                } else {
                    Response::Telemetry(self.srv.telemetry(
                        t,
                        &report,
                        self.srv.cfg.calibration.pendulum_angle(self.last.count),
                        self.current,
                    ))
                };
                self.telemetry_seq = self.telemetry_seq.wrapping_add(1);
                self.queue(self.telemetry_seq, &resp, true);
            }
        }
        let awake = matches!(report.mode, Mode::Running | Mode::Stopping(_)) || extra;
        self.bridge.drive(awake, t);
        let faulted = matches!(report.mode, Mode::Faulted(_));
        let rearm = core::mem::take(&mut self.rearm) || (seen.rearm && !faulted);
        if rearm && seen.fault.is_none() && !lines.nfault_low {
            drive.rearm();
        }
        Tick {
            bridge: awake,
            servo_deg,
            servo_us: servo_deg.map(|d| self.srv.cfg.calibration.servo.pulse(d)),
            store: self.store.take(),
            report,
        }
    }

    /// The pre-run check's or bring-up mode's part of a control tick, after the rig's own
    /// (which left the duty at 0: the supervisor is idle). Returns whether the bridge must be
    /// awake for it.
    fn activity<D: Drive>(
        &mut self,
        m: &mut Calibrated<'_, D>,
        report: &ControlReport,
        link_us: u32,
    ) -> bool {
        let idle = report.mode == Mode::Idle;
        let srv = &mut self.srv;
        match &mut srv.activity {
            Activity::None => false,
            Activity::Checking { .. } if !idle => {
                srv.activity = Activity::None;
                srv.check = Some(Check::Failed(Verdict::Aborted));
                false
            }
            Activity::Checking { check, start } => {
                let sensor = SensorView {
                    diagnostics: self.last.diagnostics,
                    failed: self.last.sensor_failed,
                };
                let start = *start;
                match check.tick(m.crank, m.current, sensor) {
                    Step::Drive { bridge, duty } => {
                        m.set_duty(duty);
                        bridge
                    }
                    Step::Done(verdict) => {
                        srv.activity = Activity::None;
                        srv.check = Some(match verdict {
                            Ok(()) => match apply(&mut srv.rig, &srv.cfg, start) {
                                Ok(()) => Check::Passed,
                                // The start was checked when it arrived and nothing but a
                                // fault (which aborts above) changes what it needs.
                                Err(_) => Check::Failed(Verdict::Aborted),
                            },
                            Err(v) => Check::Failed(v),
                        });
                        false
                    }
                }
            }
            Activity::BringUp { duty } => {
                let silent = elapsed_us(srv.heard_us, link_us)
                    > srv.cfg.limits.link_timeout_ms.saturating_mul(1000);
                if !idle || silent {
                    srv.activity = Activity::None;
                    return false;
                }
                m.set_duty(*duty);
                true
            }
        }
    }

    /// The sensors as they read at this tick.
    fn raw(&self, report: &ControlReport) -> RawTelemetry {
        RawTelemetry {
            t_us: self.last.t_us,
            pendulum: (!self.last.failed).then_some(self.last.count),
            crank: self.raw_crank.to_turns_u32(),
            current: self.counts,
            duty: report.duty.to_bits(),
            diagnostics: self.last.diagnostics.map(Into::into),
            sensor_errors: self.srv.counters.sensor_errors,
            theta_d_deg: to_q16(crate::link::convert::deg_along_travel(
                report.theta_d,
                self.srv.cfg.limits.drive_angle_min_deg,
            )),
            commands: self.srv.counters.commands,
        }
    }

    /// Bytes from the laptop. Every frame they complete is checked and answered at once; a bad
    /// frame is answered with its reason (seq 0 if its CRC failed). `link_us` on the link's
    /// clock.
    pub fn receive(&mut self, bytes: &[u8], link_us: u32) {
        for &b in bytes {
            let Some(got) = self.reader.push(b) else {
                continue;
            };
            let (seq, req) = match got {
                Ok(stuffed) => match open(stuffed) {
                    Ok(f) => (
                        f.header.seq,
                        decode_request_as(&f, self.srv.protocol)
                            .map(|req| (FrameId::of(f.header.seq, f.payload), req)),
                    ),
                    Err(r) => (0, Err(r)),
                },
                Err(r) => (0, Err(r)),
            };
            let c = &mut self.srv.counters;
            let resp = match req {
                Ok((id, req)) => {
                    c.frames_ok = c.frames_ok.saturating_add(1);
                    self.answer(id, req, link_us)
                }
                Err(reason) => {
                    c.frames_bad = c.frames_bad.saturating_add(1);
                    Response::Refused(reason)
                }
            };
            self.queue(seq, &resp, false);
        }
    }

    /// A line error (overrun, framing, noise) on the laptop link: the partial frame is dropped
    /// and counted as bad.
    pub fn line_error(&mut self) {
        self.reader.reset();
        let c = &mut self.srv.counters;
        c.frames_bad = c.frames_bad.saturating_add(1);
    }

    /// Moves queued frame bytes into `out` (as many as fit); returns how many.
    pub fn transmit(&mut self, out: &mut [u8]) -> usize {
        self.out.pop(out)
    }

    /// Bytes waiting for the line.
    pub fn pending(&self) -> usize {
        self.out.len
    }

    /// The store asked for by [`Tick::store`] with `tag` finished (`ok`: it reached flash).
    /// The outcome of a store that a newer one has overtaken says nothing about the
    /// configuration in use, and is ignored.
    pub fn config_saved(&mut self, tag: u32, ok: bool) {
        if tag == self.store_tag {
            self.srv.config_saved(ok);
        }
    }

    /// The rig and its configuration, counters and origin.
    pub fn server(&self) -> &RigServer {
        &self.srv
    }

    /// The configuration in use.
    pub fn config(&self) -> &RigConfig {
        &self.srv.cfg
    }

    pub fn counters(&self) -> &Counters {
        &self.srv.counters
    }

    /// The sample rate the rig expects now (Hz).
    pub fn sample_hz(&self) -> u32 {
        self.srv.cfg.sample_hz
    }

    fn answer(&mut self, id: FrameId, req: Request, link_us: u32) -> Response {
        let at = Clock {
            rig_us: self.last.t_us,
            link_us,
            uptime_ms: (self.uptime_us / 1000) as u32,
        };
        let (resp, effect) = self.srv.respond_once(id, req, at, self.estop);
        match effect {
            Effect::None => {}
            Effect::StoreConfig(cfg) => {
                self.samples_per_control = per_control(&cfg);
                self.since_control = 0;
                self.telemetry_every = telemetry_ticks(self.telemetry_ms, &cfg);
                self.store_tag = self.store_tag.wrapping_add(1);
                self.store = Some(StoreRequest {
                    tag: self.store_tag,
                    cfg,
                });
            }
            Effect::Telemetry { period_ms } => {
                self.telemetry_ms = period_ms;
                self.telemetry_every = telemetry_ticks(period_ms, &self.srv.cfg);
                self.since_telemetry = self.telemetry_every.saturating_sub(1);
            }
            Effect::Rearm => self.rearm = true,
        }
        resp
    }

    /// Frames `resp` into the outbox. Telemetry leaves room for one answer behind it.
    fn queue(&mut self, seq: u8, resp: &Response, telemetry: bool) {
        let mut frame = [0u8; MAX_RESPONSE_FRAME];
        let header = Header {
            version: self.srv.protocol,
            seq,
        };
        let Ok(n) = encode(header, resp, &mut frame) else {
            return;
        };
        let reserve = if telemetry { MAX_RESPONSE_FRAME } else { 0 };
        if n + reserve > self.out.free() || !self.out.push(&frame[..n]) {
            let c = &mut self.srv.counters;
            c.frames_dropped = c.frames_dropped.saturating_add(1);
        }
    }
}

fn per_control(cfg: &RigConfig) -> u32 {
    cfg.derived().samples_per_control.max(1)
}

/// `period_ms` (raised to [`MIN_TELEMETRY_MS`]) in control ticks; 0 stays off.
fn telemetry_ticks(period_ms: u16, cfg: &RigConfig) -> u32 {
    if period_ms == 0 {
        return 0;
    }
    let ms = u64::from(period_ms.max(MIN_TELEMETRY_MS));
    let ticks = (ms * u64::from(cfg.control_hz)).div_ceil(1000);
    u32::try_from(ticks).unwrap_or(u32::MAX).max(1)
}
