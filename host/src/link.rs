//! The laptop's side of the serial link: one method per command, over any byte port (a serial
//! port, or an in-memory rig in the tests). The protocol itself — messages, frames, reasons,
//! the version policy — is `kapitza_core::link`.
//!
//! Errors keep two things apart ([`Error`]): **the line failed** ([`Error::Line`]: no answer,
//! an I/O error, frames damaged on every try, a rig that speaks another protocol version) and
//! **the rig refused** ([`Error::Refused`]: it understood the command and said no, with a
//! [`Reason`]; nothing changed).
//!
//! **Retries, exactly once.** A call sends its request and waits for the answer with the
//! request's seq. Without one within the per-try timeout the same frame — the same seq — is
//! sent again; so it is at once when the rig says it could not read the frame, or a damaged
//! frame arrives (it may have been the answer), without waiting the try out. The rig answers a
//! repeat from the answer it already gave without carrying it out again
//! (`kapitza_core::station::repeat`), so a command whose answer was lost is carried out once
//! and still answered; an answer to any copy is taken. A refusal is never retried. The version handshake ([`Client::version`]) is a call like any other, so opening
//! and reopening a line retry the same way.
//!
//! | | default |
//! |---|---|
//! | per-try timeout | [`ANSWER_TIMEOUT`] = 40 ms (a round trip of the largest frames at 115200 baud, behind the telemetry queued before it, is about 55 ms: an answer later than the try is still taken) |
//! | tries | [`TRIES`] = 25 |
//! | retry window | tries × per-try timeout = 1 s, then the line has failed ([`LineError::Timeout`] or the last link-level reason) |
//! | copies sent | at most [`MAX_SENDS_PER_TRY`] × tries = 100 in the window (damaged answers asked again at once) |
//!
//! On the line the tests damage (3 bytes in 400), a 170-byte configuration answer arrives
//! whole about one time in four; a round trip over a pseudo-terminal takes a few ms, so the
//! window holds dozens of tries.
//!
//! The port's `read` should return within a few milliseconds when no byte arrives (a serial
//! port's read timeout, `Ok(0)`, `TimedOut` or `WouldBlock`).

use std::collections::VecDeque;
use std::fmt;
use std::io::{self, Read, Write};
use std::time::{Duration, Instant};

use kapitza_core::link::convert::to_q16;
use kapitza_core::link::frame::{encode, receive_response, Header};
use kapitza_core::link::message::RawTelemetry;
use kapitza_core::link::{
    FrameReader, Reason, Request, Response, Status, Telemetry, VersionInfo, MAX_REQUEST_FRAME,
    MAX_RESPONSE_FRAME,
};
use kapitza_core::rig::config::RigConfig;

/// Why the line failed.
#[derive(Debug)]
pub enum LineError {
    Io(io::Error),
    /// No answer within the timeout, on every try.
    Timeout,
    /// Every try was refused for a link-level reason (the last one given).
    Link(Reason),
    /// The rig speaks another protocol version (only `GetVersion` works).
    VersionMismatch(Reason),
    /// An answer of the wrong kind for the request.
    Unexpected(Box<Response>),
}

/// Why a call failed: the line, or the rig's refusal.
#[derive(Debug)]
pub enum Error {
    Line(LineError),
    Refused(Reason),
    /// The request cannot be sent as given (a number that is not finite or out of its format).
    Invalid(&'static str),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Line(LineError::Io(e)) => write!(f, "serial line: {e}"),
            Self::Line(LineError::Timeout) => f.write_str("serial line: no answer from the rig"),
            Self::Line(LineError::Link(r)) => write!(f, "serial line: {r}"),
            Self::Line(LineError::VersionMismatch(r)) => {
                write!(f, "{r}: flash the firmware that matches this host tool")
            }
            Self::Line(LineError::Unexpected(r)) => write!(f, "unexpected answer {r:?}"),
            Self::Refused(r) => write!(f, "the rig refused: {r}"),
            Self::Invalid(what) => write!(f, "cannot send: {what}"),
        }
    }
}

impl std::error::Error for Error {}

/// How long one try waits for its answer before the request is sent again.
pub const ANSWER_TIMEOUT: Duration = Duration::from_millis(40);
/// How many per-try timeouts make the retry window.
pub const TRIES: u32 = 25;
/// A damaged answer is asked for again at once, without waiting its try out: at most this many
/// copies per try in the window, a bound on what a call sends.
pub const MAX_SENDS_PER_TRY: u32 = 4;

/// A connection to a rig.
pub struct Client<P> {
    port: P,
    seq: u8,
    reader: FrameReader<MAX_RESPONSE_FRAME>,
    timeout: Duration,
    tries: u32,
    telemetry: VecDeque<Telemetry>,
    raw: VecDeque<RawTelemetry>,
}

/// I16F16 bits of a finite number within ±32768.
fn q16(x: f64, what: &'static str) -> Result<i32, Error> {
    if x.is_finite() && x.abs() < 32_768.0 {
        Ok(to_q16(x))
    } else {
        Err(Error::Invalid(what))
    }
}

