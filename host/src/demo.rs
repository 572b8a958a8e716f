//! The lecture demo as a script over the monitor's [`Feed`]: the commands a lecturer would
//! type, each step waiting until the rod has settled, its measurement set against the averaged
//! theory's prediction (physics §3).
//!
//! ```text
//! 0  drive off                 hanging at rest for REST_S
//! 1  R = 1.75,  θd =  90°      settles near arccos(1/R) = 55°
//! 2  R = 2.2,   θd = 180°      above R = 2 a tilted equilibrium within 90° of the drive exists
//!                              at every θd, so the slewing drive carries the rod over the top
//!                              (at R = 1.75 that branch dies near θd = 110° and it falls back)
//! 3  R = 1.75,  θd = 180°      stays upside down (inverted stable for R > 1)
//! then stop, and wait for the drive to run down
//! ```
//! A step is measured at the first frame taken after its command (the telemetry's command
//! counter above the count before it: a snapshot from before the command never counts) that is
//! steady, settled and carries φ0. R in situ comes with it where the rig can tell: at θd = 180°
//! the equilibrium formula is singular and R comes from ωp alone (physics §7), so a rod that
//! reaches the top without a slow swing to time (lowered gently from R = 2.2 to 1.75, say)
//! reports no ωp and no R.

use kapitza_core::link::message::Mode;
use serde::Serialize;

use crate::monitor::{Command, Driver, State};
use crate::outcome::show_deg;
use crate::rig::predicted::{predict, Stable};

/// Seconds of the rig's clock the rod hangs at rest before the first command.
pub const REST_S: f64 = 3.0;
/// Rig seconds a step may take to settle before the script gives up on it.
pub const SETTLE_TIMEOUT_S: f64 = 240.0;
/// Rig seconds the drive may take to run down after the stop.
const STOP_TIMEOUT_S: f64 = 60.0;

/// One driven step: R and θd as a lecturer would type them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    pub r: f64,
    pub theta_d_deg: f64,
}

/// The driven steps, after the rest.
pub const STEPS: [Step; 3] = [
    Step {
        r: 1.75,
        theta_d_deg: 90.0,
    },
    Step {
        r: 2.2,
        theta_d_deg: 180.0,
    },
    Step {
        r: 1.75,
        theta_d_deg: 180.0,
    },
];

/// One step's measurement against the prediction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Outcome {
    /// R requested (0: the drive off) and the drive angle (degrees).
    pub r: f64,
    pub drive_angle_deg: f64,
    pub settled: bool,
    /// Rig seconds from the first frame after the command to the settled frame (the rest
    /// step: its length).
    pub settle_s: Option<f64>,
    /// Measured: φ0 (at rest: the angle sample), ωp, R in situ.
    pub measured: Measured,
    pub predicted: Predicted,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measured {
    pub phi0_deg: Option<f64>,
    pub omega_p: Option<f64>,
    pub r: Option<f64>,
}

/// The stable equilibrium nearest the measured φ0 (`rig::predicted`), the others, and whether
/// the measurement is outside reach.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Predicted {
    pub phi0_deg: Option<f64>,
    pub omega_p: Option<f64>,
    pub r: f64,
    pub other_stable: Vec<Stable>,
    pub outside_reach: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Waiting for the first frame and the configuration.
    Start,
    Rest {
        until_s: f64,
    },
    /// Step `i` commanded; frames with `commands >= need` count, the first of them (taken
    /// within a telemetry period of the rig carrying the command out) at `since_s`.
    Settling {
        i: usize,
        need: u32,
        since_s: Option<f64>,
    },
    Stopping {
        need: u32,
        since_s: f64,
    },
    Done,
}

/// The table of measured against predicted, one line per step under a header: 71 columns, so
/// it fits the dashboard on an 80-column terminal as well as the terminal after it.
pub fn table(rows: &[Outcome]) -> Vec<String> {
    let show = |x: Option<f64>, prec: usize| x.map_or("—".into(), |v| format!("{v:.prec$}"));
    let angle = |x: Option<f64>| x.map_or("—".into(), show_deg);
    let mut lines = vec![format!(
        "{:>5} {:>6} {:>8} {:>9} {:>9} {:>7} {:>7} {:>6} {:>6}",
        "R", "θd (°)", "settle s", "φ0 meas", "φ0 pred", "ωp meas", "ωp pred", "R meas", "R req"
    )];
    for o in rows {
        lines.push(format!(
            "{:>5.2} {:>6.1} {:>8} {:>9} {:>9} {:>7} {:>7} {:>6} {:>6.3}{}",
            o.r,
            o.drive_angle_deg,
            show(o.settle_s, 1),
            angle(o.measured.phi0_deg),
            angle(o.predicted.phi0_deg),
            show(o.measured.omega_p, 3),
            show(o.predicted.omega_p, 3),
            show(o.measured.r, 3),
            o.predicted.r,
            if o.predicted.outside_reach {
                "  outside reach"
            } else {
                ""
            },
        ));
    }
    lines
}

/// The demo's script: see the [module doc](self).
#[derive(Debug, Clone)]
pub struct Script {
    phase: Phase,
    /// The command it asked for and the phase that follows once it is carried out.
    pending: Option<Phase>,
    pub outcomes: Vec<Outcome>,
    /// Why the script ended early, if it did.
    pub aborted: Option<String>,
}

impl Default for Script {
    fn default() -> Self {
        Self::new()
    }
}

impl Script {
    pub fn new() -> Self {
        Self {
            phase: Phase::Start,
            pending: None,
            outcomes: Vec::new(),
            aborted: None,
        }
    }

