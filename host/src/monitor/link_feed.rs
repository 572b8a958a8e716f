//! A [`Feed`] over the serial-link [`Client`]: an I/O thread owns the client and the port, so
//! the monitor never waits on the line.
//!
//! ```text
//! I/O thread:  connect → version check → configuration → telemetry stream → Linked
//!              loop: commands from the monitor, answered in order
//!                    GetStatus every 250 ms of rig time (the keep-alive; also every 250 ms
//!                    of wall time, should telemetry stop) → Status
//!                    telemetry → Telemetry
//!              a line failure → LinkLost, then connect again until the rig is back
//! ```
//! The events go through a bounded channel: a monitor that falls behind holds the thread back
//! (a simulated rig then waits too) rather than piling up frames. The thread ends when the feed
//! is dropped.

use std::io::{Read, Write};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, SyncSender, TryRecvError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use kapitza_core::link::PROTOCOL_VERSION;

use super::feed::{Command, Event, Feed};
use crate::link::{Client, Error};

/// The keep-alive period: well inside the rig's link timeout (1 s in the reference config).
const KEEP_ALIVE: Duration = Duration::from_millis(250);
/// Telemetry period asked of the rig (ms).
const TELEMETRY_MS: u16 = 20;
/// Pause between attempts to reach a rig that is not there.
const RETRY: Duration = Duration::from_millis(500);
/// How long a command may take, answer included.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(5);
/// Events the channel holds before the I/O thread waits for the monitor.
const BACKLOG: usize = 256;

/// Opens the port, again after every loss; `Err` names why the rig cannot be reached now.
pub type Connect<P> = Box<dyn FnMut() -> Result<P, String> + Send>;

type Reply = Sender<Result<(), String>>;

/// The monitor's end: see the [module doc](self).
pub struct LinkFeed {
    events: Receiver<Event>,
    commands: Sender<(Command, Reply)>,
    /// Events that arrived while a command waited for its answer.
    early: std::collections::VecDeque<Event>,
    thread: Option<JoinHandle<()>>,
}

impl LinkFeed {
    /// Starts the I/O thread on ports from `connect`.
    pub fn spawn<P: Read + Write + Send + 'static>(connect: Connect<P>) -> Self {
        let (ev_tx, events) = mpsc::sync_channel(BACKLOG);
        let (commands, cmd_rx) = mpsc::channel();
        let thread = std::thread::spawn(move || io_thread(connect, &ev_tx, &cmd_rx));
        Self {
            events,
            commands,
            early: Default::default(),
            thread: Some(thread),
        }
    }
}

