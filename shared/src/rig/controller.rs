//! One rig: drive generator, phase lock, estimator and safety composed into the two periodic
//! calls the firmware makes (and the closed-loop tests make in virtual time).
//!
//! ```text
//! sample tick (fs):   φ_ref ← DDS tick;  estimator ← (t, θ_pendulum, φ_ref)
//! control tick (fc):  motor → (crank angle, current), bridge lines;  safety.check → run / ramp / halt, θd;
//!                     DDS target or halt (a start aligns the DDS phase to the crank);
//!                     phase lock → duty → motor;  estimator restarts its slow history while
//!                     the drive ramps or θd slews;  closed-loop R (when on) trims ω once the
//!                     pendulum has settled ([`super::r_trim`])
//! ```

use super::bridge::Line;
use super::closed_loop::ClosedLoopR;
use super::config::RigConfig;
use super::dds::Dds;
use super::estimator::{Estimate, Estimator, Tuning};
use super::fixed::{Angle, Duty, RadPerSec};
use super::phase_lock::{LockOutput, Motor, PhaseLock};
use super::r_trim::RTrim;
use super::safety::{Inputs, Mode, Refusal, Request, Supervisor};

/// What one control tick did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ControlReport {
    pub mode: Mode,
    pub duty: Duty,
    /// Phase error φ_ref − φ_crank (rad).
    pub phase_error: RadPerSec,
    pub crank_speed: RadPerSec,
    pub ref_omega: RadPerSec,
    /// Slew-limited drive angle for the tilt servo.
    pub theta_d: Angle,
    /// The drive is at its set frequency and θd at its target: the estimator is measuring.
    pub steady: bool,
}

/// The rig logic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rig {
    dds: Dds,
    lock: PhaseLock,
    est: Estimator,
    sup: Supervisor,
    sensor_failed: bool,
    sensor_not_ready: bool,
    nfault_low: bool,
    bridge: Option<Line>,
    phase_error: RadPerSec,
    saturated: bool,
    trim: RTrim,
}

impl Rig {
    /// A stopped rig; `cfg` must have passed [`RigConfig::validate`].
    pub fn new(cfg: &RigConfig, tuning: &Tuning, theta_d0: Angle, now_us: u32) -> Self {
        let d = cfg.derived();
        Self {
            dds: Dds::new(cfg.sample_hz, d.dds_step),
            lock: PhaseLock::new(cfg),
            est: Estimator::new(cfg, tuning, theta_d0),
            sup: Supervisor::new(cfg, theta_d0, now_us),
            sensor_failed: false,
            sensor_not_ready: false,
            nfault_low: false,
            bridge: None,
            phase_error: RadPerSec::ZERO,
            saturated: false,
            trim: RTrim::new(
                cfg.closed_loop,
                cfg.omega_for_r(1.0).unwrap_or(f64::INFINITY),
                cfg.limits.omega_max,
            ),
        }
    }

    /// A valid message arrived from the laptop (keeps the link alive); `now_us` on the link's
    /// clock.
    pub fn link_message(&mut self, now_us: u32) {
        self.sup.heard_from_link(now_us);
    }

    /// A command; refused ones change nothing.
    pub fn request(&mut self, req: Request) -> Result<(), Refusal> {
        self.sup.request(req)
    }

    /// The drive strength R asked for with the last drive request (0: stopped): closed-loop R
    /// holds the in-situ R at it; the drive starts from its open-loop ω.
    pub fn r_asked(&mut self, r: f64) {
        self.trim.asked(r);
    }

    /// Closed-loop R on or off (band, rate); off returns ω to the open-loop ω of the R asked
    /// for. `now_us` on the rig's clock.
    pub fn set_closed_loop(&mut self, settings: ClosedLoopR, now_us: u32) {
        if let Some(omega) = self.trim.set(settings, now_us) {
            // The open-loop ω of an accepted R is within the limits: the request cannot fail.
            let _ = self.sup.request(Request::SetOmega { omega });
        }
    }

    /// The closed-loop R's state: its settings and the R the drive's ω stands for.
    pub fn r_trim(&self) -> &RTrim {
        &self.trim
    }