    fn abort(&mut self, state: &mut State, why: String) {
        state.note(format!("demo stopped: {why}"));
        self.aborted = Some(why);
        self.done(state);
    }

    /// The end: the table stays on the dashboard.
    fn done(&mut self, state: &mut State) {
        state.summary = table(&self.outcomes);
        self.phase = Phase::Done;
    }

    /// Records step `i` (or the rest, `None`) from the state's latest frame.
    fn record(&mut self, state: &mut State, step: Option<Step>, since_s: f64, settled: bool) {
        let (Some(r), Some(cfg)) = (state.readings(), state.config) else {
            return;
        };
        let (r_req, theta_d) = step.map_or((0.0, r.drive_angle_deg), |s| (s.r, s.theta_d_deg));
        let measured = if step.is_some() {
            Measured {
                phi0_deg: r.equilibrium_deg,
                omega_p: r.omega_p,
                r: r.r_estimate,
            }
        } else {
            Measured {
                phi0_deg: Some(r.theta_deg),
                omega_p: None,
                r: None,
            }
        };
        let p = predict(&cfg, r_req, theta_d, measured.phi0_deg);
        let o = Outcome {
            r: r_req,
            drive_angle_deg: theta_d,
            settled,
            settle_s: settled.then_some(state.t_s() - since_s),
            measured,
            predicted: Predicted {
                phi0_deg: p.as_ref().map(|p| p.phi0_deg),
                omega_p: p.as_ref().map(|p| p.omega_p),
                r: r_req,
                other_stable: p.as_ref().map_or(Vec::new(), |p| p.other_stable.clone()),
                outside_reach: p.is_some_and(|p| p.outside_reach),
            },
        };
        let show = |x: Option<f64>, prec: usize| x.map_or("—".into(), |v| format!("{v:.prec$}"));
        let angle = |x: Option<f64>| x.map_or("—".into(), show_deg);
        state.note(format!(
            "R = {} at θd = {}°: {}",
            o.r,
            o.drive_angle_deg,
            match o.settle_s {
                Some(s) if step.is_some() => format!("settled after {s:.1} s"),
                Some(_) => "at rest".into(),
                None => "did not settle".into(),
            },
        ));
        state.note(format!(
            "  φ0 {} (model {}{}), ωp {} ({}), R {}",
            angle(o.measured.phi0_deg),
            angle(o.predicted.phi0_deg),
            if o.predicted.outside_reach {
                "; OUTSIDE REACH"
            } else {
                ""
            },
            show(o.measured.omega_p, 3),
            show(o.predicted.omega_p, 3),
            show(o.measured.r, 3),
        ));
        self.outcomes.push(o);
    }

    /// Sends step `i`, or the stop after the last.
    fn command_after(&mut self, state: &State, i: usize) -> Command {
        let need = state.commands_seen() + 1;
        let since_s = state.t_s();
        match STEPS.get(i) {
            Some(s) => {
                self.pending = Some(Phase::Settling {
                    i,
                    need,
                    since_s: None,
                });
                Command::SetDrive {
                    r: s.r,
                    theta_d_deg: s.theta_d_deg,
                }
            }
            None => {
                self.pending = Some(Phase::Stopping { need, since_s });
                Command::Stop
            }
        }
    }
}

impl Driver for Script {
    fn next(&mut self, state: &mut State) -> Option<Command> {
        let t = state.t_s();
        match self.phase {
            Phase::Start => {
                if state.readings().is_some() && state.config.is_some() {
                    state.note(format!("demo: hanging at rest for {REST_S} s"));
                    self.phase = Phase::Rest {
                        until_s: t + REST_S,
                    };
                }
                None
            }
            Phase::Rest { until_s } if t >= until_s => {
                self.record(state, None, until_s - REST_S, true);
                Some(self.command_after(state, 0))
            }
            Phase::Settling { i, need, since_s } => {
                let tm = state.telemetry?;
                // A start waits for the rig's pre-run check.
                if tm.commands < need || tm.mode == Mode::Checking {
                    return None;
                }
                if tm.mode != Mode::Running {
                    let why = format!("the drive is no longer running (mode {:?})", tm.mode);
                    self.record(state, Some(STEPS[i]), since_s.unwrap_or(t), false);
                    self.abort(state, why);
                    return None;
                }
                let Some(since_s) = since_s else {
                    self.phase = Phase::Settling {
                        i,
                        need,
                        since_s: Some(t),
                    };
                    return None;
                };
                let done = tm.steady && tm.settled && tm.equilibrium.is_some();
                let late = t - since_s > SETTLE_TIMEOUT_S;
                if !(done || late) {
                    return None;
                }
                self.record(state, Some(STEPS[i]), since_s, done);
                Some(self.command_after(state, i + 1))
            }
            Phase::Stopping { need, since_s } => {
                let idle = state
                    .telemetry
                    .is_some_and(|tm| tm.commands >= need && tm.mode == Mode::Idle);
                if idle || t - since_s > STOP_TIMEOUT_S {
                    state.note(if idle {
                        "demo: done, the drive is off"
                    } else {
                        "demo: done, but the drive has not run down"
                    });
                    self.done(state);
                }
                None
            }
            Phase::Rest { .. } | Phase::Done => None,
        }
    }

    fn sent(&mut self, state: &mut State, c: Command, result: &Result<(), String>) {
        match (result, self.pending.take()) {
            (Ok(()), Some(next)) => self.phase = next,
            (Err(why), _) => self.abort(state, format!("{}: {why}", c.label())),
            (Ok(()), None) => {}
        }
    }

    fn finished(&self) -> bool {
        self.phase == Phase::Done
    }
}