impl<P: Read + Write> Client<P> {
    /// A client with the default retries: [`TRIES`] tries of [`ANSWER_TIMEOUT`] each.
    pub fn new(port: P) -> Self {
        Self {
            port,
            seq: 0,
            reader: FrameReader::new(),
            timeout: ANSWER_TIMEOUT,
            tries: TRIES,
            telemetry: VecDeque::new(),
            raw: VecDeque::new(),
        }
    }

    /// The per-try timeout.
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// How many times a request is sent (at least once).
    pub fn with_tries(mut self, tries: u32) -> Self {
        self.tries = tries.max(1);
        self
    }

    /// The longest a call waits before it reports the line as failed: tries × per-try timeout.
    pub fn window(&self) -> Duration {
        self.timeout * self.tries
    }

    pub fn into_inner(self) -> P {
        self.port
    }

    /// The rig's protocol and firmware versions (works with a rig of any protocol version).
    pub fn version(&mut self) -> Result<VersionInfo, Error> {
        match self.call(Request::GetVersion)? {
            Response::Version(v) => Ok(v),
            r => Err(Error::Line(LineError::Unexpected(Box::new(r)))),
        }
    }

    /// The rig's state; also keeps a running rig's link-silence timer from expiring.
    pub fn status(&mut self) -> Result<Status, Error> {
        match self.call(Request::GetStatus)? {
            Response::Status(s) => Ok(s),
            r => Err(Error::Line(LineError::Unexpected(Box::new(r)))),
        }
    }

    /// Drive strength R and drive angle θd (degrees): starts or changes the drive; R = 0 stops.
    pub fn set_drive(&mut self, r: f64, theta_d_deg: f64) -> Result<(), Error> {
        let req = Request::SetDrive {
            r: q16(r, "R must be finite and below 32768")?,
            theta_d_deg: q16(
                theta_d_deg,
                "the drive angle must be finite, within ±32768°",
            )?,
        };
        self.ok(req)
    }

    pub fn stop(&mut self) -> Result<(), Error> {
        self.ok(Request::Stop)
    }

    pub fn clear_fault(&mut self) -> Result<(), Error> {
        self.ok(Request::ClearFault)
    }

    /// Replaces the rig's configuration (while it is idle); the rig stores it in flash.
    pub fn set_config(&mut self, cfg: &RigConfig) -> Result<(), Error> {
        self.ok(Request::SetConfig((*cfg).into()))
    }

    pub fn config(&mut self) -> Result<RigConfig, Error> {
        match self.call(Request::GetConfig)? {
            Response::Config(c) => Ok(c.into()),
            r => Err(Error::Line(LineError::Unexpected(Box::new(r)))),
        }
    }

    /// Asks for telemetry every `period_ms` (0 stops it); read it with [`Client::telemetry`].
    pub fn stream_telemetry(&mut self, period_ms: u16) -> Result<(), Error> {
        self.ok(Request::Telemetry { period_ms })
    }

    /// The next telemetry snapshot, waiting up to the retry window for one.
    pub fn telemetry(&mut self) -> Result<Telemetry, Error> {
        let deadline = Instant::now() + self.window();
        loop {
            if let Some(t) = self.telemetry.pop_front() {
                return Ok(t);
            }
            if Instant::now() >= deadline {
                return Err(Error::Line(LineError::Timeout));
            }
            // Only telemetry is expected: answers to nothing are dropped.
            let _ = self.poll(0)?;
        }
    }

    /// Bring-up mode (from idle): the crank at an open-loop `duty` in [−1, 1) (the rig caps
    /// it), the servo jogged to θd (degrees); the telemetry stream carries the raw sensors
    /// instead ([`Client::raw_telemetry`]). [`Client::stop`] leaves it.
    pub fn bring_up(&mut self, duty: f64, theta_d_deg: f64) -> Result<(), Error> {
        if !(duty.is_finite() && (-1.0..1.0).contains(&duty)) {
            return Err(Error::Invalid("the duty must be a number in [-1, 1)"));
        }
        let req = Request::BringUp {
            duty: (duty * 32_768.0).round() as i16,
            theta_d_deg: q16(
                theta_d_deg,
                "the drive angle must be finite, within ±32768°",
            )?,
        };
        self.ok(req)
    }

    /// The next raw snapshot of bring-up mode, waiting up to the retry window for one.
    pub fn raw_telemetry(&mut self) -> Result<RawTelemetry, Error> {
        let deadline = Instant::now() + self.window();
        loop {
            if let Some(t) = self.raw.pop_front() {
                return Ok(t);
            }
            if Instant::now() >= deadline {
                return Err(Error::Line(LineError::Timeout));
            }
            let _ = self.poll(0)?;
        }
    }