    /// The pendulum sensor's driver says it has failed (or recovered); the next control tick
    /// latches [`super::safety::Fault::Sensor`] while it is failed.
    pub fn sensor_failed(&mut self, failed: bool) {
        self.sensor_failed = failed;
    }

    /// The pendulum sensor's last diagnostics say it is not ready
    /// ([`super::as5047::Diagnostics::ready`] clear): the next control tick latches
    /// [`super::safety::Fault::Sensor`] if the drive runs.
    pub fn sensor_not_ready(&mut self, not_ready: bool) {
        self.sensor_not_ready = not_ready;
    }

    /// The H-bridge's lines for the next control tick: nFAULT's level, and the fault they show
    /// ([`super::bridge::Watch::check`]), latched as [`super::safety::Fault::Bridge`].
    pub fn bridge(&mut self, nfault_low: bool, fault: Option<Line>) {
        self.nfault_low = nfault_low;
        self.bridge = fault;
    }

    /// Sample tick: advance the reference phase and feed the estimator. Returns the phase.
    #[inline]
    pub fn sample(&mut self, t_us: u32, pendulum: Angle) -> Angle {
        let psi = self.dds.tick();
        self.est.push(t_us, pendulum, psi);
        psi
    }

    /// Control tick, the link's clock the same as the rig's.
    pub fn control<M: Motor>(&mut self, t_us: u32, motor: &mut M, estop: bool) -> ControlReport {
        self.control_at(t_us, t_us, motor, estop)
    }

    /// Control tick, with the link's clock apart ([`super::safety::Inputs::link_us`]).
    pub fn control_at<M: Motor>(
        &mut self,
        t_us: u32,
        link_us: u32,
        motor: &mut M,
        estop: bool,
    ) -> ControlReport {
        let crank = motor.crank_angle();
        let inputs = Inputs {
            estop,
            current: motor.current(),
            crank_speed: self.lock.crank_speed(),
            ref_omega: self.dds.omega(),
            drive_stopped: self.dds.is_stopped(),
            sensor_failed: self.sensor_failed,
            phase_error: self.phase_error,
            duty_saturated: self.saturated,
            ramping: self.dds.is_ramping(),
            link_us,
            nfault_low: self.nfault_low,
            bridge: self.bridge.take(),
            sensor_not_ready: self.sensor_not_ready,
        };
        let out = self.sup.check(t_us, &inputs);
        if out.halt {
            self.dds.halt();
        } else if out.active && self.dds.is_stopped() && out.target_word > 0 {
            self.dds.start_at(crank, out.target_word);
        } else {
            self.dds.set_target(out.target_word);
        }
        let run = out.active && !out.halt;
        let lock: LockOutput = self.lock.update(
            run,
            self.dds.phase(),
            self.dds.omega(),
            self.dds.accel(),
            crank,
        );
        motor.set_duty(lock.duty);
        self.phase_error = lock.error;
        self.saturated = lock.saturated;
        let steady = run
            && !self.dds.is_ramping()
            && self.dds.word() > 0
            && out.theta_d == self.sup.theta_d_target();
        if !steady {
            self.est.reset_slow(out.theta_d);
        }
        let e = self.est.estimate();
        let settled_r = match e.r {
            Some((r, _)) if steady && e.settled => Some(r.to_num::<f64>()),
            _ => None,
        };
        if let Some(omega) = self.trim.update(t_us, settled_r) {
            // Within the limits by construction (r_trim clamps to ω_max); a refusal (the mode
            // changed this tick) leaves the drive as it was.
            let _ = self.sup.request(Request::SetOmega { omega });
        }
        ControlReport {
            mode: self.sup.mode(),
            duty: lock.duty,
            phase_error: lock.error,
            crank_speed: lock.crank_speed,
            ref_omega: self.dds.omega(),
            theta_d: out.theta_d,
            steady,
        }
    }

    pub fn estimate(&self) -> &Estimate {
        self.est.estimate()
    }
    /// The fast wobble's amplitude over the latest drive period (rad, Q30).
    pub fn wobble(&self) -> super::fixed::Unit {
        self.est.wobble_now()
    }
    pub fn dds(&self) -> &Dds {
        &self.dds
    }
    pub fn supervisor(&self) -> &Supervisor {
        &self.sup
    }
}
