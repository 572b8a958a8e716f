//! The safety supervisor: what the rig may do, and what stops it.
//!
//! A state machine with two entry points: [`Supervisor::request`] for commands from the laptop
//! (checked against the limits; a refused request returns its reason and changes nothing) and
//! [`Supervisor::check`] once per control tick with the hardware inputs (e-stop line, motor
//! current, crank speed). Its output says whether the drive may run, the frequency it ramps to,
//! and the slew-limited drive angle for the tilt servo.
//!
//! ```text
//!            Start(ω ≤ ω_max)                Stop, or link silent > timeout
//!   Idle ───────────────────────▶ Running ───────────────────────────────▶ Stopping ─▶ Idle
//!    ▲                               │  SetOmega (ramped), SetDriveAngle (slewed)      (when the
//!    │ ClearFault (e-stop released,  │                                                  drive is 0)
//!    │  nFAULT high)                 │
//!    └──────────── Faulted ◀─────────┴── e-stop, over-current (peak, RMS), stall, wrong direction,
//!                                        sensor, phase lock lost, duty ceiling, bridge (from any
//!                                        state): drive halted at once, duty 0, latched
//! ```
//! A drive strength R from the laptop becomes ω = ωc√R through [`RigConfig::omega_for_r`]
//! before it reaches the supervisor (physics §7: "setting R means computing ω from R, A and ℓ").
//! Limits: ω ≤ ω_max (refused above); |dω/dt| ≤ the ramp rate (the drive generator's step, not
//! a request); |dθd/dt| ≤ its limit (slewed here); θd inside the mount's travel (refused
//! outside). Over-current: I > I_max for `overcurrent_ms`. Stall: commanded ω ≥ `stall_min_omega`
//! and crank speed < `stall_fraction`·commanded for `stall_ms`. Wrong direction: the same
//! commanded speed while the crank turns backwards faster than `stall_fraction`·commanded for
//! `stall_ms`. Sensor: the pendulum sensor's driver reports it failed, or, while the drive runs,
//! its diagnostics say it is not ready. Bridge: the H-bridge's nFAULT or TIM1's break while the
//! bridge is awake ([`super::bridge`]). Phase lock lost: two
//! cycle slips within [`SLIP_WINDOW_US`]. Over-current RMS (I²t): the exponential mean of i²
//! over [`RMS_TAU_S`] above ([`RMS_FRACTION`]·I_max)². Duty ceiling: the phase lock clamped at
//! `duty_max` for `stall_ms` while driving.
//!
//! # When the laptop link goes silent
//!
//! The link layer calls [`Supervisor::heard_from_link`] for every valid message. If the rig is
//! `Running` and nothing valid arrives for `link_timeout_ms`, it performs a *soft stop*: the drive
//! ramps down at the normal rate limit (an abrupt stop would fling an inverted pendulum), θd holds
//! where it is, and the mode becomes `Stopping(LinkSilent)` and then `Idle` with the reason kept
//! in [`Supervisor::last_stop`]. It never restarts by itself: when the link returns the laptop
//! sees `Idle` and the reason, and must send `Start` again. Silence while `Idle`, `Stopping` or
//! `Faulted` changes nothing.

use super::bridge::Line;
use super::config::RigConfig;
use super::dds::word_from_omega;
use super::fixed::{elapsed_us, Amps, Angle, RadPerSec};

/// A command from the laptop, in SI units (θd in degrees, as the user gives it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Request {
    /// Soft start from `Idle` to ω (rad/s).
    Start { omega: f64 },
    /// New ω while `Running`; ramped.
    SetOmega { omega: f64 },
    /// New drive angle θd (degrees); slewed.
    SetDriveAngle { deg: f64 },
    /// Soft stop.
    Stop,
    /// Leave `Faulted` once the cause is gone (the e-stop line released).
    ClearFault,
}

/// Why a request was refused. The supervisor is unchanged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Refusal {
    /// Not a finite number ≥ 0.
    OmegaInvalid {
        requested: f64,
    },
    OmegaAboveLimit {
        requested: f64,
        limit: f64,
    },
    DriveAngleOutOfRange {
        requested: f64,
        min: f64,
        max: f64,
    },
    /// A fault is latched; clear it first.
    Faulted(Fault),
    /// `SetOmega` needs `Running`; `Start` needs `Idle`.
    WrongMode(Mode),
    /// `ClearFault` while the e-stop line is still active.
    EStopStillActive,
    /// `ClearFault` while the H-bridge's nFAULT still reads low: re-enabling the outputs
    /// would only trip the break again.
    BridgeFaultActive,
}

