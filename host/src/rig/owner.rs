//! Who holds the port. A serial port has one owner at a time, and the rig soft-stops about a
//! second after the laptop goes silent, so a drive that outlives one command needs a process
//! that keeps the link alive: `kapitza attach` or `kapitza monitor`. The owner serves a
//! control socket beside the port; one-shot commands find it there and send their requests
//! through it, in the link's own framing, so the same client works on both.
//!
//! ```text
//! one-shot command ──frames──▶ control socket ──▶ owner ──Client──▶ serial port ──▶ rig
//!                  ◀──answer (its own seq) ───────────────◀ answer ◀───────────────
//!                  ◀──telemetry, when it asked for it ─────◀ the owner's own stream
//! the owner: GetStatus every 250 ms (the keep-alive), telemetry every 20 ms; a lost line is
//! reopened at the same path, its version checked again
//! ```

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, Sender};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use kapitza_core::link::frame::{encode, receive_request, Header};
use kapitza_core::link::{
    FrameReader, Request, Response, Status, Telemetry, MAX_REQUEST_FRAME, MAX_RESPONSE_FRAME,
};

use super::control_socket::{self, Listener, Stream};
use super::port::Target;
use super::session::{self, Session};
use super::simhost::SimOptions;
use crate::link::{Error, LineError};

/// The keep-alive period: well inside the rig's 1 s link timeout.
const KEEP_ALIVE: Duration = Duration::from_millis(250);
/// The owner's telemetry period (ms).
const TELEMETRY_MS: u16 = 20;
/// Telemetry frames taken per turn at most.
const TELEMETRY_BATCH: usize = 16;
/// How often a lost line is tried again.
const REOPEN_EVERY: Duration = Duration::from_millis(500);

/// The control socket of the owner of `port` (a device path or a symlink to one).
pub fn socket_path(port: &str) -> PathBuf {
    let real = std::fs::canonicalize(port).unwrap_or_else(|_| PathBuf::from(port));
    let name: String = real
        .to_string_lossy()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    runtime_dir().join(format!("{name}.sock"))
}

/// Where control sockets live: `$XDG_RUNTIME_DIR/kapitza`, else a per-user folder in the
/// system's temporary directory.
fn runtime_dir() -> PathBuf {
    match std::env::var_os("XDG_RUNTIME_DIR") {
        Some(d) if Path::new(&d).is_dir() => PathBuf::from(d).join("kapitza"),
        _ => std::env::temp_dir().join(format!("kapitza-{}", control_socket::uid())),
    }
}

/// A connection to the running owner of `port`, if there is one.
pub fn connect(port: &str) -> Option<Stream> {
    let s = control_socket::connect(&socket_path(port))?;
    s.set_read_timeout(Some(Duration::from_millis(5))).ok()?;
    Some(s)
}

/// Socket clients are numbered across every socket this process serves.
static NEXT_CLIENT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// A request from a socket client, to be relayed.
pub(super) struct Job {
    pub(super) client: usize,
    pub(super) seq: u8,
    pub(super) req: Request,
}

/// What the owner saw in one turn.
#[derive(Debug, Clone)]
pub enum Event {
    Telemetry(Telemetry),
    Status(Status),
    /// The line failed; the owner keeps trying to reopen it.
    LinkLost(String),
    /// The line is back (the version checked again).
    LinkBack,
    /// A socket client's request was relayed (what it was, for the event log).
    Relayed(Box<Request>),
}

/// The owner of one rig's port.
pub struct Owner {
    target: Target,
    sim: SimOptions,
    session: Option<Session>,
    socket: Option<PathBuf>,
    jobs: Receiver<Job>,
    job_tx: Sender<Job>,
    clients: Receiver<(usize, Stream)>,
    client_tx: Sender<(usize, Stream)>,
    writers: Vec<(usize, Stream, bool)>,
    /// Each socket client's last command and its answer: a client resends what it got no
    /// answer to under the same seq, and gets the answer without the rig carrying it out twice.
    answered: Vec<(usize, u8, Request, Response)>,
    next_alive: Instant,
    next_reopen: Instant,
}

