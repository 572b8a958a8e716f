//! The rig's side of the link, free of hardware: applying a command to a [`Rig`] all or nothing,
//! building the status and telemetry messages from it, and [`RigServer`], which answers every
//! request. [`crate::station::RigLoop`] owns one and frames its answers.

use super::precheck::PreCheck;
use super::repeat::{FrameId, LastAnswer};
use crate::link::convert::{deg_along_travel, from_q16, to_q16};
use crate::link::message::Verdict;
use crate::link::message::{
    Check, Counters, Mode, Request, ResetInfo, Response, Status, Telemetry, VersionInfo, WireConfig,
};
use crate::link::reason::Reason;
use crate::persist::ConfigOrigin;
use crate::rig::config::RigConfig;
use crate::rig::controller::{ControlReport, Rig};
use crate::rig::dds::omega_of_word;
use crate::rig::fixed::{Amps, Angle, Duty};
use crate::rig::safety::{self, Request as Sr};

/// A request that changes the drive. Everything else ([`Request::GetVersion`],
/// [`Request::GetStatus`], …) is answered without touching the rig.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    SetDrive { r: i32, theta_d_deg: i32 },
    Stop,
    ClearFault,
}

impl Command {
    /// The command a request carries, if it is one.
    pub fn of(req: &Request) -> Option<Self> {
        match *req {
            Request::SetDrive { r, theta_d_deg } => Some(Self::SetDrive { r, theta_d_deg }),
            Request::Stop => Some(Self::Stop),
            Request::ClearFault => Some(Self::ClearFault),
            _ => None,
        }
    }
}

/// Applies `cmd` to `rig` (configured with `cfg`) or refuses it with the reason; a refused
/// command leaves `rig` exactly as it was (the requests are tried on a copy and the copy kept
/// only if all of them pass).
///
/// ```text
/// SetDrive{R, θd}:  θd → SetDriveAngle (slewed);  R > 0: ω = ωc √R → Start (idle) or SetOmega;
///                   R = 0 → Stop;  R < 0 or not representable → RInvalid
/// Stop:             soft stop; accepted while faulted too (the drive is already halted)
/// ClearFault:       leaves Faulted once the e-stop is released and nFAULT reads high
/// ```
pub fn apply(rig: &mut Rig, cfg: &RigConfig, cmd: Command) -> Result<(), Reason> {
    let mut trial = *rig;
    match cmd {
        Command::SetDrive { r, theta_d_deg } => {
            if r < 0 {
                return Err(Reason::RInvalid { requested: r });
            }
            trial.request(Sr::SetDriveAngle {
                deg: from_q16(theta_d_deg),
            })?;
            trial.r_asked(from_q16(r));
            if r == 0 {
                trial.request(Sr::Stop)?;
            } else {
                let omega = cfg
                    .omega_for_r(from_q16(r))
                    .map_err(|_| Reason::RInvalid { requested: r })?;
                let req = match trial.supervisor().mode() {
                    safety::Mode::Idle => Sr::Start { omega },
                    _ => Sr::SetOmega { omega },
                };
                trial.request(req)?;
            }
        }
        Command::Stop => {
            if !matches!(trial.supervisor().mode(), safety::Mode::Faulted(_)) {
                trial.request(Sr::Stop)?;
            }
        }
        Command::ClearFault => trial.request(Sr::ClearFault)?,
    }
    *rig = trial;
    Ok(())
}

/// A new configuration may replace the running one only while the rig is idle.
pub fn config_change_allowed(rig: &Rig) -> Result<(), Reason> {
    match rig.supervisor().mode() {
        safety::Mode::Idle => Ok(()),
        m => Err(Reason::WrongMode(m.into())),
    }
}

/// The status message.
pub fn status(
    rig: &Rig,
    cfg: &RigConfig,
    estop: bool,
    config: ConfigOrigin,
    uptime_ms: u32,
    counters: Counters,
    reset: ResetInfo,
) -> Status {
    let sup = rig.supervisor();
    let min = cfg.limits.drive_angle_min_deg;
    Status {
        mode: sup.mode().into(),
        last_stop: sup.last_stop().map(Into::into),
        estop,
        omega: rig.dds().omega().to_bits(),
        omega_target: to_q16(omega_of_word(sup.target_word())),
        theta_d_deg: to_q16(deg_along_travel(sup.theta_d(), min)),
        theta_d_target_deg: to_q16(deg_along_travel(sup.theta_d_target(), min)),
        config,
        uptime_ms,
        counters,
        reset,
        check: None,
        bring_up: None,
    }
}