impl core::fmt::Display for Refusal {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::OmegaInvalid { requested } => {
                write!(f, "omega = {requested} is not a finite number >= 0")
            }
            Self::OmegaAboveLimit { requested, limit } => {
                write!(
                    f,
                    "omega = {requested} rad/s is above the limit {limit} rad/s"
                )
            }
            Self::DriveAngleOutOfRange {
                requested,
                min,
                max,
            } => write!(
                f,
                "drive angle {requested} deg is outside the actuator's travel [{min}, {max}] deg"
            ),
            Self::Faulted(x) => write!(f, "a fault is latched ({x:?}): clear it first"),
            Self::WrongMode(m) => write!(f, "not allowed in mode {m:?}"),
            Self::EStopStillActive => f.write_str("the emergency stop is still pressed"),
            Self::BridgeFaultActive => {
                f.write_str("the H-bridge still signals a fault (nFAULT low)")
            }
        }
    }
}

/// A latched fault: the drive is halted until [`Request::ClearFault`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fault {
    EStop,
    OverCurrent,
    Stall,
    /// The pendulum sensor gave no good angle for too long, or reports its magnet out of range
    /// ([`super::as5047::Health::failed`]).
    Sensor,
    /// The crank turns against the drive: swapped encoder channels or motor leads. The phase
    /// lock would push it to full duty; caught like a stall, by sign.
    WrongDirection,
    /// The crank slipped a whole cycle behind or ahead of the drive twice within
    /// [`SLIP_WINDOW_US`] while ω is steady: the phase lock cannot hold it (a motor too weak for the set ω, a
    /// slipping belt). The crank may still turn fast enough not to count as a stall.
    PhaseLockLost,
    /// The motor current's RMS over the last [`RMS_TAU_S`] is above [`RMS_FRACTION`] of
    /// `current_max`: an I²t limit for the winding and the bridge's continuous rating, below
    /// the peak trip.
    OverCurrentRms,
    /// The drive has needed the duty ceiling (`duty_max`) for `stall_ms`: the motor cannot
    /// hold the asked-for speed within the duty it may use.
    DutyCeiling,
    /// The H-bridge signalled a fault while awake ([`super::bridge`]): its outputs are off
    /// (TIM1's break) until `ClearFault` re-arms them.
    Bridge(Line),
}

/// Two cycle slips within this long lose the lock (µs).
pub const SLIP_WINDOW_US: u32 = 1_000_000;
/// The I²t limit's time constant (s): the mean of i² is an exponential average over it.
pub const RMS_TAU_S: f32 = 1.0;
/// The RMS limit as a fraction of the peak limit `current_max`: the DRV8874 carrier's
/// continuous ≈ 2 A against its peak-trip setting of 3 A (docs/hardware.md, "Parts").
pub const RMS_FRACTION: f32 = 0.6;

/// Why the drive last stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    Requested,
    LinkSilent,
    Fault(Fault),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Idle,
    Running,
    Stopping(StopReason),
    Faulted(Fault),
}

/// Hardware inputs for one control tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Inputs {
    pub estop: bool,
    pub current: Amps,
    pub crank_speed: RadPerSec,
    /// The drive reference ω now (from the drive generator).
    pub ref_omega: RadPerSec,
    /// The drive generator has reached zero frequency.
    pub drive_stopped: bool,
    /// The pendulum sensor has failed ([`super::as5047::Health::failed`]).
    pub sensor_failed: bool,
    /// The phase lock's error φ_ref − φ_crank (rad, in (−π, π]) at the previous tick.
    pub phase_error: RadPerSec,
    /// The drive generator is ramping ω: the crank's lag behind the feed-forward may slip
    /// cycles then without the lock being lost (the stall check watches that phase).
    pub ramping: bool,
    /// The phase lock's duty is clamped at the ceiling `duty_max`.
    pub duty_saturated: bool,
    /// The link's clock now (µs, wrapping), the clock [`Supervisor::heard_from_link`] is given.
    /// On the rig it is `now_us`; a simulated rig running faster than real time gives wall time,
    /// so the link-silence timeout stays what it says.
    pub link_us: u32,
    /// The H-bridge's nFAULT reads low now (asleep or not): `ClearFault` waits for it.
    pub nfault_low: bool,
    /// A bridge fault seen this tick ([`super::bridge::Watch::check`]).
    pub bridge: Option<Line>,
    /// The pendulum sensor's last diagnostics say it is not ready
    /// ([`super::as5047::Diagnostics::ready`] clear): a sensor fault while the drive runs.
    pub sensor_not_ready: bool,
}

