//! The laptop's side of the serial link: one method per command, over any byte port (a serial
//! port, or an in-memory rig in the tests). The protocol itself — messages, frames, reasons,
//! the version policy — is `kapitza_core::link`.
//!
//! Errors keep two things apart ([`Error`]): **the line failed** ([`Error::Line`]: no answer,
//! an I/O error, frames damaged on every try, a rig that speaks another protocol version) and
//! **the rig refused** ([`Error::Refused`]: it understood the command and said no, with a
//! [`Reason`]; nothing changed). A call is retried on a link-level failure (a damaged frame
//! either way, a timeout), never on a refusal; every command is a setting (R and θd, stop,
//! clear, a configuration), so a retried one that had arrived the first time does no harm.
//!
//! The port's `read` should return within a few milliseconds when no byte arrives (a serial
//! port's read timeout, `Ok(0)`, `TimedOut` or `WouldBlock`); the call's own deadline is
//! [`Client::with_timeout`].

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
    /// A client with a 500 ms answer timeout and 3 tries per call.
    pub fn new(port: P) -> Self {
        Self {
            port,
            seq: 0,
            reader: FrameReader::new(),
            timeout: Duration::from_millis(500),
            tries: 3,
            telemetry: VecDeque::new(),
            raw: VecDeque::new(),
        }
    }

    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    pub fn with_tries(mut self, tries: u32) -> Self {
        self.tries = tries.max(1);
        self
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

    /// The next telemetry snapshot, waiting up to the timeout for one.
    pub fn telemetry(&mut self) -> Result<Telemetry, Error> {
        let deadline = Instant::now() + self.timeout;
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

    /// The next raw snapshot of bring-up mode, waiting up to the timeout for one.
    pub fn raw_telemetry(&mut self) -> Result<RawTelemetry, Error> {
        let deadline = Instant::now() + self.timeout;
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

    /// Sends `req` and waits for its answer, retrying on link-level failures.
    fn call(&mut self, req: Request) -> Result<Response, Error> {
        let mut last = LineError::Timeout;
        for _ in 0..self.tries {
            // seq 0 is what the rig answers a frame it could not read with; never ours.
            self.seq = self.seq.wrapping_add(1).max(1);
            let mut frame = [0u8; MAX_REQUEST_FRAME];
            let n = encode(Header::new(self.seq), &req, &mut frame)
                .map_err(|_| Error::Invalid("request larger than a frame"))?;
            self.port
                .write_all(&frame[..n])
                .and_then(|()| self.port.flush())
                .map_err(|e| Error::Line(LineError::Io(e)))?;
            let deadline = Instant::now() + self.timeout;
            last = LineError::Timeout;
            while Instant::now() < deadline {
                match self.poll(self.seq)? {
                    None => {}
                    Some(Response::Refused(r)) if r.is_link() => {
                        if let Reason::VersionMismatch { .. } = r {
                            return Err(Error::Line(LineError::VersionMismatch(r)));
                        }
                        last = LineError::Link(r);
                        break;
                    }
                    Some(Response::Refused(r)) => return Err(Error::Refused(r)),
                    Some(resp) => return Ok(resp),
                }
            }
        }
        Err(Error::Line(last))
    }

    /// Reads what has arrived. Returns the answer to `seq` (or a link-level refusal of a frame
    /// the rig could not read, seq 0), queues telemetry, drops everything else.
    fn poll(&mut self, seq: u8) -> Result<Option<Response>, Error> {
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
        let mut answer = None;
        for &b in &buf[..n] {
            let Some(Ok(stuffed)) = self.reader.push(b) else {
                continue;
            };
            match receive_response(stuffed) {
                Ok((_, Response::Telemetry(t))) => self.telemetry.push_back(t),
                Ok((_, Response::Raw(t))) => self.raw.push_back(t),
                Ok((h, resp)) if h.seq == seq && seq != 0 => answer = Some(resp),
                Ok((h, Response::Refused(r))) if h.seq == 0 && r.is_link() && seq != 0 => {
                    answer = Some(Response::Refused(r))
                }
                Err(r @ Reason::VersionMismatch { .. }) => {
                    return Err(Error::Line(LineError::VersionMismatch(r)))
                }
                // A stale answer, or one damaged on the way back: the deadline decides.
                _ => {}
            }
        }
        Ok(answer)
    }
}