/// What the rig does besides what its supervisor says: a start waiting for its pre-run check,
/// or bring-up mode. The supervisor is idle in both.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Activity {
    None,
    /// The pre-run check runs; `start` is carried out when it passes.
    Checking {
        check: PreCheck,
        start: Command,
    },
    /// Bring-up mode at this open-loop duty.
    BringUp {
        duty: Duty,
    },
}

/// The largest |duty| bring-up mode accepts (also capped at `duty_max`): a quarter of full
/// speed turns a crank visibly and slowly enough to stop by hand.
pub const BRING_UP_DUTY_MAX: f64 = 0.25;

/// What the caller must do besides sending the response.
// No heap on the rig: the configuration travels inline, once per request.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Effect {
    None,
    /// A new configuration is in use: store it (then report with [`RigServer::config_saved`]).
    StoreConfig(RigConfig),
    /// Stream telemetry every `period_ms` (0: stop), as [`Request::Telemetry`] asked.
    Telemetry {
        period_ms: u16,
    },
    /// `ClearFault` was accepted: clear TIM1's break flag and re-enable the bridge's outputs
    /// ([`super::drive::Drive::rearm`]).
    Rearm,
}

/// When a request is answered: the rig's clock, the link's clock and the uptime.
///
/// On the rig the two clocks are one; a simulated rig running faster than real time keeps the
/// link's clock on wall time, so a link-silence timeout of 1 s stays 1 s of the laptop's time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Clock {
    /// The rig's µs clock (wrapping), as its samples are stamped.
    pub rig_us: u32,
    /// The link's µs clock (wrapping), see [`crate::rig::safety::Inputs::link_us`].
    pub link_us: u32,
    /// Milliseconds since power-up, for the status.
    pub uptime_ms: u32,
}

impl Clock {
    /// One clock for both, as on the rig.
    pub const fn single(t_us: u32, uptime_ms: u32) -> Self {
        Self {
            rig_us: t_us,
            link_us: t_us,
            uptime_ms,
        }
    }
}

/// The rig's side of the conversation in one place: a [`Rig`] with its configuration, where
/// that came from, and the loop's counters, answering every [`Request`]. Owned by
/// [`crate::station::RigLoop`], which frames the answers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigServer {
    pub rig: Rig,
    pub cfg: RigConfig,
    pub origin: ConfigOrigin,
    pub counters: Counters,
    /// A start waiting for its check, or bring-up mode.
    pub activity: Activity,
    /// The last pre-run check: running, or its verdict.
    pub check: Option<Check>,
    /// The link's clock when a valid request last arrived (bring-up leaves on silence).
    pub heard_us: u32,
    /// This firmware's version, reported by `GetVersion`.
    pub firmware: [u16; 3],
    /// The protocol version reported by `GetVersion`: [`crate::link::PROTOCOL_VERSION`] unless a
    /// simulated rig is made to speak another one.
    pub protocol: u8,
    /// Why the rig last reset (reported in the status).
    pub reset: ResetInfo,
    /// The last request answered, to answer its repeat from it ([`super::repeat`]).
    pub last: Option<LastAnswer>,
}

impl RigServer {
    /// A stopped rig on `cfg` (which must have passed [`RigConfig::validate`]).
    pub fn new(
        cfg: RigConfig,
        origin: ConfigOrigin,
        theta_d0: Angle,
        at: Clock,
        firmware: [u16; 3],
    ) -> Self {
        let mut rig = Rig::new(&cfg, &cfg.calibration.estimator, theta_d0, at.rig_us);
        rig.link_message(at.link_us);
        Self {
            rig,
            cfg,
            origin,
            counters: Counters::default(),
            activity: Activity::None,
            check: None,
            heard_us: at.link_us,
            firmware,
            protocol: crate::link::PROTOCOL_VERSION,
            reset: ResetInfo::POWER_ON,
            last: None,
        }
    }

    /// Answers the request that arrived as frame `id`: a repeat of the last one (the host
    /// resending what it got no answer to) from the answer already given, without carrying it
    /// out again; any other as [`RigServer::respond`] does.
    pub fn respond_once(
        &mut self,
        id: FrameId,
        req: Request,
        at: Clock,
        estop: bool,
    ) -> (Response, Effect) {
        if let Some(resp) = self.last.and_then(|l| l.recall(id)) {
            self.rig.link_message(at.link_us);
            self.heard_us = at.link_us;
            return (resp, Effect::None);
        }
        let (resp, effect) = self.respond(req, at, estop);
        self.last = Some(LastAnswer::new(id, &req, &resp));
        (resp, effect)
    }