/// What the drive may do after this tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Output {
    /// The phase lock may drive the motor.
    pub active: bool,
    /// Stop the drive generator now (no ramp).
    pub halt: bool,
    /// Frequency word the drive generator ramps toward.
    pub target_word: u32,
    /// Slew-limited drive angle for the tilt servo.
    pub theta_d: Angle,
}

/// The supervisor's whole state. `PartialEq` so tests can show a refusal changed nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Supervisor {
    mode: Mode,
    last_stop: Option<StopReason>,
    target_word: u32,
    theta_target: Angle,
    theta: Angle,
    last_link_us: u32,
    over_since: Option<u32>,
    stall_since: Option<u32>,
    reverse_since: Option<u32>,
    ceiling_since: Option<u32>,
    last_phase_error: RadPerSec,
    last_slip_us: Option<u32>,
    /// Exponential mean of i² (A²) and its per-tick weight h/τ.
    i2_mean: f32,
    i2_weight: f32,
    i2_max: f32,
    estop_seen: bool,
    nfault_seen: bool,
    // limits, fixed at construction
    omega_max: f64,
    theta_min_deg: f64,
    theta_min: Angle,
    /// The travel max − min in 2^-32 turn.
    theta_span: i64,
    theta_max_deg: f64,
    theta_step: u32,
    current_max: Amps,
    over_us: u32,
    stall_min: RadPerSec,
    stall_frac_q16: i64,
    stall_us: u32,
    link_us: u32,
}

impl Supervisor {
    /// Idle, with θd at `theta_d0` (the actuator's position at power-up), link heard at `now_us`.
    pub fn new(cfg: &RigConfig, theta_d0: Angle, now_us: u32) -> Self {
        let l = &cfg.limits;
        let per_tick_deg = l.drive_angle_rate_max_deg / f64::from(cfg.control_hz.max(1));
        Self {
            mode: Mode::Idle,
            last_stop: None,
            target_word: 0,
            theta_target: theta_d0,
            theta: theta_d0,
            last_link_us: now_us,
            over_since: None,
            stall_since: None,
            reverse_since: None,
            ceiling_since: None,
            last_phase_error: RadPerSec::ZERO,
            last_slip_us: None,
            i2_mean: 0.0,
            i2_weight: 1.0 / (RMS_TAU_S * cfg.control_hz.max(1) as f32),
            i2_max: {
                let i = RMS_FRACTION * l.current_max as f32;
                i * i
            },
            estop_seen: false,
            nfault_seen: false,
            omega_max: l.omega_max,
            theta_min_deg: l.drive_angle_min_deg,
            theta_min: Angle::from_deg(l.drive_angle_min_deg),
            theta_span: libm::round(
                (l.drive_angle_max_deg - l.drive_angle_min_deg) / 360.0 * 4_294_967_296.0,
            ) as i64,
            theta_max_deg: l.drive_angle_max_deg,
            theta_step: libm::floor(per_tick_deg / 360.0 * 4_294_967_296.0).max(1.0) as u32,
            current_max: Amps::saturating_from_num(l.current_max),
            over_us: l.overcurrent_ms.saturating_mul(1000),
            stall_min: RadPerSec::saturating_from_num(l.stall_min_omega),
            stall_frac_q16: libm::round(l.stall_fraction * 65_536.0) as i64,
            stall_us: l.stall_ms.saturating_mul(1000),
            link_us: l.link_timeout_ms.saturating_mul(1000),
        }
    }

