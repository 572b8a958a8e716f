//! A connection to a rig, checked: the port opened (or the owner's control socket, or an
//! in-process simulated rig), stale input dropped, the frozen version exchange first, the
//! configuration read. And the rig's state in the units and names every JSON output uses.

use std::time::{Duration, Instant};

use anyhow::Result;
use kapitza_core::link::convert::from_q16;
use kapitza_core::link::message::{Check, Mode};
use kapitza_core::link::{Status, Telemetry, VersionInfo, PROTOCOL_VERSION};
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::config::RigConfig;
use serde::Serialize;

use super::names::{fault_name, mode_name, reset_name, stop_name, turns_deg};
use super::owner;
use super::port::{self, ReadWrite, Target};
use super::predicted::{predict, Prediction};
use super::simhost::{SimOptions, SimPort};
use super::{Exit, Failure};
use crate::link::{Client, Error, LineError};

/// Through an owner, how long one try waits: the owner's own retry window on the line behind
/// it, and some. The owner answers a resent request from its first answer, so a resend through
/// it is carried out once too.
const OWNER_TIMEOUT: Duration = Duration::from_millis(1500);
/// Through an owner, how many tries (the socket itself loses nothing).
const OWNER_TRIES: u32 = 2;

/// A checked connection.
pub struct Session {
    pub client: Client<Box<dyn ReadWrite>>,
    pub version: VersionInfo,
    pub config: RigConfig,
    /// What it is connected to, for messages.
    pub name: String,
    /// Through a running owner's control socket (`kapitza attach` / `monitor`).
    pub via_owner: bool,
}

/// Opens `target`: through its owner's control socket when one is running, else the port
/// itself (or an in-process simulated rig built from `sim`).
pub fn connect(target: &Target, sim: &SimOptions) -> Result<Session> {
    if let Target::Serial { path } = target {
        if let Some(stream) = owner::connect(path) {
            return check(
                Box::new(stream),
                format!("{path} (through its owner)"),
                true,
            );
        }
    }
    open(target, sim)
}

/// Opens `target` itself, never through an owner (the owner's own way in).
pub fn open(target: &Target, sim: &SimOptions) -> Result<Session> {
    let (port, name): (Box<dyn ReadWrite>, String) = match target {
        Target::Serial { path } => (Box::new(port::open_serial(path)?), path.clone()),
        Target::Sim => (Box::new(SimPort::start(sim)), target.describe()),
    };
    check(port, name, false)
}

/// The version exchange and the configuration, on a freshly opened port.
pub fn check(port: Box<dyn ReadWrite>, name: String, via_owner: bool) -> Result<Session> {
    let mut client = Client::new(port);
    if via_owner {
        client = client.with_timeout(OWNER_TIMEOUT).with_tries(OWNER_TRIES);
    }
    let version = client.version().map_err(|e| line_failure(&name, e))?;
    check_version(&version, &name)?;
    let config = client.config().map_err(|e| line_failure(&name, e))?;
    Ok(Session {
        client,
        version,
        config,
        name,
        via_owner,
    })
}

/// Refuses a rig that speaks another link protocol than this host tool.
pub fn check_version(version: &VersionInfo, name: &str) -> Result<()> {
    if version.protocol != PROTOCOL_VERSION {
        return Err(Failure::new(
            Exit::NoRig,
            format!(
                "{name}: the rig speaks link protocol v{} (firmware {}.{}.{}) and this host tool \
                 v{PROTOCOL_VERSION}: flash the firmware that matches this host tool \
                 (`kapitza flash`), or use the host tool that matches the firmware",
                version.protocol, version.firmware[0], version.firmware[1], version.firmware[2]
            ),
        )
        .into());
    }
    Ok(())
}

/// A failed call in terms of its exit status: refused (1) or the line (3).
pub fn line_failure(name: &str, e: Error) -> anyhow::Error {
    match e {
        Error::Refused(r) => Failure::new(Exit::Refused, format!("the rig refused: {r}")).into(),
        Error::Invalid(what) => Failure::new(Exit::Refused, format!("cannot send: {what}")).into(),
        Error::Line(LineError::VersionMismatch(r)) => Failure::new(
            Exit::NoRig,
            format!(
                "{name}: {r}: flash the firmware that matches this host tool (`kapitza flash`)"
            ),
        )
        .into(),
        Error::Line(LineError::Timeout) => Failure::new(
            Exit::NoRig,
            format!("{name}: no answer from the rig (is it powered, and is this its port?)"),
        )
        .into(),
        Error::Line(l) => Failure::new(Exit::NoRig, format!("{name}: {}", Error::Line(l))).into(),
    }
}