    /// Answers one request (decoded from a valid frame, so it also counts as the link being
    /// alive). `estop` is the e-stop line now.
    pub fn respond(&mut self, req: Request, at: Clock, estop: bool) -> (Response, Effect) {
        self.rig.link_message(at.link_us);
        self.heard_us = at.link_us;
        let (resp, effect) = match req {
            Request::GetVersion => (
                Response::Version(VersionInfo {
                    protocol: self.protocol,
                    firmware: self.firmware,
                }),
                Effect::None,
            ),
            Request::GetStatus => (
                Response::Status(self.status(estop, at.uptime_ms)),
                Effect::None,
            ),
            Request::SetDrive { .. } | Request::Stop | Request::ClearFault => {
                let r = match Command::of(&req) {
                    Some(c) => self.command(c),
                    None => Err(Reason::UnknownMessage),
                };
                match r {
                    Ok(()) if req == Request::ClearFault => (Response::Ok, Effect::Rearm),
                    Ok(()) => (Response::Ok, Effect::None),
                    Err(reason) => (Response::Refused(reason), Effect::None),
                }
            }
            Request::BringUp { duty, theta_d_deg } => match self.bring_up(duty, theta_d_deg) {
                Ok(()) => (Response::Ok, Effect::None),
                Err(reason) => (Response::Refused(reason), Effect::None),
            },
            Request::SetConfig(w) => match self.set_config(w, at) {
                Ok(Some(cfg)) => (Response::Ok, Effect::StoreConfig(cfg)),
                Ok(None) => (Response::Ok, Effect::None),
                Err(reason) => (Response::Refused(reason), Effect::None),
            },
            Request::GetConfig => (Response::Config(self.cfg.into()), Effect::None),
            Request::Telemetry { period_ms } => (Response::Ok, Effect::Telemetry { period_ms }),
        };
        let command = matches!(
            req,
            Request::SetDrive { .. }
                | Request::Stop
                | Request::ClearFault
                | Request::SetConfig(_)
                | Request::BringUp { .. }
        );
        if command && resp == Response::Ok {
            self.counters.commands = self.counters.commands.wrapping_add(1);
        }
        (resp, effect)
    }

    /// The status message now.
    pub fn status(&self, estop: bool, uptime_ms: u32) -> Status {
        let mut s = status(
            &self.rig,
            &self.cfg,
            estop,
            self.origin,
            uptime_ms,
            self.counters,
            self.reset,
        );
        s.check = self.check;
        if let Activity::Checking { .. } = self.activity {
            s.mode = Mode::Checking;
        }
        s.bring_up = match self.activity {
            Activity::BringUp { duty } => Some(duty.to_bits()),
            _ => None,
        };
        s
    }

    /// A drive command. A start from idle is checked now (all or nothing, as [`apply`]) but
    /// carried out only once its pre-run check passes; a stop ends a check or bring-up.
    fn command(&mut self, cmd: Command) -> Result<(), Reason> {
        if let Activity::Checking { .. } = self.activity {
            if cmd == Command::Stop {
                self.activity = Activity::None;
                self.check = Some(Check::Failed(Verdict::Aborted));
                return Ok(());
            }
            return Err(Reason::CheckRunning);
        }
        let starts = matches!(cmd, Command::SetDrive { r, .. } if r > 0)
            && self.rig.supervisor().mode() == safety::Mode::Idle;
        if !starts {
            apply(&mut self.rig, &self.cfg, cmd)?;
            if cmd == Command::Stop {
                self.activity = Activity::None;
            }
            return Ok(());
        }
        let mut trial = self.rig;
        apply(&mut trial, &self.cfg, cmd)?;
        self.activity = Activity::Checking {
            check: PreCheck::new(&self.cfg),
            start: cmd,
        };
        self.check = Some(Check::Running);
        Ok(())
    }

