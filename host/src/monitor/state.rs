//! Everything the dashboard shows, as a state machine: fed by the feed's [`Event`]s and by keys,
//! it keeps the latest snapshot, the slow angle's history and an event log, and turns keys into
//! [`Command`]s. No I/O here, so every transition is testable.

use kapitza_core::rig::closed_loop::ClosedLoopR;
use std::collections::VecDeque;

use serde::Serialize;

use kapitza_core::link::convert::from_q16;
use kapitza_core::link::message::{Fault, Mode, StopReason};
use kapitza_core::link::{Status, Telemetry};
use kapitza_core::rig::config::RigConfig;

use super::feed::{Command, Event};
use crate::rig::live::Live;
use crate::rig::names::{fault_name, fault_reason, mode_name};
use crate::rig::predicted::predict;

/// Seconds of slow angle the chart keeps.
pub const HISTORY_S: f64 = 60.0;
/// Event-log lines kept.
pub const LOG_LINES: usize = 200;

/// A key, as the monitor understands it (the terminal's own key type stays in the run loop).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    Char(char),
    Esc,
    CtrlC,
}

/// The link as last heard.
#[derive(Debug, Clone, PartialEq)]
pub enum Link {
    /// No answer to the version check yet.
    Waiting,
    Up {
        protocol: u8,
        firmware: [u16; 3],
    },
    Lost(String),
}

/// One point of the chart: rig seconds, the slow angle and the prediction (degrees, in the
/// chart's window [`chart_deg`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    pub t_s: f64,
    pub phi_deg: f64,
    pub predicted_deg: Option<f64>,
}

/// The numbers of one telemetry frame with the latest status and the model's prediction. The
/// field names are the contract shared with `kapitza status --json` and the `--plain` records.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Readings {
    /// Rig seconds since the monitor's first frame.
    pub t_s: f64,
    /// `idle`, `running`, `stopping` or `faulted`.
    pub mode: &'static str,
    /// The fault that stopped (or is stopping) the drive: `e_stop`, `over_current`, `stall`.
    pub fault: Option<&'static str>,
    /// R of the drive reference now, and the R requested: (ω / ωc)².
    pub r: Option<f64>,
    pub r_target: Option<f64>,
    /// Drive reference ω now, its target, and the crank's measured speed (rad/s).
    pub omega: f64,
    pub omega_target: Option<f64>,
    pub crank_speed: f64,
    /// θd now and its target (degrees along the mount's travel).
    pub drive_angle_deg: f64,
    pub drive_angle_target_deg: Option<f64>,
    /// The latest pendulum sample θ and the slow angle φ, degrees in (−180, 180]; φ only while
    /// the drive runs (`rig::live`).
    pub theta_deg: f64,
    pub slow_angle_deg: Option<f64>,
    /// φ0 once settled, and the averaged theory's stable φ0 at the present R and θd nearest the
    /// measured slow angle (before one is measured, the one within reach).
    pub equilibrium_deg: Option<f64>,
    pub predicted_phi0_deg: Option<f64>,
    /// The measured slow angle lies more than 90° from the blade (no body, a sensor zero off).
    pub outside_reach: bool,
    /// The other stable equilibria at the present R and θd (degrees).
    #[serde(skip)]
    pub other_stable_deg: Vec<f64>,
    /// ωp measured and predicted (rad/s).
    pub omega_p: Option<f64>,
    pub predicted_omega_p: Option<f64>,
    /// R in situ from the settled angle (or from ωp where that is singular).
    pub r_estimate: Option<f64>,
    pub settled: bool,
    /// The drive is at its set point: the estimator is measuring.
    pub steady: bool,
    /// Commands the rig has carried out.
    pub commands: u32,
    /// Closed-loop R's settings (the configuration's), once the configuration is known; the
    /// dashboard shows them, the JSON keys stay as they were.
    #[serde(skip)]
    pub closed_loop: Option<ClosedLoopR>,
}