impl Session {
    /// Runs one call, mapping its failure to an exit status.
    pub fn call<T>(
        &mut self,
        f: impl FnOnce(&mut Client<Box<dyn ReadWrite>>) -> Result<T, Error>,
    ) -> Result<T> {
        f(&mut self.client).map_err(|e| line_failure(&self.name, e))
    }

    /// The status and one telemetry snapshot taken after it (so it reflects every command the
    /// status counted).
    pub fn snapshot(&mut self) -> Result<StatusView> {
        let status = self.call(|c| c.status())?;
        self.call(|c| c.stream_telemetry(20))?;
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut tm = None;
        while Instant::now() < deadline {
            match self.client.telemetry() {
                Ok(t) if t.commands >= status.counters.commands => {
                    tm = Some(t);
                    break;
                }
                Ok(_) | Err(Error::Line(LineError::Timeout)) => {}
                Err(e) => return Err(line_failure(&self.name, e)),
            }
        }
        self.call(|c| c.stream_telemetry(0))?;
        Ok(StatusView::new(&status, tm.as_ref(), &self.config))
    }
}

/// The rig's state as `status --json`, `set --json` and the monitor print it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StatusView {
    /// `"idle"`, `"running"`, `"stopping"`, `"faulted"`.
    pub mode: &'static str,
    /// The latched fault (`"estop"`, `"over_current"`, `"stall"`), or null.
    pub fault: Option<&'static str>,
    /// Why the drive last stopped, or null.
    pub last_stop: Option<&'static str>,
    pub estop: bool,
    /// R requested (the drive's target frequency as R for the configured pendulum and stroke).
    pub r_target: f64,
    /// The drive reference now and its target (rad/s).
    pub omega: f64,
    pub omega_target: f64,
    pub drive_angle_deg: f64,
    pub drive_angle_target_deg: f64,
    /// The estimator's slow angle φ (the settled equilibrium once settled), degrees.
    pub slow_angle_deg: Option<f64>,
    /// Slow-oscillation frequency ωp (rad/s), once measured.
    pub omega_p: Option<f64>,
    /// R in situ, once settled.
    pub r_estimate: Option<f64>,
    pub settled: bool,
    /// The model's φ0 and ωp for `r_target` and `drive_angle_target_deg` (while running).
    pub predicted: Option<Prediction>,
    /// Commands the rig has carried out since power-up.
    pub commands: u32,
    /// Where the rig's configuration came from.
    pub config: String,
    pub uptime_s: f64,
    /// Why the rig last reset (`"power_on"`, `"pin"`, `"watchdog"`, `"software"`, `"other"`),
    /// and the fault latched before that reset, or null.
    pub reset_cause: &'static str,
    pub fault_before_reset: Option<&'static str>,
    pub frames_ok: u32,
    pub frames_bad: u32,
    pub frames_dropped: u32,
    pub sensor_errors: u32,
    pub overruns: u32,
    /// The pre-run check of the last start: `"running"`, `"passed"`, `"failed"`, or null
    /// before any; with the reason it failed.
    pub check: Option<&'static str>,
    pub check_reason: Option<String>,
    /// In bring-up mode: its open-loop duty; else null.
    pub bring_up_duty: Option<f64>,
    /// The fast wobble's amplitude at the drive frequency (rad), from the telemetry.
    pub wobble_rad: Option<f64>,
    /// The rig's calibration (as `kapitza config get` prints it).
    pub calibration: crate::cmd::config::CalibrationFile,
}