impl Owner {
    /// Opens the rig and, for a serial port, its control socket.
    pub fn start(target: Target, sim: SimOptions) -> Result<Self> {
        let session = session::open(&target, &sim)?;
        let (job_tx, jobs) = mpsc::channel();
        let (client_tx, clients) = mpsc::channel();
        let socket = match &target {
            Target::Serial { path } => listen(path, job_tx.clone(), client_tx.clone())?,
            Target::Sim => None,
        };
        let mut o = Self {
            target,
            sim,
            session: Some(session),
            socket,
            jobs,
            job_tx,
            clients,
            client_tx,
            writers: Vec::new(),
            answered: Vec::new(),
            next_alive: Instant::now(),
            next_reopen: Instant::now(),
        };
        o.stream()?;
        Ok(o)
    }

    /// The connection, while the line is up.
    pub fn session(&mut self) -> Option<&mut Session> {
        self.session.as_mut()
    }

    /// Where one-shot commands reach this owner, if anywhere.
    pub fn socket(&self) -> Option<&Path> {
        self.socket.as_deref()
    }

    fn stream(&mut self) -> Result<()> {
        if let Some(s) = self.session.as_mut() {
            s.call(|c| c.stream_telemetry(TELEMETRY_MS))?;
        }
        Ok(())
    }

    /// One turn: new socket clients, relayed requests, the keep-alive, telemetry, and a lost
    /// line reopened. Returns what happened.
    pub fn turn(&mut self) -> Vec<Event> {
        let mut events = Vec::new();
        while let Ok((id, stream)) = self.clients.try_recv() {
            self.writers.push((id, stream, false));
        }
        if self.session.is_none() {
            if Instant::now() >= self.next_reopen {
                self.next_reopen = Instant::now() + REOPEN_EVERY;
                if let Ok(s) = session::open(&self.target, &self.sim) {
                    self.session = Some(s);
                    if let Target::Serial { path } = &self.target {
                        self.socket = listen(path, self.job_tx.clone(), self.client_tx.clone())
                            .ok()
                            .flatten();
                    }
                    if self.stream().is_ok() {
                        events.push(Event::LinkBack);
                    }
                }
            } else {
                std::thread::sleep(Duration::from_millis(10));
            }
            // Requests that came in meanwhile time out at their clients.
            while self.jobs.try_recv().is_ok() {}
            return events;
        }
        while let Ok(job) = self.jobs.try_recv() {
            self.relay(job, &mut events);
        }
        if Instant::now() >= self.next_alive {
            self.next_alive = Instant::now() + KEEP_ALIVE;
            match self.session.as_mut().map(|s| s.client.status()) {
                Some(Ok(st)) => events.push(Event::Status(st)),
                Some(Err(e)) => self.lost(e, &mut events),
                None => {}
            }
        }
        // A bounded batch: a rig faster than real time streams a frame every millisecond, and
        // requests must not wait behind them.
        for _ in 0..TELEMETRY_BATCH {
            let Some(s) = self.session.as_mut() else {
                break;
            };
            match s.client.telemetry_now() {
                Ok(Some(t)) => {
                    self.fan_out(&Response::Telemetry(t));
                    events.push(Event::Telemetry(t));
                }
                Ok(None) => break,
                Err(e) => {
                    self.lost(e, &mut events);
                    break;
                }
            }
        }
        events
    }

    /// Sends a command of the owner's own (the monitor's keys).
    pub fn command(&mut self, req: Request) -> Result<Response, Error> {
        match self.session.as_mut() {
            Some(s) => s.client.request(req),
            None => Err(Error::Line(LineError::Timeout)),
        }
    }

    /// Stops the drive (a soft stop) and lets go of the port and the socket. Says whether the
    /// rig confirmed the stop: without a line, or when it does not answer, it stops by itself
    /// once the line has been silent for its link timeout.
    pub fn shutdown(mut self) -> bool {
        let stopped = match self.session.as_mut() {
            Some(s) => {
                let stopped = s.client.stop().is_ok();
                let _ = s.client.stream_telemetry(0);
                stopped
            }
            None => false,
        };
        if let Some(p) = self.socket.take() {
            let _ = std::fs::remove_file(p);
        }
        stopped
    }

    fn lost(&mut self, e: Error, events: &mut Vec<Event>) {
        // A refusal is an answer: the line is fine.
        if let Error::Refused(_) = e {
            return;
        }
        self.session = None;
        self.next_reopen = Instant::now() + REOPEN_EVERY;
        // No socket while there is no rig behind it: the device name may come back as
        // another rig's (a pseudo-terminal's number is reused), whose commands must not
        // reach this owner.
        if let Some(p) = self.socket.take() {
            let _ = std::fs::remove_file(p);
        }
        events.push(Event::LinkLost(e.to_string()));
    }