/// An angle as the chart shows it, in [−90°, 270°): every equilibrium reachable within the
/// mount's travel (θd in [−10°, 190°], φ0 within 90° of it) stays clear of the chart's edges, so
/// a rod carried over the top draws as one curve instead of jumping between ±180°.
pub fn chart_deg(deg: f64) -> f64 {
    (deg + 90.0).rem_euclid(360.0) - 90.0
}

fn mode_fault(m: Mode) -> Option<Fault> {
    match m {
        Mode::Faulted(f) | Mode::Stopping(StopReason::Fault(f)) => Some(f),
        _ => None,
    }
}

/// The monitor's state: see the [module doc](self).
#[derive(Debug, Clone)]
pub struct State {
    pub link: Link,
    pub config: Option<RigConfig>,
    pub telemetry: Option<Telemetry>,
    pub status: Option<Status>,
    /// The latest mode, from whichever of telemetry and status came last.
    pub mode: Option<Mode>,
    pub history: VecDeque<Point>,
    /// (rig seconds, text), oldest first.
    pub log: VecDeque<(f64, String)>,
    /// Lines ever logged (the log drops old ones; writers of new lines count on this).
    pub logged: u64,
    pub quit: bool,
    /// A result table a driver leaves on the dashboard in place of the chart (the demo's, at
    /// its end); empty: the chart.
    pub summary: Vec<String>,
    /// Rig µs since the first frame (summed exactly), and the rig's µs clock at the last frame
    /// (`None`: take the next frame as the base, as after a reconnect to a rig whose clock
    /// restarted).
    elapsed_us: u64,
    last_us: Option<u32>,
    commands_seen: u32,
}

impl Default for State {
    fn default() -> Self {
        Self::new()
    }
}

impl State {
    pub fn new() -> Self {
        Self {
            link: Link::Waiting,
            config: None,
            telemetry: None,
            status: None,
            mode: None,
            history: VecDeque::new(),
            log: VecDeque::new(),
            logged: 0,
            quit: false,
            summary: Vec::new(),
            elapsed_us: 0,
            last_us: None,
            commands_seen: 0,
        }
    }

    /// Rig seconds since the first frame (carried across reconnects).
    pub fn t_s(&self) -> f64 {
        self.elapsed_us as f64 * 1e-6
    }

    /// The largest command count the rig has reported: a frame with a larger one was taken
    /// after a command sent now.
    pub fn commands_seen(&self) -> u32 {
        self.commands_seen
    }

    pub fn faulted(&self) -> bool {
        matches!(self.mode, Some(Mode::Faulted(_)))
    }

    /// Adds a line to the event log.
    pub fn note(&mut self, text: impl Into<String>) {
        if self.log.len() == LOG_LINES {
            self.log.pop_front();
        }
        self.log.push_back((self.t_s(), text.into()));
        self.logged += 1;
    }

    pub fn on_event(&mut self, e: Event) {
        match e {
            Event::Linked {
                protocol,
                firmware,
                config,
            } => {
                let [a, b, c] = firmware;
                self.note(format!(
                    "link up: protocol {protocol}, firmware {a}.{b}.{c}"
                ));
                self.link = Link::Up { protocol, firmware };
                self.config = Some(*config);
                self.last_us = None;
            }
            Event::Telemetry(t) => self.on_telemetry(t),
            Event::Status(s) => {
                self.commands_seen = self.commands_seen.max(s.counters.commands);
                self.set_mode(s.mode);
                self.status = Some(s);
            }
            Event::LinkLost(why) => {
                self.note(format!("link lost: {why}"));
                self.link = Link::Lost(why);
            }
            Event::Note(text) => self.note(text),
        }
    }