    /// Telemetry that has arrived by now, without waiting for more than one read.
    pub fn telemetry_now(&mut self) -> Result<Option<Telemetry>, Error> {
        if self.telemetry.is_empty() {
            let _ = self.poll(0)?;
        }
        Ok(self.telemetry.pop_front())
    }

    /// Any request, answered (a refusal is [`Error::Refused`]); for a process that relays
    /// requests for others.
    pub fn request(&mut self, req: Request) -> Result<Response, Error> {
        self.call(req)
    }

    fn ok(&mut self, req: Request) -> Result<(), Error> {
        match self.call(req)? {
            Response::Ok => Ok(()),
            r => Err(Error::Line(LineError::Unexpected(Box::new(r)))),
        }
    }

    /// Sends `req` and waits for its answer, sending the same frame again (the same seq) after
    /// a per-try timeout without it, and at once on a link-level refusal or a damaged frame,
    /// until the retry window (tries × per-try timeout) is over or [`MAX_SENDS_PER_TRY`] × tries
    /// copies are out.
    fn call(&mut self, req: Request) -> Result<Response, Error> {
        // seq 0 is what the rig answers a frame it could not read with; never ours.
        self.seq = self.seq.wrapping_add(1).max(1);
        let mut frame = [0u8; MAX_REQUEST_FRAME];
        let n = encode(Header::new(self.seq), &req, &mut frame)
            .map_err(|_| Error::Invalid("request larger than a frame"))?;
        let mut last = LineError::Timeout;
        let window = Instant::now() + self.window();
        for _ in 0..self.tries.saturating_mul(MAX_SENDS_PER_TRY) {
            self.port
                .write_all(&frame[..n])
                .and_then(|()| self.port.flush())
                .map_err(|e| Error::Line(LineError::Io(e)))?;
            let deadline = (Instant::now() + self.timeout).min(window);
            while Instant::now() < deadline {
                match self.poll(self.seq)? {
                    Heard::Nothing => continue,
                    Heard::Damaged => {
                        last = LineError::Link(Reason::BadCrc);
                    }
                    Heard::Answer(Response::Refused(r)) if r.is_link() => {
                        if let Reason::VersionMismatch { .. } = r {
                            return Err(Error::Line(LineError::VersionMismatch(r)));
                        }
                        last = LineError::Link(r);
                    }
                    Heard::Answer(Response::Refused(r)) => return Err(Error::Refused(r)),
                    Heard::Answer(resp) => return Ok(resp),
                }
                break;
            }
            if Instant::now() >= window {
                break;
            }
        }
        Err(Error::Line(last))
    }

    /// Reads what has arrived. Returns the answer to `seq` (or a link-level refusal of a frame
    /// the rig could not read, seq 0), else whether a damaged frame came; queues telemetry and
    /// drops everything else.
    fn poll(&mut self, seq: u8) -> Result<Heard, Error> {
        let mut buf = [0u8; 512];
        let n = match self.port.read(&mut buf) {
            Ok(n) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::TimedOut
                        | io::ErrorKind::WouldBlock
                        | io::ErrorKind::Interrupted
                ) =>
            {
                0
            }
            Err(e) => return Err(Error::Line(LineError::Io(e))),
        };
        if n == 0 {
            std::thread::sleep(Duration::from_millis(1));
        }
        let mut heard = Heard::Nothing;
        for &b in &buf[..n] {
            let stuffed = match self.reader.push(b) {
                None => continue,
                Some(Ok(stuffed)) => stuffed,
                Some(Err(_)) => {
                    heard = heard.or(Heard::Damaged);
                    continue;
                }
            };
            match receive_response(stuffed) {
                Ok((_, Response::Telemetry(t))) => self.telemetry.push_back(t),
                Ok((_, Response::Raw(t))) => self.raw.push_back(t),
                Ok((h, resp)) if h.seq == seq && seq != 0 => heard = Heard::Answer(resp),
                Ok((h, Response::Refused(r))) if h.seq == 0 && r.is_link() && seq != 0 => {
                    heard = heard.or(Heard::Answer(Response::Refused(r)))
                }
                Err(r @ Reason::VersionMismatch { .. }) => {
                    return Err(Error::Line(LineError::VersionMismatch(r)))
                }
                // Damaged on the way back: perhaps the answer.
                Err(_) => heard = heard.or(Heard::Damaged),
                // A stale answer (to an earlier call, or a second copy's).
                Ok(_) => {}
            }
        }
        Ok(heard)
    }
}

/// What one read brought, the most telling first: the answer, else a damaged frame.
// Lives for one read, on the stack.
#[allow(clippy::large_enum_variant)]
enum Heard {
    Nothing,
    Damaged,
    Answer(Response),
}

impl Heard {
    /// `self`, unless `other` tells more.
    fn or(self, other: Heard) -> Heard {
        match (&self, &other) {
            (Heard::Answer(Response::Refused(r)), Heard::Answer(_)) if r.is_link() => other,
            (Heard::Answer(_), _) => self,
            (_, Heard::Nothing) => self,
            _ => other,
        }
    }
}