    pub fn mode(&self) -> Mode {
        self.mode
    }
    pub fn last_stop(&self) -> Option<StopReason> {
        self.last_stop
    }
    pub fn target_word(&self) -> u32 {
        self.target_word
    }
    pub fn theta_d(&self) -> Angle {
        self.theta
    }
    pub fn theta_d_target(&self) -> Angle {
        self.theta_target
    }

    /// A valid message arrived from the laptop (`now_us` on the link's clock, [`Inputs::link_us`]).
    pub fn heard_from_link(&mut self, now_us: u32) {
        self.last_link_us = now_us;
    }

    fn check_omega(&self, omega: f64) -> Result<u32, Refusal> {
        if !omega.is_finite() || omega < 0.0 {
            return Err(Refusal::OmegaInvalid { requested: omega });
        }
        if omega > self.omega_max {
            return Err(Refusal::OmegaAboveLimit {
                requested: omega,
                limit: self.omega_max,
            });
        }
        word_from_omega(omega).ok_or(Refusal::OmegaInvalid { requested: omega })
    }

    /// Applies a request, or refuses it with the reason and leaves everything as it was.
    pub fn request(&mut self, req: Request) -> Result<(), Refusal> {
        if let Mode::Faulted(f) = self.mode {
            if req != Request::ClearFault {
                return Err(Refusal::Faulted(f));
            }
        }
        match req {
            Request::Start { omega } => {
                let w = self.check_omega(omega)?;
                if self.mode != Mode::Idle {
                    return Err(Refusal::WrongMode(self.mode));
                }
                self.mode = Mode::Running;
                self.target_word = w;
                self.stall_since = None;
                self.reverse_since = None;
                self.ceiling_since = None;
                self.last_slip_us = None;
            }
            Request::SetOmega { omega } => {
                let w = self.check_omega(omega)?;
                if self.mode != Mode::Running {
                    return Err(Refusal::WrongMode(self.mode));
                }
                self.target_word = w;
            }
            Request::SetDriveAngle { deg } => {
                if !(deg.is_finite() && deg >= self.theta_min_deg && deg <= self.theta_max_deg) {
                    return Err(Refusal::DriveAngleOutOfRange {
                        requested: deg,
                        min: self.theta_min_deg,
                        max: self.theta_max_deg,
                    });
                }
                self.theta_target = Angle::from_deg(deg);
            }
            Request::Stop => {
                if self.mode == Mode::Running {
                    self.mode = Mode::Stopping(StopReason::Requested);
                    self.target_word = 0;
                }
            }
            Request::ClearFault => {
                if let Mode::Faulted(_) = self.mode {
                    if self.estop_seen {
                        return Err(Refusal::EStopStillActive);
                    }
                    if self.nfault_seen {
                        return Err(Refusal::BridgeFaultActive);
                    }
                    self.mode = Mode::Idle;
                    self.over_since = None;
                    self.stall_since = None;
                    self.reverse_since = None;
                    self.ceiling_since = None;
                }
            }
        }
        Ok(())
    }

    fn fault(&mut self, f: Fault) {
        self.mode = Mode::Faulted(f);
        self.last_stop = Some(StopReason::Fault(f));
        self.target_word = 0;
    }

