//! A [`Feed`] over a port this process owns ([`crate::rig::owner::Owner`]): the monitor is
//! then the port's owner, keeps the link alive, serves the control socket that `kapitza set`,
//! `status` and `stop` in other terminals use, and reopens a lost line at the same path. When
//! the feed is dropped the drive is told to stop and the socket goes away.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use kapitza_core::link::convert::{from_q16, to_q16};
use kapitza_core::link::{Request, Response};

use super::feed::{Command, Event, Feed};
use crate::rig::owner::{self, Owner};

/// A request relayed from another terminal, as the event log shows it; `None` for the routine
/// traffic of every one-shot command (version, status, configuration read, telemetry stream),
/// which would push the events out of the pane.
fn relayed(req: &Request) -> Option<String> {
    Some(match req {
        Request::GetVersion
        | Request::GetStatus
        | Request::GetConfig
        | Request::Telemetry { .. } => return None,
        Request::SetDrive { r, theta_d_deg } if *r == 0 => {
            format!("stop (R = 0, θd = {:.1}°)", from_q16(*theta_d_deg))
        }
        Request::SetDrive { r, theta_d_deg } => format!(
            "set R = {:.3}, θd = {:.1}°",
            from_q16(*r),
            from_q16(*theta_d_deg)
        ),
        Request::Stop => "stop".into(),
        Request::ClearFault => "clear fault".into(),
        Request::SetConfig(_) => "new configuration".into(),
        other => format!("{other:?}"),
    })
}

type Reply = Sender<Result<(), String>>;

/// How long a command may take, answer included.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(5);

/// The monitor's end of an owner running on its own thread.
pub struct OwnerFeed {
    events: Receiver<Event>,
    /// Events that arrived while a command waited for its answer.
    early: VecDeque<Event>,
    commands: Sender<(Command, Reply)>,
    stop: Arc<AtomicBool>,
    /// Ends with whether the rig confirmed the stop.
    thread: Option<JoinHandle<bool>>,
}

fn linked(o: &mut Owner) -> Option<Event> {
    o.session().map(|s| Event::Linked {
        protocol: s.version.protocol,
        firmware: s.version.firmware,
        config: Box::new(s.config),
    })
}

fn request(c: Command) -> Request {
    match c {
        Command::Stop => Request::Stop,
        Command::ClearFault => Request::ClearFault,
        Command::SetDrive { r, theta_d_deg } => Request::SetDrive {
            r: to_q16(r),
            theta_d_deg: to_q16(theta_d_deg),
        },
    }
}

impl OwnerFeed {
    /// Runs `owner` on a thread of its own.
    pub fn spawn(mut owner: Owner) -> Self {
        let (ev_tx, events) = mpsc::sync_channel(256);
        let (commands, cmd_rx) = mpsc::channel::<(Command, Reply)>();
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::spawn(move || {
            if let Some(p) = owner.socket() {
                let _ = ev_tx.send(Event::Note(format!("control socket {}", p.display())));
            }
            if let Some(e) = linked(&mut owner) {
                let _ = ev_tx.send(e);
            }
            while !flag.load(Ordering::Relaxed) {
                while let Ok((c, reply)) = cmd_rx.try_recv() {
                    let r = match owner.command(request(c)) {
                        Ok(Response::Ok) => Ok(()),
                        Ok(other) => Err(format!("unexpected answer {other:?}")),
                        Err(e) => Err(e.to_string()),
                    };
                    let _ = reply.send(r);
                }
                for e in owner.turn() {
                    let ev = match e {
                        owner::Event::Telemetry(t) => Event::Telemetry(t),
                        owner::Event::Status(s) => Event::Status(s),
                        owner::Event::LinkLost(why) => Event::LinkLost(why),
                        owner::Event::LinkBack => match linked(&mut owner) {
                            Some(e) => e,
                            None => continue,
                        },
                        owner::Event::Relayed(req) => match relayed(&req) {
                            Some(what) => Event::Note(format!("from another terminal: {what}")),
                            None => continue,
                        },
                    };
                    if ev_tx.send(ev).is_err() {
                        // Nobody is watching any more: the rig's own timeout backs the stop.
                        return owner.shutdown();
                    }
                }
                std::thread::sleep(Duration::from_millis(2));
            }
            owner.shutdown()
        });
        Self {
            events,
            early: VecDeque::new(),
            commands,
            stop,
            thread: Some(thread),
        }
    }
}

impl Feed for OwnerFeed {
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
        // The owner's thread may be handing over events meanwhile: keep them, in order.
        let deadline = Instant::now() + COMMAND_TIMEOUT;
        loop {
            match rx.recv_timeout(Duration::from_millis(5)) {
                Ok(r) => return r,
                Err(RecvTimeoutError::Disconnected) => {
                    return Err("the link's thread has ended".to_string())
                }
                Err(RecvTimeoutError::Timeout) if Instant::now() >= deadline => {
                    return Err("no answer from the rig".to_string())
                }
                Err(RecvTimeoutError::Timeout) => self.early.extend(self.events.try_iter()),
            }
        }
    }

    fn close(&mut self) -> Option<bool> {
        self.stop.store(true, Ordering::Relaxed);
        // Let go of the events first: a thread waiting to hand one over then sees the end.
        drop(std::mem::replace(&mut self.events, mpsc::sync_channel(0).1));
        let t = self.thread.take()?;
        Some(t.join().unwrap_or(false))
    }
}

impl Drop for OwnerFeed {
    fn drop(&mut self) {
        let _ = self.close();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn routine_requests_stay_out_of_the_event_log() {
        for r in [
            Request::GetVersion,
            Request::GetStatus,
            Request::GetConfig,
            Request::Telemetry { period_ms: 20 },
        ] {
            assert_eq!(relayed(&r), None, "{r:?}");
        }
        let set = Request::SetDrive {
            r: to_q16(1.75),
            theta_d_deg: to_q16(80.0),
        };
        assert_eq!(relayed(&set).as_deref(), Some("set R = 1.750, θd = 80.0°"));
        assert_eq!(relayed(&Request::Stop).as_deref(), Some("stop"));
        assert_eq!(
            relayed(&Request::ClearFault).as_deref(),
            Some("clear fault")
        );
    }
}