    fn relay(&mut self, job: Job, events: &mut Vec<Event>) {
        let answer = match job.req {
            // The owner streams already; a client's wish only says whether it wants copies.
            Request::Telemetry { period_ms } => {
                for w in &mut self.writers {
                    if w.0 == job.client {
                        w.2 = period_ms > 0;
                    }
                }
                Some(Response::Ok)
            }
            req => match self
                .answered
                .iter()
                .find(|a| (a.0, a.1, &a.2) == (job.client, job.seq, &req))
            {
                Some(a) => Some(a.3),
                None => {
                    events.push(Event::Relayed(Box::new(req)));
                    let answer = match self.session.as_mut().map(|s| s.client.request(req)) {
                        Some(Ok(r)) => Some(r),
                        Some(Err(Error::Refused(r))) => Some(Response::Refused(r)),
                        Some(Err(e)) => {
                            self.lost(e, events);
                            None
                        }
                        None => None,
                    };
                    self.answered.retain(|a| a.0 != job.client);
                    let query = matches!(
                        req,
                        Request::GetVersion | Request::GetStatus | Request::GetConfig
                    );
                    if let (Some(r), false) = (answer, query) {
                        self.answered.push((job.client, job.seq, req, r));
                    }
                    answer
                }
            },
        };
        if let Some(resp) = answer {
            let mut frame = [0u8; MAX_RESPONSE_FRAME];
            if let Ok(n) = encode(Header::new(job.seq), &resp, &mut frame) {
                self.writers
                    .retain_mut(|w| w.0 != job.client || still_there(w.1.write_all(&frame[..n])));
            }
        }
        let writers = &self.writers;
        self.answered.retain(|a| writers.iter().any(|w| w.0 == a.0));
    }

    fn fan_out(&mut self, resp: &Response) {
        let mut frame = [0u8; MAX_RESPONSE_FRAME];
        if let Ok(n) = encode(Header::new(0), resp, &mut frame) {
            self.writers
                .retain_mut(|w| !w.2 || still_there(w.1.write_all(&frame[..n])));
        }
    }
}

/// Whether a socket client is still there after a write: a client that does not read loses
/// frames (the write times out), never the owner its turn; a closed one is forgotten.
pub(super) fn still_there(r: std::io::Result<()>) -> bool {
    match r {
        Ok(()) => true,
        Err(e) => matches!(
            e.kind(),
            std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
        ),
    }
}

impl Drop for Owner {
    fn drop(&mut self) {
        if let Some(p) = self.socket.take() {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// Binds the control socket of `port` and accepts clients on a thread of its own; each
/// client's frames are read on a thread and queued as jobs. None on a system without control
/// sockets ([`control_socket::SUPPORTED`]).
pub(super) fn listen(
    port: &str,
    jobs: Sender<Job>,
    clients: Sender<(usize, Stream)>,
) -> Result<Option<PathBuf>> {
    if !control_socket::SUPPORTED {
        return Ok(None);
    }
    let path = socket_path(port);
    let dir = path.parent().context("control socket path")?;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    if Stream::connect(&path).is_ok() {
        anyhow::bail!(
            "{port} already has an owner (its control socket {} answers)",
            path.display()
        );
    }
    let _ = std::fs::remove_file(&path);
    // A marker left by a command that died without its cleanup (`super::served`).
    let _ = std::fs::remove_file(path.with_extension("busy"));
    let listener = Listener::bind(&path)
        .with_context(|| format!("cannot open the control socket {}", path.display()))?;
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let id = NEXT_CLIENT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let Ok(writer) = stream.try_clone() else {
                continue;
            };
            let _ = writer.set_write_timeout(Some(Duration::from_millis(20)));
            if clients.send((id, writer)).is_err() {
                return;
            }
            let jobs = jobs.clone();
            std::thread::spawn(move || read_client(id, stream, jobs));
        }
    });
    Ok(Some(path))
}

fn read_client(client: usize, mut stream: Stream, jobs: Sender<Job>) {
    let mut reader = FrameReader::<MAX_REQUEST_FRAME>::new();
    let mut buf = [0u8; 256];
    while let Ok(n) = stream.read(&mut buf) {
        if n == 0 {
            return;
        }
        for &b in &buf[..n] {
            let Some(Ok(stuffed)) = reader.push(b) else {
                continue;
            };
            // A damaged local frame: the client times out and resends.
            let (seq, Ok(req)) = receive_request(stuffed) else {
                continue;
            };
            if jobs.send(Job { client, seq, req }).is_err() {
                return;
            }
        }
    }
}