    /// Enters bring-up mode, or changes its duty and θd; only from idle.
    fn bring_up(&mut self, duty: i16, theta_d_deg: i32) -> Result<(), Reason> {
        if let Activity::Checking { .. } = self.activity {
            return Err(Reason::CheckRunning);
        }
        let cap = BRING_UP_DUTY_MAX.min(self.cfg.limits.duty_max);
        let cap_bits = libm::round(cap * 32_768.0) as i16;
        if duty.unsigned_abs() > cap_bits.unsigned_abs() {
            return Err(Reason::DutyAboveCap {
                requested: duty,
                cap: cap_bits,
            });
        }
        match self.rig.supervisor().mode() {
            safety::Mode::Idle => {}
            safety::Mode::Faulted(f) => return Err(Reason::Faulted(f.into())),
            m => return Err(Reason::WrongMode(m.into())),
        }
        let mut trial = self.rig;
        trial.request(Sr::SetDriveAngle {
            deg: from_q16(theta_d_deg),
        })?;
        self.rig = trial;
        self.activity = Activity::BringUp {
            duty: Duty::from_bits(duty),
        };
        Ok(())
    }

    /// A new configuration: valid, and the rig idle; the rig restarts on it with θd kept. A
    /// change of closed-loop R alone is taken in any mode.
    /// The one already in use and in flash is accepted as it is (`None`: nothing to store, so
    /// a repeated `SetConfig` never wears the flash page); a repaired one is stored, so the
    /// flash holds what the rig runs on.
    fn set_config(&mut self, w: WireConfig, at: Clock) -> Result<Option<RigConfig>, Reason> {
        let cfg = w.to_valid()?;
        let in_flash = matches!(
            self.origin,
            ConfigOrigin::Stored | ConfigOrigin::Received { saved: true }
        );
        if cfg == self.cfg && in_flash {
            return Ok(None);
        }
        let others = RigConfig {
            closed_loop: self.cfg.closed_loop,
            ..cfg
        };
        if others == self.cfg {
            // Only closed-loop R changed: taken at once, running or not (off returns the drive
            // to the open-loop ω of the R asked for), and stored.
            self.rig.set_closed_loop(cfg.closed_loop, at.rig_us);
            self.cfg = cfg;
            self.origin = ConfigOrigin::Received { saved: false };
            return Ok(Some(cfg));
        }
        config_change_allowed(&self.rig)?;
        match self.activity {
            Activity::Checking { .. } => return Err(Reason::CheckRunning),
            Activity::BringUp { .. } => self.activity = Activity::None,
            Activity::None => {}
        }
        let theta_d = self.rig.supervisor().theta_d();
        self.rig = Rig::new(&cfg, &cfg.calibration.estimator, theta_d, at.rig_us);
        self.rig.link_message(at.link_us);
        self.cfg = cfg;
        self.origin = ConfigOrigin::Received { saved: false };
        Ok(Some(cfg))
    }

    /// The telemetry message for one control tick: its report, the latest pendulum sample and
    /// motor current, and the estimator's state.
    pub fn telemetry(
        &self,
        t_us: u32,
        report: &ControlReport,
        theta: Angle,
        current: Amps,
    ) -> Telemetry {
        let (rig, cfg) = (&self.rig, &self.cfg);
        let e = rig.estimate();
        let mode = match self.activity {
            Activity::Checking { .. } => Mode::Checking,
            _ => report.mode.into(),
        };
        Telemetry {
            t_us,
            mode,
            theta: theta.to_bits(),
            phi: e.phi.to_bits(),
            phi_rate: e.phi_rate.to_bits(),
            omega_p: e.omega_p.map(|x| x.to_bits()),
            sigma: e.sigma.map(|x| x.to_bits()),
            settled: e.settled,
            equilibrium: e.equilibrium.map(Angle::to_bits),
            r: e.r.map(|(r, m)| (r.to_bits(), m.into())),
            periods: e.periods,
            omega: report.ref_omega.to_bits(),
            crank_speed: report.crank_speed.to_bits(),
            phase_error: report.phase_error.to_bits(),
            duty: report.duty.to_bits(),
            current: current.to_bits(),
            theta_d_deg: to_q16(deg_along_travel(
                report.theta_d,
                cfg.limits.drive_angle_min_deg,
            )),
            steady: report.steady,
            commands: self.counters.commands,
            wobble: match report.mode {
                safety::Mode::Running | safety::Mode::Stopping(_) => {
                    // Q30 rad → Q16 rad
                    rig.wobble().to_bits() >> 14
                }
                _ => 0,
            },
        }
    }

    /// The store that [`Effect::StoreConfig`] asked for finished (`ok`: it reached flash).
    pub fn config_saved(&mut self, ok: bool) {
        if let ConfigOrigin::Received { .. } = self.origin {
            self.origin = ConfigOrigin::Received { saved: ok };
        }
    }
}
