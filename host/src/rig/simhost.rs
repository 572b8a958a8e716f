//! The simulated rig run against the wall clock: real time, or `speed` times faster, with its
//! bytes going to a line that never blocks it (a pseudo-terminal's master for `kapitza rig
//! serve`, a pair of channels for the in-process `--port sim`).
//!
//! ```text
//! loop:  bytes from the line → the rig (link clock = wall µs since start)
//!        physics up to wall × speed, at most MAX_BATCH of rig time per turn
//!        frame bytes → the line, as many as it takes now (the rest wait; the rig drops and
//!        counts telemetry when nobody reads)
//!        sleep a little when the physics is ahead of the clock
//! ```
//! The rig's link-silence timer runs on the link clock, which is wall time at every speed: a
//! 1 s timeout stays 1 s of the laptop's time.

use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{
    self, Receiver, RecvTimeoutError, Sender, SyncSender, TryRecvError, TrySendError,
};
use std::time::{Duration, Instant};

use kapitza_core::link::convert::deg_along_travel;
use kapitza_core::link::message::Check;
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::dds::omega_of_word;
use kapitza_core::simrig::SimRig;
use kapitza_core::station::serve::{Activity, RigServer};
use serde::Serialize;

use super::file::RigFile;
use super::names::mode_name;

/// At most this much rig time (s) between two looks at the line.
const MAX_BATCH: f64 = 0.005;

/// This host tool's version, as the simulated rig's firmware version.
pub const FIRMWARE: [u16; 3] = [0, 1, 0];

/// How to run a simulated rig.
#[derive(Debug, Clone)]
pub struct SimOptions {
    pub rig: RigFile,
    /// Rig seconds per wall second; `f64::INFINITY`: as fast as the laptop reads (the rig
    /// waits while its bytes wait, so nothing is dropped).
    pub speed: f64,
    /// Speak another link protocol version (for tests of version skew).
    pub protocol: Option<u8>,
    /// Power up with the e-stop held: the safe defaults, the rig file's configuration (the
    /// flash's) left for the next power-up (`persist::store::boot`).
    pub estop_at_power_up: bool,
}

impl SimOptions {
    pub fn new(rig: RigFile, speed: f64) -> Self {
        Self {
            rig,
            speed,
            protocol: None,
            estop_at_power_up: false,
        }
    }

    /// The rig, powered up with its configuration as if loaded from flash.
    pub fn build(&self) -> SimRig {
        let r = &self.rig;
        let (cfg, origin) = if self.estop_at_power_up {
            (RigConfig::REFERENCE, ConfigOrigin::DefaultsByEstop)
        } else {
            (r.config, ConfigOrigin::Stored)
        };
        let sim = SimRig::new(r.params, cfg, origin, FIRMWARE);
        match self.protocol {
            Some(v) => sim.speaking(v),
            None => sim,
        }
    }
}

/// Where the rig's bytes come from and go to. Neither call may block.
pub trait Line {
    /// Bytes from the laptop now (0: none). An error ends the run.
    fn take(&mut self, buf: &mut [u8]) -> io::Result<usize>;
    /// Bytes to the laptop: as many as the line takes now (possibly 0).
    fn give(&mut self, buf: &[u8]) -> io::Result<usize>;
}

/// One setting the rig applied, for the truth log: written whenever its command counter moves,
/// except for a start waiting for its pre-run check, which is written when it passes (a start
/// whose check fails applies nothing).
#[derive(Debug, Clone, Serialize)]
pub struct Applied {
    /// Rig seconds since power-up.
    pub t_s: f64,
    pub commands: u32,
    pub mode: &'static str,
    pub omega_target: f64,
    pub r_target: f64,
    pub drive_angle_target_deg: f64,
    /// In bring-up mode: its open-loop duty (the crank's motor, 0 when only the servo holds);
    /// else null.
    pub bring_up_duty: Option<f64>,
}

impl Applied {
    fn of(srv: &RigServer, t_s: f64) -> Self {
        let sup = srv.rig.supervisor();
        let omega = omega_of_word(sup.target_word());
        Self {
            t_s,
            commands: srv.counters.commands,
            mode: mode_name(&srv.rig.supervisor().mode().into()),
            omega_target: omega,
            r_target: srv.cfg.r_for_omega(omega),
            drive_angle_target_deg: deg_along_travel(
                sup.theta_d_target(),
                srv.cfg.limits.drive_angle_min_deg,
            ),
            bring_up_duty: match srv.activity {
                Activity::BringUp { duty } => Some(f64::from(duty.to_bits()) / 32_768.0),
                _ => None,
            },
        }
    }
}

/// What a run did.
#[derive(Debug, Clone, Copy, Default)]
pub struct Summary {
    pub rig_seconds: f64,
    pub wall_seconds: f64,
}

