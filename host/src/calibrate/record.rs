//! Sensor streams over the link for a stretch of *rig* time (a simulated rig may run faster
//! than the wall clock), with a keep-alive often enough that the rig's link-silence policy never
//! ends the stretch. Frames taken before the stretch's first command are skipped. Every turn
//! asks the [`Watch`] first: a signal or a stop from elsewhere ends the stretch at once.

use std::time::{Duration, Instant};

use anyhow::Result;
use kapitza_core::link::message::RawTelemetry;
use kapitza_core::link::Telemetry;

use super::watch::{Driving, Watch};
use crate::link::{Client, Error, LineError};
use crate::rig::port::ReadWrite;
use crate::rig::session::{line_failure, Session};

/// A request at least this often (wall time): well inside the rig's 1 s link timeout.
const KEEP_ALIVE: Duration = Duration::from_millis(200);
/// Give up when no frame arrives for this long (wall time).
const SILENCE: Duration = Duration::from_secs(5);

/// A streamed frame: when it was taken, and the rig's command count then.
trait Stamped {
    fn t_us(&self) -> u32;
    fn commands(&self) -> u32;
    /// The frame as the socket's clients take it, if they do.
    fn telemetry(&self) -> Option<&Telemetry> {
        None
    }
}

impl Stamped for RawTelemetry {
    fn t_us(&self) -> u32 {
        self.t_us
    }
    fn commands(&self) -> u32 {
        self.commands
    }
}

impl Stamped for Telemetry {
    fn t_us(&self) -> u32 {
        self.t_us
    }
    fn commands(&self) -> u32 {
        self.commands
    }
    fn telemetry(&self) -> Option<&Telemetry> {
        Some(self)
    }
}

/// The raw sensors for `secs` of rig time from now, each frame with its time (s) from the first.
pub fn raw(s: &mut Session, w: &mut Watch, secs: f64) -> Result<Vec<(f64, RawTelemetry)>> {
    Ok(stream(s, w, secs, |c| c.raw_telemetry(), |_, _| false)?.0)
}

/// Raw telemetry until `done` says so (given each frame and the rig seconds since the first), or
/// until `secs` of rig time have passed; the flag says which.
pub fn raw_until(
    s: &mut Session,
    w: &mut Watch,
    secs: f64,
    done: impl FnMut(&RawTelemetry, f64) -> bool,
) -> Result<(Vec<(f64, RawTelemetry)>, bool)> {
    stream(s, w, secs, |c| c.raw_telemetry(), done)
}

/// Telemetry until `done` says so (given each frame and the rig seconds since the first), or
/// until `secs` of rig time have passed; the flag says which.
pub fn telemetry(
    s: &mut Session,
    w: &mut Watch,
    secs: f64,
    done: impl FnMut(&Telemetry, f64) -> bool,
) -> Result<(Vec<(f64, Telemetry)>, bool)> {
    stream(s, w, secs, |c| c.telemetry(), done)
}

type Link = Client<Box<dyn ReadWrite>>;

fn stream<T: Stamped>(
    s: &mut Session,
    w: &mut Watch,
    secs: f64,
    mut next: impl FnMut(&mut Link) -> Result<T, Error>,
    mut done: impl FnMut(&T, f64) -> bool,
) -> Result<(Vec<(f64, T)>, bool)> {
    let mut driving = Driving::default();
    let st = s.call(|c| c.status())?;
    driving.check(&st)?;
    let after = st.counters.commands;
    let mut out = Vec::new();
    let mut t0 = None;
    let mut alive = Instant::now() + KEEP_ALIVE;
    let mut heard = Instant::now();
    loop {
        w.tick(s)?;
        if Instant::now() >= alive {
            driving.check(&s.call(|c| c.status())?)?;
            alive = Instant::now() + KEEP_ALIVE;
        }
        match next(&mut s.client) {
            Ok(f) if f.commands() >= after => {
                heard = Instant::now();
                if let Some(t) = f.telemetry() {
                    w.fan_out(t);
                }
                let t0 = *t0.get_or_insert(f.t_us());
                let t = f64::from(f.t_us().wrapping_sub(t0)) * 1e-6;
                let stop = done(&f, t);
                out.push((t, f));
                if stop || t >= secs {
                    return Ok((out, stop));
                }
            }
            Ok(_) | Err(Error::Line(LineError::Timeout)) => {}
            Err(e) => return Err(line_failure(&s.name, e)),
        }
        if heard.elapsed() > SILENCE {
            return Err(line_failure(&s.name, Error::Line(LineError::Timeout)));
        }
    }
}