impl StatusView {
    pub fn new(s: &Status, t: Option<&Telemetry>, cfg: &RigConfig) -> Self {
        let omega_target = from_q16(s.omega_target);
        let r_target = cfg.r_for_omega(omega_target);
        let theta_d_target = from_q16(s.theta_d_target_deg);
        let settled = t.is_some_and(|t| t.settled);
        let slow = t.map(|t| match (t.settled, t.equilibrium) {
            (true, Some(e)) => turns_deg(e),
            _ => turns_deg(t.phi),
        });
        let predicted = (s.mode == Mode::Running && r_target > 0.0)
            .then(|| predict(cfg, r_target, theta_d_target))
            .flatten();
        Self {
            mode: mode_name(&s.mode),
            fault: match s.mode {
                Mode::Faulted(f) => Some(fault_name(&f)),
                _ => None,
            },
            last_stop: s.last_stop.as_ref().map(stop_name),
            estop: s.estop,
            r_target,
            omega: from_q16(s.omega),
            omega_target,
            drive_angle_deg: from_q16(s.theta_d_deg),
            drive_angle_target_deg: theta_d_target,
            slow_angle_deg: slow,
            omega_p: t.and_then(|t| t.omega_p).map(from_q16),
            r_estimate: t.and_then(|t| t.r).map(|(r, _)| from_q16(r)),
            settled,
            predicted,
            commands: s.counters.commands,
            config: match s.config {
                ConfigOrigin::Stored => "stored".into(),
                ConfigOrigin::Received { saved: true } => "received, saved".into(),
                ConfigOrigin::Received { saved: false } => "received, not saved".into(),
                ConfigOrigin::Defaults(f) => format!("safe defaults ({f:?})"),
            },
            uptime_s: f64::from(s.uptime_ms) / 1000.0,
            reset_cause: reset_name(&s.reset.cause),
            fault_before_reset: s.reset.last_fault.as_ref().map(fault_name),
            frames_ok: s.counters.frames_ok,
            frames_bad: s.counters.frames_bad,
            frames_dropped: s.counters.frames_dropped,
            sensor_errors: s.counters.sensor_errors,
            overruns: s.counters.overruns,
            check: s.check.map(|c| match c {
                Check::Running => "running",
                Check::Passed => "passed",
                Check::Failed(_) => "failed",
            }),
            check_reason: match s.check {
                Some(Check::Failed(v)) => Some(v.to_string()),
                _ => None,
            },
            bring_up_duty: s.bring_up.map(|d| f64::from(d) / 32_768.0),
            wobble_rad: t.map(|t| from_q16(t.wobble)),
            calibration: (&cfg.calibration).into(),
        }
    }

    /// A few lines for a person.
    pub fn text(&self) -> String {
        let mut s = format!("mode        {}", self.mode);
        if let Some(f) = self.fault {
            s += &format!(" (fault: {f}; `kapitza clear` once its cause is gone)");
        } else if let Some(r) = self.last_stop {
            s += &format!(" (last stop: {r})");
        }
        s += &format!(
            "\ndrive       R = {:.3} (ω = {:.1} of {:.1} rad/s), θd = {:.1}° (target {:.1}°)",
            self.r_target,
            self.omega,
            self.omega_target,
            self.drive_angle_deg,
            self.drive_angle_target_deg
        );
        if let Some(phi) = self.slow_angle_deg {
            s += &format!(
                "\npendulum    φ = {phi:.2}°{}",
                if self.settled { ", settled" } else { "" }
            );
            if let Some(p) = self.predicted {
                s += &format!(" (model: {:.2}°)", p.phi0_deg);
            }
        }
        if let Some(w) = self.omega_p {
            s += &format!("\n            ωp = {w:.3} rad/s");
            if let Some(p) = self.predicted {
                s += &format!(" (model: {:.3})", p.omega_p);
            }
        }
        if let Some(r) = self.r_estimate {
            s += &format!(
                "\n            R in situ = {r:.3} (requested {:.3})",
                self.r_target
            );
        }
        match (self.check, &self.check_reason) {
            (Some("failed"), Some(why)) => {
                s += &format!("\ncheck       pre-run check failed: {why}")
            }
            (Some(c), _) => s += &format!("\ncheck       pre-run check {c}"),
            _ => {}
        }
        if let Some(d) = self.bring_up_duty {
            s += &format!("\nbring-up    open-loop duty {d:.3}");
        }
        if self.reset_cause != "power_on" {
            s += &format!(
                "\nreset       last reset: {}{}",
                self.reset_cause,
                self.fault_before_reset
                    .map(|f| format!(" after the fault {f}"))
                    .unwrap_or_default()
            );
        }
        s += &format!(
            "\nlink        {} frames ok, {} bad, {} dropped; e-stop {}; configuration {}",
            self.frames_ok,
            self.frames_bad,
            self.frames_dropped,
            if self.estop { "PRESSED" } else { "released" },
            self.config
        );
        s
    }
}