    /// One control tick: faults, link silence, end of a stop, θd slew.
    pub fn check(&mut self, now_us: u32, inp: &Inputs) -> Output {
        self.estop_seen = inp.estop;
        self.nfault_seen = inp.nfault_low;
        let mut halt = false;
        if inp.estop {
            if self.mode != Mode::Faulted(Fault::EStop) {
                self.fault(Fault::EStop);
            }
            halt = true;
        }
        // Over-current, debounced by time.
        if inp.current.saturating_abs() > self.current_max {
            let since = *self.over_since.get_or_insert(now_us);
            if elapsed_us(since, now_us) >= self.over_us && !matches!(self.mode, Mode::Faulted(_)) {
                self.fault(Fault::OverCurrent);
            }
        } else {
            self.over_since = None;
        }
        if let Some(line) = inp.bridge {
            if !matches!(self.mode, Mode::Faulted(_)) {
                self.fault(Fault::Bridge(line));
            }
        }
        // A sensor that stops being ready while the drive runs (a MISO line stuck low reads
        // DIAAGC 0: AGC 0, LF clear) is as failed as a silent one; idle, the pre-run check
        // refuses the next start for it.
        let driving_now = matches!(self.mode, Mode::Running | Mode::Stopping(_));
        if (inp.sensor_failed || (driving_now && inp.sensor_not_ready))
            && !matches!(self.mode, Mode::Faulted(_))
        {
            self.fault(Fault::Sensor);
        }
        // I²t: the exponential mean of i² against the RMS limit squared.
        let i = inp.current.to_num::<f32>();
        self.i2_mean += (i * i - self.i2_mean) * self.i2_weight;
        if self.i2_mean > self.i2_max && !matches!(self.mode, Mode::Faulted(_)) {
            self.fault(Fault::OverCurrentRms);
        }
        // Stall: driving hard but the crank does not follow. Wrong direction: it follows
        // backwards (the drive reference is never negative), at least as fast as a stall is slow.
        let driving = matches!(self.mode, Mode::Running | Mode::Stopping(_));
        let want = inp.ref_omega.saturating_abs();
        let got = inp.crank_speed.saturating_abs();
        let bar = i64::from(want.to_bits()) * self.stall_frac_q16;
        let slow = i64::from(got.to_bits()) * 65_536 < bar;
        let backwards = i64::from(inp.crank_speed.to_bits()) * 65_536 <= -bar;
        let armed = driving && want >= self.stall_min;
        if held(&mut self.stall_since, armed && slow, now_us, self.stall_us) {
            self.fault(Fault::Stall);
        }
        if held(
            &mut self.reverse_since,
            armed && backwards,
            now_us,
            self.stall_us,
        ) {
            self.fault(Fault::WrongDirection);
        }
        if held(
            &mut self.ceiling_since,
            driving && inp.duty_saturated,
            now_us,
            self.stall_us,
        ) {
            self.fault(Fault::DutyCeiling);
        }
        // A cycle slip: the wrapped phase error jumps from beyond +π/2 to beyond −π/2 or back,
        // with the crank turning the right way at speed (else it is a stall or a wrong
        // direction, whose own checks name it).
        let quarter = RadPerSec::from_bits(102_944); // π/2 in I16F16
        let (e0, e1) = (self.last_phase_error, inp.phase_error);
        self.last_phase_error = e1;
        let slipped = (e0 > quarter && e1 < -quarter) || (e0 < -quarter && e1 > quarter);
        if slipped && self.mode == Mode::Running && !inp.ramping && !slow && !backwards {
            match self.last_slip_us {
                Some(t) if elapsed_us(t, now_us) <= SLIP_WINDOW_US => {
                    self.fault(Fault::PhaseLockLost)
                }
                _ => self.last_slip_us = Some(now_us),
            }
        }
        // Link silence: soft stop.
        if self.mode == Mode::Running && elapsed_us(self.last_link_us, inp.link_us) > self.link_us {
            self.mode = Mode::Stopping(StopReason::LinkSilent);
            self.target_word = 0;
        }
        if let Mode::Stopping(reason) = self.mode {
            if inp.drive_stopped {
                self.mode = Mode::Idle;
                self.last_stop = Some(reason);
            }
        }
        if let Mode::Faulted(_) = self.mode {
            halt = true;
        } else {
            // Slew θd toward its target by at most one step per tick, along the mount's travel
            // (measured from its lower end), never through the side it cannot reach; from
            // outside the travel (only possible at power-up), the shortest way.
            let off = |a: Angle| i64::from((a - self.theta_min).to_turns_u32());
            let d = if off(self.theta) <= self.theta_span {
                off(self.theta_target) - off(self.theta)
            } else {
                i64::from((self.theta_target - self.theta).to_bits())
            };
            let step = i64::from(self.theta_step).min(d.abs()) as i32;
            self.theta += Angle::from_bits(if d >= 0 { step } else { -step });
        }
        Output {
            active: matches!(self.mode, Mode::Running | Mode::Stopping(_)),
            halt,
            target_word: self.target_word,
            theta_d: self.theta,
        }
    }
}

/// A condition debounced by time: true once it has held for `for_us` since `since` (set when it
/// began, cleared when it stops).
fn held(since: &mut Option<u32>, cond: bool, now_us: u32, for_us: u32) -> bool {
    if !cond {
        *since = None;
        return false;
    }
    elapsed_us(*since.get_or_insert(now_us), now_us) >= for_us
}
