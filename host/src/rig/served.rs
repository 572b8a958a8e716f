//! The control socket of a command that drives the link itself (`kapitza calibrate` with no
//! owner running): it owns the port for as long as it runs, so `kapitza stop` and `status` from
//! another terminal come through here. What only reads is relayed, a stop is relayed (and the
//! command told), and what would change the rig under the running command is refused. A marker
//! file beside the socket names the command, so `set` and `config set` refuse before they send.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver};

use anyhow::Result;
use kapitza_core::link::frame::{encode, Header};
use kapitza_core::link::{Reason, Request, Response, Telemetry, MAX_RESPONSE_FRAME};

use super::control_socket::Stream;
use super::owner::{listen, socket_path, still_there, Job};
use super::port::ReadWrite;
use crate::link::{Client, Error};

/// The control socket, while the command runs.
pub struct Served {
    socket: PathBuf,
    marker: PathBuf,
    jobs: Receiver<Job>,
    clients: Receiver<(usize, Stream)>,
    /// Each client, and whether it asked for telemetry.
    writers: Vec<(usize, Stream, bool)>,
}

fn marker_path(port: &str) -> PathBuf {
    socket_path(port).with_extension("busy")
}

/// What the command serving `port`'s socket is doing, when it is not a plain owner.
pub fn busy(port: &str) -> Option<String> {
    let text = std::fs::read_to_string(marker_path(port)).ok()?;
    Some(text.trim().to_string()).filter(|t| !t.is_empty())
}

impl Served {
    /// Serves `port`'s control socket; `busy` says what the command is doing (shown to the
    /// commands it refuses). None on a system without control sockets.
    pub fn open(port: &str, busy: &str) -> Result<Option<Self>> {
        let (job_tx, jobs) = mpsc::channel();
        let (client_tx, clients) = mpsc::channel();
        let Some(socket) = listen(port, job_tx, client_tx)? else {
            return Ok(None);
        };
        let marker = marker_path(port);
        std::fs::write(&marker, busy)?;
        Ok(Some(Self {
            socket,
            marker,
            jobs,
            clients,
            writers: Vec::new(),
        }))
    }

    pub fn socket(&self) -> &Path {
        &self.socket
    }

    /// Answers what the socket's clients asked, on `client` (the command's own link). Returns
    /// whether one of them stopped the drive.
    pub fn serve(&mut self, client: &mut Client<Box<dyn ReadWrite>>) -> Result<bool, Error> {
        while let Ok((id, stream)) = self.clients.try_recv() {
            self.writers.push((id, stream, false));
        }
        let mut stopped = false;
        while let Ok(job) = self.jobs.try_recv() {
            let answer = match job.req {
                // The command streams what it needs; a client's wish only says whether it
                // wants copies of the telemetry.
                Request::Telemetry { period_ms } => {
                    for w in &mut self.writers {
                        if w.0 == job.client {
                            w.2 = period_ms > 0;
                        }
                    }
                    Response::Ok
                }
                Request::GetVersion
                | Request::GetStatus
                | Request::GetConfig
                | Request::ClearFault
                | Request::Stop => {
                    stopped |= job.req == Request::Stop;
                    match client.request(job.req) {
                        Ok(r) => r,
                        Err(Error::Refused(r)) => Response::Refused(r),
                        Err(e) => return Err(e),
                    }
                }
                // The one-shot commands refuse these themselves (the marker); a client that
                // does not read it gets the rig's mode as the reason.
                Request::SetDrive { .. } | Request::SetConfig(_) | Request::BringUp { .. } => {
                    Response::Refused(Reason::WrongMode(client.status()?.mode))
                }
            };
            self.answer(job.client, Header::new(job.seq), &answer);
        }
        Ok(stopped)
    }

    /// Copies a telemetry frame to the clients that asked for it.
    pub fn fan_out(&mut self, t: &Telemetry) {
        let mut frame = [0u8; MAX_RESPONSE_FRAME];
        if let Ok(n) = encode(Header::new(0), &Response::Telemetry(*t), &mut frame) {
            self.writers
                .retain_mut(|w| !w.2 || still_there(w.1.write_all(&frame[..n])));
        }
    }

    fn answer(&mut self, client: usize, header: Header, resp: &Response) {
        let mut frame = [0u8; MAX_RESPONSE_FRAME];
        if let Ok(n) = encode(header, resp, &mut frame) {
            self.writers
                .retain_mut(|w| w.0 != client || still_there(w.1.write_all(&frame[..n])));
        }
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.marker);
        let _ = std::fs::remove_file(&self.socket);
    }
}