impl Drop for LinkFeed {
    fn drop(&mut self) {
        // Closing both channels ends the thread at its next send or command check.
        let (_, dead) = mpsc::sync_channel(0);
        drop(std::mem::replace(&mut self.events, dead));
        let (dead, _) = mpsc::channel();
        drop(std::mem::replace(&mut self.commands, dead));
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Feed for LinkFeed {
    fn next_event(&mut self, timeout: Duration) -> Option<Event> {
        if let Some(e) = self.early.pop_front() {
            return Some(e);
        }
        self.events.recv_timeout(timeout).ok()
    }

    fn command(&mut self, c: Command) -> Result<(), String> {
        let (tx, rx) = mpsc::channel();
        self.commands
            .send((c, tx))
            .map_err(|_| "the link's thread has ended".to_string())?;
        let deadline = Instant::now() + COMMAND_TIMEOUT;
        loop {
            match rx.try_recv() {
                Ok(r) => return r,
                Err(TryRecvError::Disconnected) => return Err("the link's thread has ended".into()),
                Err(TryRecvError::Empty) => {}
            }
            if Instant::now() >= deadline {
                return Err("no answer in time".into());
            }
            // Keep the events flowing so the thread is never stuck on a full channel.
            match self.events.recv_timeout(Duration::from_millis(1)) {
                Ok(e) => self.early.push_back(e),
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    return Err("the link's thread has ended".into())
                }
            }
        }
    }
}

/// Why a session with the rig ended.
enum End {
    /// The monitor is gone.
    Closed,
    Lost(String),
}

fn io_thread<P: Read + Write>(
    mut connect: Connect<P>,
    events: &SyncSender<Event>,
    commands: &Receiver<(Command, Reply)>,
) {
    let mut last_failure = String::new();
    loop {
        let why = match connect() {
            Ok(port) => match run_session(&mut Client::new(port), events, commands) {
                Ok(()) | Err(End::Closed) => return,
                Err(End::Lost(why)) => {
                    if events.send(Event::LinkLost(why.clone())).is_err() {
                        return;
                    }
                    why
                }
            },
            Err(why) => why,
        };
        // Say once why the rig cannot be reached, not every half second.
        if why != last_failure {
            if events
                .send(Event::Note(format!("waiting for the rig: {why}")))
                .is_err()
            {
                return;
            }
            last_failure = why;
        }
        // Refuse commands while the rig is away; end if the monitor is gone.
        let until = Instant::now() + RETRY;
        while Instant::now() < until {
            match commands.recv_timeout(Duration::from_millis(20)) {
                Ok((_, reply)) => {
                    let _ = reply.send(Err("the link is down".into()));
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => return,
            }
        }
    }
}

fn line<T>(r: Result<T, Error>) -> Result<T, End> {
    r.map_err(|e| End::Lost(e.to_string()))
}

fn send(events: &SyncSender<Event>, e: Event) -> Result<(), End> {
    events.send(e).map_err(|_| End::Closed)
}

/// One connection, from the version check until the line fails (`Err(Lost)`) or the monitor
/// goes.
fn run_session<P: Read + Write>(
    client: &mut Client<P>,
    events: &SyncSender<Event>,
    commands: &Receiver<(Command, Reply)>,
) -> Result<(), End> {
    let v = line(client.version())?;
    if v.protocol != PROTOCOL_VERSION {
        return Err(End::Lost(format!(
            "the rig speaks link protocol {}, this tool {PROTOCOL_VERSION}: flash the firmware \
             that matches this host tool",
            v.protocol
        )));
    }
    let config = line(client.config())?;
    line(client.stream_telemetry(TELEMETRY_MS))?;
    send(
        events,
        Event::Linked {
            protocol: v.protocol,
            firmware: v.firmware,
            config,
        },
    )?;
    let mut status_wall = Instant::now() - KEEP_ALIVE;
    let mut rig_us_since_status = u64::MAX;
    let mut last_t_us: Option<u32> = None;
    loop {
        loop {
            match commands.try_recv() {
                Ok((c, reply)) => {
                    let r = match c {
                        Command::Stop => client.stop(),
                        Command::ClearFault => client.clear_fault(),
                        Command::SetDrive { r, theta_d_deg } => client.set_drive(r, theta_d_deg),
                    };
                    let lost = matches!(r, Err(Error::Line(_)));
                    let _ = reply.send(r.as_ref().map_err(ToString::to_string).copied());
                    if lost {
                        line(r)?;
                    }
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return Ok(()),
            }
        }
        if rig_us_since_status >= KEEP_ALIVE.as_micros() as u64
            || status_wall.elapsed() >= KEEP_ALIVE
        {
            let s = line(client.status())?;
            send(events, Event::Status(s))?;
            status_wall = Instant::now();
            rig_us_since_status = 0;
        }
        match client.telemetry() {
            Ok(t) => {
                if let Some(last) = last_t_us {
                    rig_us_since_status =
                        rig_us_since_status.saturating_add(u64::from(t.t_us.wrapping_sub(last)));
                }
                last_t_us = Some(t.t_us);
                send(events, Event::Telemetry(t))?;
            }
            // No telemetry: if the rig still answers, it forgot the stream (a restart).
            Err(_) => {
                line(client.status())?;
                line(client.stream_telemetry(TELEMETRY_MS))?;
            }
        }
    }
}