    fn on_telemetry(&mut self, t: Telemetry) {
        if let Some(last) = self.last_us {
            self.elapsed_us += u64::from(t.t_us.wrapping_sub(last));
        }
        self.last_us = Some(t.t_us);
        self.commands_seen = self.commands_seen.max(t.commands);
        let was_settled = self.telemetry.is_some_and(|p| p.settled);
        self.set_mode(t.mode);
        self.telemetry = Some(t);
        let Some(r) = self.readings() else { return };
        if r.settled && !was_settled && r.slow_angle_deg.is_some() {
            let at = r
                .equilibrium_deg
                .map_or("—".into(), crate::outcome::show_deg);
            self.note(format!("settled at φ0 = {at}"));
        }
        self.history.push_back(Point {
            t_s: r.t_s,
            phi_deg: chart_deg(r.slow_angle_deg.unwrap_or(r.theta_deg)),
            predicted_deg: r.predicted_phi0_deg.map(chart_deg),
        });
        while self
            .history
            .front()
            .is_some_and(|p| p.t_s < r.t_s - HISTORY_S)
        {
            self.history.pop_front();
        }
    }

    fn set_mode(&mut self, m: Mode) {
        if self.mode != Some(m) {
            let fault = mode_fault(m).map_or(String::new(), |f| {
                let line = fault_reason(&f).map_or(String::new(), |r| format!(", {r}"));
                format!(" ({}{line})", fault_name(&f))
            });
            self.note(format!("mode: {}{fault}", mode_name(&m)));
            self.mode = Some(m);
        }
    }

    /// A key press: what to send, if anything. `s` (and space) stop the drive in every mode;
    /// `c` clears a fault, and only while faulted; `q`, Esc and Ctrl-C quit the monitor (a
    /// running rig left without its keep-alive soft-stops by itself).
    pub fn on_key(&mut self, k: Key) -> Option<Command> {
        match k {
            Key::Char('q') | Key::Esc | Key::CtrlC => {
                self.quit = true;
                None
            }
            Key::Char('s' | ' ') => Some(Command::Stop),
            Key::Char('c') if self.faulted() => Some(Command::ClearFault),
            Key::Char('c') => {
                self.note("no fault to clear");
                None
            }
            _ => None,
        }
    }

    /// The outcome of a command sent.
    pub fn on_command(&mut self, c: Command, result: &Result<(), String>) {
        match result {
            Ok(()) => self.note(format!("{}: done", c.label())),
            Err(why) => self.note(format!("{}: {why}", c.label())),
        }
    }

    /// The latest frame's numbers, once a frame has arrived.
    pub fn readings(&self) -> Option<Readings> {
        let t = self.telemetry?;
        let cfg = self.config;
        let omega = from_q16(t.omega);
        let omega_target = self.status.map(|s| from_q16(s.omega_target));
        let drive_angle_deg = from_q16(t.theta_d_deg);
        let r = cfg.map(|c| c.r_for_omega(omega));
        let mode = self.mode.unwrap_or(t.mode);
        let live = Live::of(mode, &t);
        let prediction = cfg
            .zip(r)
            .and_then(|(c, r)| predict(&c, r, drive_angle_deg, live.measured_deg));
        Some(Readings {
            t_s: self.t_s(),
            mode: mode_name(&mode),
            fault: mode_fault(mode).map(|f| fault_name(&f)),
            r,
            r_target: cfg.zip(omega_target).map(|(c, w)| c.r_for_omega(w)),
            omega,
            omega_target,
            crank_speed: from_q16(t.crank_speed),
            drive_angle_deg,
            drive_angle_target_deg: self.status.map(|s| from_q16(s.theta_d_target_deg)),
            theta_deg: live.theta_deg,
            slow_angle_deg: live.slow_angle_deg,
            equilibrium_deg: live
                .slow_angle_deg
                .and(t.equilibrium)
                .map(crate::rig::names::turns_deg),
            predicted_phi0_deg: prediction.as_ref().map(|p| p.phi0_deg),
            outside_reach: prediction.as_ref().is_some_and(|p| p.outside_reach),
            other_stable_deg: prediction.as_ref().map_or(Vec::new(), |p| {
                p.other_stable.iter().map(|o| o.phi0_deg).collect()
            }),
            omega_p: live.omega_p,
            predicted_omega_p: prediction.as_ref().map(|p| p.omega_p),
            r_estimate: live.r_estimate,
            settled: t.settled && live.slow_angle_deg.is_some(),
            steady: t.steady,
            commands: t.commands,
            closed_loop: cfg.map(|c| c.closed_loop),
        })
    }
}
