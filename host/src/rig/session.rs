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

use super::live::Live;
use super::names::{fault_hint, fault_name, fault_reason, mode_name, reset_name, stop_name};
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
        Error::Refused(r) => {
            let range = match r {
                kapitza_core::link::Reason::ConfigInvalid { field } => {
                    super::fields::allowed(field)
                        .map(|a| format!(" ({}: allowed {a})", super::fields::key(field)))
                        .unwrap_or_default()
                }
                _ => String::new(),
            };
            Failure::new(Exit::Refused, format!("the rig refused: {r}{range}")).into()
        }
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
    /// The latched fault (`"estop"`, `"over_current"`, `"stall"`, `"bridge"`, …), or null.
    pub fault: Option<&'static str>,
    /// The line a bridge fault was seen on (`"nfault"`, `"break"`), or null.
    pub fault_reason: Option<&'static str>,
    /// What to do about the latched fault, or null.
    pub fault_hint: Option<&'static str>,
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
    /// The latest pendulum sample θ, degrees: what stands in for the slow angle while there is
    /// none.
    pub theta_deg: Option<f64>,
    /// The estimator's slow angle φ (the settled equilibrium once settled), degrees; only
    /// while the drive runs ([`Live`]).
    pub slow_angle_deg: Option<f64>,
    /// Slow-oscillation frequency ωp (rad/s), once measured, while the drive runs.
    pub omega_p: Option<f64>,
    /// R in situ, once settled, while the drive runs.
    pub r_estimate: Option<f64>,
    pub settled: bool,
    /// While running: the model's stable φ0 nearest the measured slow angle (before one is
    /// measured, the one within reach) for `r_target` and `drive_angle_target_deg`, with the
    /// other stable ones and whether the measurement is outside reach.
    pub predicted: Option<Prediction>,
    /// Commands the rig has carried out since power-up.
    pub commands: u32,
    /// Where the rig's configuration came from.
    pub config: String,
    /// The stored configuration's fields that were out of range and run at their defaults
    /// (their `config get` keys); empty when none did.
    pub config_fallbacks: Vec<&'static str>,
    pub uptime_s: f64,
    /// Why the rig last reset (`"power_on"`, `"pin"`, `"watchdog"`, `"software"`, `"other"`,
    /// `"panic"`, `"hard_fault"`, `"stack_overflow"`), and the fault latched before that
    /// reset, or null.
    pub reset_cause: &'static str,
    pub fault_before_reset: Option<&'static str>,
    /// After a hard fault or stack overflow, the program counter it was taken at
    /// (`"0x08001234"`), when known; else null.
    pub fault_pc: Option<String>,
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
        let live = t.map(|t| Live::of(s.mode, t));
        let settled =
            t.is_some_and(|t| t.settled) && live.is_some_and(|l| l.slow_angle_deg.is_some());
        let measured = live.and_then(|l| l.measured_deg);
        let predicted = (s.mode == Mode::Running && r_target > 0.0)
            .then(|| predict(cfg, r_target, theta_d_target, measured))
            .flatten();
        Self {
            mode: mode_name(&s.mode),
            fault: match s.mode {
                Mode::Faulted(f) => Some(fault_name(&f)),
                _ => None,
            },
            fault_reason: match s.mode {
                Mode::Faulted(f) => fault_reason(&f),
                _ => None,
            },
            fault_hint: match s.mode {
                Mode::Faulted(f) => Some(fault_hint(&f)),
                _ => None,
            },
            last_stop: s.last_stop.as_ref().map(stop_name),
            estop: s.estop,
            r_target,
            omega: from_q16(s.omega),
            omega_target,
            drive_angle_deg: from_q16(s.theta_d_deg),
            drive_angle_target_deg: theta_d_target,
            theta_deg: live.map(|l| l.theta_deg),
            slow_angle_deg: live.and_then(|l| l.slow_angle_deg),
            omega_p: live.and_then(|l| l.omega_p),
            r_estimate: live.and_then(|l| l.r_estimate),
            settled,
            predicted,
            commands: s.counters.commands,
            config: match s.config {
                ConfigOrigin::Stored => "stored".into(),
                ConfigOrigin::Repaired { .. } => "stored, with fields at their defaults".into(),
                ConfigOrigin::Received { saved: true } => "received, saved".into(),
                ConfigOrigin::Received { saved: false } => "received, not saved".into(),
                ConfigOrigin::Defaults(f) => format!("safe defaults ({f:?})"),
                ConfigOrigin::DefaultsByEstop => "defaults_by_estop".into(),
            },
            config_fallbacks: match s.config {
                ConfigOrigin::Repaired { defaulted } => {
                    defaulted.iter().map(super::fields::key).collect()
                }
                _ => Vec::new(),
            },
            uptime_s: f64::from(s.uptime_ms) / 1000.0,
            reset_cause: reset_name(&s.reset.cause),
            fault_before_reset: s.reset.last_fault.as_ref().map(fault_name),
            fault_pc: s.reset.fault_pc.map(|pc| format!("{pc:#010x}")),
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
            let line = self
                .fault_reason
                .map_or(String::new(), |r| format!(", {r}"));
            let hint = self
                .fault_hint
                .unwrap_or("`kapitza clear` once its cause is gone");
            s += &format!(" (fault: {f}{line}; {hint})");
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
        match (self.slow_angle_deg, self.theta_deg) {
            (Some(phi), _) => {
                s += &format!(
                    "\npendulum    φ = {phi:.2}°{}",
                    if self.settled { ", settled" } else { "" }
                );
                if let Some(p) = &self.predicted {
                    s += &format!(" (model: {:.2}°)", p.phi0_deg);
                    if p.outside_reach {
                        s += ", outside reach: more than 90° from the blade (no body, or the \
                               sensor's zero off?)";
                    }
                }
            }
            (None, Some(theta)) => {
                s += &format!("\npendulum    θ = {theta:.2}° (slow angle, ωp, R in situ: —, the drive is not running)")
            }
            (None, None) => {}
        }
        if let Some(w) = self.omega_p {
            s += &format!("\n            ωp = {w:.3} rad/s");
            if let Some(p) = &self.predicted {
                s += &format!(" (model: {:.3})", p.omega_p);
            }
        }
        if let Some(p) = self
            .predicted
            .as_ref()
            .filter(|p| !p.other_stable.is_empty())
        {
            let others: Vec<String> = p
                .other_stable
                .iter()
                .map(|o| format!("{:.2}° (ωp {:.3})", o.phi0_deg, o.omega_p))
                .collect();
            s += &format!("\n            also stable: {}", others.join(", "));
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
                "\nreset       last reset: {}{}{}",
                self.reset_cause,
                self.fault_pc
                    .as_ref()
                    .map(|pc| format!(" at pc {pc}"))
                    .unwrap_or_default(),
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
        if !self.config_fallbacks.is_empty() {
            s += &format!(
                "\nconfig      stored out of range, running at their defaults: {} \
                 (`kapitza config set` to store new values)",
                self.config_fallbacks.join(", ")
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kapitza_core::persist;
    use kapitza_core::rig::fixed::Angle;
    use kapitza_core::station::serve::{Clock, RigServer};

    /// A record stored with `link_timeout_ms = 0` boots with that field at its default and
    /// the calibration kept; the status names it in `config_fallbacks` and in its text.
    #[test]
    fn a_repaired_record_lists_its_fallbacks() {
        let mut stored = RigConfig::REFERENCE;
        stored.calibration.pendulum_zero = 999;
        stored.limits.link_timeout_ms = 0;
        let mut buf = [0u8; persist::RECORD_MAX];
        persist::encode(&stored, 1, &mut buf);
        let (cfg, origin) = persist::load(&buf);
        assert_eq!(cfg.calibration.pendulum_zero, 999);
        assert_eq!(cfg.limits.link_timeout_ms, 1000);
        let rig = RigServer::new(cfg, origin, Angle::ZERO, Clock::single(0, 0), [0, 1, 0]);
        let view = StatusView::new(&rig.status(false, 0), None, &cfg);
        let json = serde_json::to_value(&view).unwrap();
        assert_eq!(
            json["config_fallbacks"],
            serde_json::json!(["limits.link_timeout_ms"])
        );
        assert_eq!(json["config"], "stored, with fields at their defaults");
        assert!(
            view.text()
                .contains("at their defaults: limits.link_timeout_ms"),
            "{}",
            view.text()
        );
    }

    /// The reset's cause and PC as the status JSON spells them: `reset_cause` by name,
    /// `fault_pc` as eight hex digits, null when the PC is not known or there was no crash.
    #[test]
    fn a_crash_is_named_with_its_pc() {
        use kapitza_core::link::message::ResetInfo;
        use kapitza_core::rig::retained::{Cause, Crash, CrashKind};
        let cfg = RigConfig::REFERENCE;
        let crash = |kind, pc| Cause::Crash(Crash { kind, pc });
        let cases = [
            (
                crash(CrashKind::HardFault, Some(0x0800_1234)),
                "hard_fault",
                Some("0x08001234"),
            ),
            (crash(CrashKind::Panic, None), "panic", None),
            (
                crash(CrashKind::StackOverflow, None),
                "stack_overflow",
                None,
            ),
            (Cause::Watchdog, "watchdog", None),
        ];
        for (cause, name, pc) in cases {
            let mut rig = RigServer::new(
                cfg,
                ConfigOrigin::Stored,
                Angle::ZERO,
                Clock::single(0, 0),
                [0, 1, 0],
            );
            rig.reset = ResetInfo::new(cause, None);
            let view = StatusView::new(&rig.status(false, 0), None, &cfg);
            let json = serde_json::to_value(&view).unwrap();
            assert_eq!(json["reset_cause"], name);
            assert_eq!(json["fault_pc"], serde_json::json!(pc));
            assert!(view.text().contains(&format!("last reset: {name}")));
        }
        let view = StatusView::new(
            &RigServer::new(
                cfg,
                ConfigOrigin::Stored,
                Angle::ZERO,
                Clock::single(0, 0),
                [0, 1, 0],
            )
            .status(false, 0),
            None,
            &cfg,
        );
        let json = serde_json::to_value(&view).unwrap();
        assert_eq!(json["reset_cause"], "power_on");
        assert_eq!(json["fault_pc"], serde_json::Value::Null);
    }
}