/// Runs `sim` against `line` until `stop()` says so or the line fails; `truth` receives one
/// JSON line per setting applied.
pub fn run(
    mut sim: SimRig,
    speed: f64,
    line: &mut impl Line,
    stop: &dyn Fn() -> bool,
    mut truth: Option<&mut dyn Write>,
) -> io::Result<Summary> {
    let start = Instant::now();
    let mut inbox = [0u8; 256];
    let mut out = [0u8; 256];
    let (mut out_from, mut out_to) = (0, 0);
    let mut commands = sim.counters().commands;
    let mut check = None;
    while !stop() {
        let wall = start.elapsed();
        let link_us = Some(wall.as_micros() as u32);
        loop {
            let n = line.take(&mut inbox)?;
            if n == 0 {
                break;
            }
            sim.receive(&inbox[..n], link_us);
        }
        if let Some(w) = truth.as_deref_mut() {
            let now = sim.counters().commands;
            let srv = sim.rig().server();
            let verdict = check == Some(Check::Running) && srv.check != Some(Check::Running);
            let passed = verdict && srv.check == Some(Check::Passed);
            check = srv.check;
            let waiting = matches!(srv.activity, Activity::Checking { .. });
            if verdict && !passed {
                // A failed check: its start applied nothing.
                commands = now;
            }
            if !waiting && (passed || now != commands) {
                commands = now;
                let a = Applied::of(sim.rig().server(), sim.seconds());
                serde_json::to_writer(&mut *w, &a)?;
                w.write_all(b"\n")?;
                w.flush()?;
            }
        }
        let unpaced = speed.is_infinite();
        let due = if unpaced {
            sim.seconds() + MAX_BATCH
        } else {
            (wall.as_secs_f64() * speed).min(sim.seconds() + MAX_BATCH)
        };
        while sim.seconds() < due {
            if unpaced && (out_from != out_to || sim.rig().pending() > 0) {
                break;
            }
            sim.step(link_us);
        }
        loop {
            if out_from == out_to {
                out_from = 0;
                out_to = sim.transmit(&mut out);
                if out_to == 0 {
                    break;
                }
            }
            let n = line.give(&out[out_from..out_to])?;
            out_from += n;
            if n == 0 {
                break;
            }
        }
        let waiting = if unpaced {
            out_from != out_to
        } else {
            sim.seconds() >= wall.as_secs_f64() * speed
        };
        if waiting {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    Ok(Summary {
        rig_seconds: sim.seconds(),
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}

/// The laptop's end of an in-process simulated rig: a byte port over two channels. Reading
/// waits up to 5 ms for bytes, as a serial port's read timeout does.
pub struct SimPort {
    to_rig: Sender<Vec<u8>>,
    from_rig: Receiver<Vec<u8>>,
    pending: Vec<u8>,
    stop: std::sync::Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

/// The rig's end of the channels.
struct ChannelLine {
    from_laptop: Receiver<Vec<u8>>,
    to_laptop: SyncSender<Vec<u8>>,
    pending: Vec<u8>,
}

impl Line for ChannelLine {
    fn take(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.pending.is_empty() {
            match self.from_laptop.try_recv() {
                Ok(v) => self.pending = v,
                Err(TryRecvError::Empty) => return Ok(0),
                Err(TryRecvError::Disconnected) => return Err(io::ErrorKind::BrokenPipe.into()),
            }
        }
        let n = buf.len().min(self.pending.len());
        buf[..n].copy_from_slice(&self.pending[..n]);
        self.pending.drain(..n);
        Ok(n)
    }
    fn give(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self.to_laptop.try_send(buf.to_vec()) {
            Ok(()) => Ok(buf.len()),
            // The laptop is not reading: the line is full, as a serial line would be.
            Err(TrySendError::Full(_)) => Ok(0),
            Err(TrySendError::Disconnected(_)) => Err(io::ErrorKind::BrokenPipe.into()),
        }
    }
}

/// Chunks of rig bytes the in-process line holds before it counts as full (a few frames).
const LINE_CHUNKS: usize = 16;

impl SimPort {
    /// Starts the simulated rig on its own thread.
    pub fn start(opts: &SimOptions) -> Self {
        let (to_rig, from_laptop) = mpsc::channel();
        let (to_laptop, from_rig) = mpsc::sync_channel(LINE_CHUNKS);
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let sim = opts.build();
        let speed = opts.speed;
        let flag = stop.clone();
        let thread = std::thread::spawn(move || {
            let mut line = ChannelLine {
                from_laptop,
                to_laptop,
                pending: Vec::new(),
            };
            // The run ends when the laptop's end is dropped (the channel breaks) or on `stop`.
            let _ = run(
                sim,
                speed,
                &mut line,
                &|| flag.load(Ordering::Relaxed),
                None,
            );
        });
        Self {
            to_rig,
            from_rig,
            pending: Vec::new(),
            stop,
            thread: Some(thread),
        }
    }
}

impl io::Read for SimPort {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.pending.is_empty() {
            match self.from_rig.recv_timeout(Duration::from_millis(5)) {
                Ok(v) => self.pending = v,
                Err(RecvTimeoutError::Timeout) => return Err(io::ErrorKind::TimedOut.into()),
                Err(RecvTimeoutError::Disconnected) => return Err(io::ErrorKind::BrokenPipe.into()),
            }
        }
        let n = buf.len().min(self.pending.len());
        buf[..n].copy_from_slice(&self.pending[..n]);
        self.pending.drain(..n);
        Ok(n)
    }
}

impl Write for SimPort {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.to_rig
            .send(buf.to_vec())
            .map_err(|_| io::Error::from(io::ErrorKind::BrokenPipe))?;
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Drop for SimPort {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
