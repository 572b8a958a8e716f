//! The rig's side of the link, free of hardware: applying a command to a [`Rig`] all or nothing,
//! and building the status and telemetry messages from it. The firmware calls these from its
//! control loop; the simulated rig can call the same.

use super::convert::{deg_along_travel, from_q16, to_q16};
use super::message::{Counters, Request, Status, Telemetry};
use super::reason::Reason;
use crate::persist::ConfigOrigin;
use crate::rig::config::RigConfig;
use crate::rig::controller::{ControlReport, Rig};
use crate::rig::dds::omega_of_word;
use crate::rig::fixed::{Amps, Angle};
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
/// ClearFault:       leaves Faulted once the e-stop is released
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
    }
}

/// The telemetry message for one control tick: its report, the latest pendulum sample and
/// motor current, and the estimator's state.
pub fn telemetry(
    t_us: u32,
    rig: &Rig,
    cfg: &RigConfig,
    report: &ControlReport,
    theta: Angle,
    current: Amps,
) -> Telemetry {
    let e = rig.estimate();
    Telemetry {
        t_us,
        mode: report.mode.into(),
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
    }
}
