//! The control loop: the rig logic of `kapitza_core::rig` on the real motor, at interrupt
//! priority.
//!
//! ```text
//! every sample (fs, from the pendulum task):   rig.sample(t, θ): DDS tick, estimator
//! every fs/fc samples (the control tick):      link keep-alive, e-stop in, rig.control:
//!                                              safety check, DDS target, phase lock → duty;
//!                                              bridge on only while running or stopping;
//!                                              θd to the servo, heartbeat to the watchdog,
//!                                              telemetry (every 10th tick), one link request
//! ```
//! The loop is clocked by the samples, so the DDS advances exactly once per sample. The
//! estimator runs inside `rig.sample` because it needs each sample with the drive phase of the
//! same tick; a separate task would need a queue of (t, θ, φ) at 10 kHz for nothing.
//! Link requests are applied here, between two ticks, all or nothing (`link::serve::apply`).

use kapitza_core::link::convert::deg_along_travel;
use kapitza_core::link::message::Counters;
use kapitza_core::link::serve;
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::controller::Rig;
use kapitza_core::rig::estimator::Tuning;
use kapitza_core::rig::fixed::{Amps, Angle, Duty};
use kapitza_core::rig::phase_lock::Motor;
use kapitza_core::rig::safety::Mode;

use crate::board::{Drive, AMPS_PER_COUNT_Q16, CRANK_COUNTS};
use crate::channels::{
    FromControl, ToControl, CONFIG_SAVED, ESTOP, FROM_CONTROL, HEARTBEAT, LINK_HEARD, SAMPLES,
    SAMPLE_HZ, SAVE_CONFIG, TELEMETRY, THETA_D, TO_CONTROL,
};

/// Telemetry is published every this many control ticks (100 Hz at fc = 1 kHz).
const TELEMETRY_EVERY: u32 = 10;

/// The crank motor behind the phase lock's three-method trait.
struct Hw<'a> {
    drive: &'a mut Drive,
    current: Amps,
}

impl Motor for Hw<'_> {
    fn crank_angle(&mut self) -> Angle {
        Angle::from_turns_u32(self.drive.crank_count() * (u32::MAX / CRANK_COUNTS + 1))
    }
    fn current(&mut self) -> Amps {
        let counts = i32::from(self.drive.current_counts());
        self.current = Amps::from_bits(counts.saturating_mul(AMPS_PER_COUNT_Q16));
        self.current
    }
    fn set_duty(&mut self, duty: Duty) {
        self.drive.set_duty(duty.to_bits());
    }
}

/// The rig, its configuration and the loop's bookkeeping.
struct Loop {
    rig: Rig,
    cfg: RigConfig,
    origin: ConfigOrigin,
    counters: Counters,
    samples_per_control: u32,
}

impl Loop {
    fn new(cfg: RigConfig, origin: ConfigOrigin, theta_d: Angle, t_us: u32) -> Self {
        Self {
            rig: Rig::new(&cfg, &Tuning::DEFAULT, theta_d, t_us),
            samples_per_control: cfg.derived().samples_per_control.max(1),
            cfg,
            origin,
            counters: Counters::default(),
        }
    }

    /// One request from the link, answered at once.
    fn answer(&mut self, msg: ToControl, t_us: u32, estop: bool) -> FromControl {
        match msg {
            ToControl::Command(c) => FromControl::Done(serve::apply(&mut self.rig, &self.cfg, c)),
            ToControl::SetConfig(cfg) => {
                FromControl::Done(serve::config_change_allowed(&self.rig).map(|()| {
                    let theta_d = self.rig.supervisor().theta_d();
                    let counters = self.counters;
                    *self = Self::new(cfg, ConfigOrigin::Received { saved: false }, theta_d, t_us);
                    self.counters = counters;
                    SAMPLE_HZ.sender().send(cfg.sample_hz);
                    SAVE_CONFIG.signal(cfg);
                }))
            }
            ToControl::GetStatus => FromControl::Status(serve::status(
                &self.rig,
                &self.cfg,
                estop,
                self.origin,
                embassy_time::Instant::now().as_millis() as u32,
                self.counters,
            )),
            ToControl::GetConfig => FromControl::Config(self.cfg),
        }
    }
}

#[embassy_executor::task]
pub async fn run(mut drive: Drive, cfg: RigConfig, origin: ConfigOrigin) {
    // The servo's position at power-up is unknown (it is open loop): command θd = 0 (vertical
    // shaking), or the nearest end of the travel if 0 is outside it, while the drive is idle.
    let theta0_deg = 0f64.clamp(
        cfg.limits.drive_angle_min_deg,
        cfg.limits.drive_angle_max_deg,
    );
    let t0 = embassy_time::Instant::now().as_micros() as u32;
    let mut lp = Loop::new(cfg, origin, Angle::from_deg(theta0_deg), t0);
    THETA_D.signal(theta0_deg);
    let mut last_theta_d = lp.rig.supervisor().theta_d();
    let mut k = 0u32;
    let mut ticks = 0u32;
    drive.enable(false);
    loop {
        let s = SAMPLES.receive().await;
        if s.failed {
            lp.counters.sensor_errors = lp.counters.sensor_errors.saturating_add(1);
        }
        if s.late {
            lp.counters.overruns = lp.counters.overruns.saturating_add(1);
        }
        lp.rig.sample(s.t_us, s.angle);
        k += 1;
        if k < lp.samples_per_control {
            continue;
        }
        k = 0;
        ticks = ticks.wrapping_add(1);
        let t = s.t_us;

        if LINK_HEARD.try_take().is_some() {
            lp.rig.link_message(t);
        }
        // No e-stop reading yet counts as pressed: the rig cannot start blind.
        let estop = ESTOP.try_get().unwrap_or(true);
        let mut hw = Hw {
            drive: &mut drive,
            current: Amps::ZERO,
        };
        let rep = lp.rig.control(t, &mut hw, estop);
        let current = hw.current;
        drive.enable(matches!(rep.mode, Mode::Running | Mode::Stopping(_)));
        if rep.theta_d != last_theta_d {
            last_theta_d = rep.theta_d;
            THETA_D.signal(deg_along_travel(
                rep.theta_d,
                lp.cfg.limits.drive_angle_min_deg,
            ));
        }
        HEARTBEAT.signal(());
        if ticks.is_multiple_of(TELEMETRY_EVERY) {
            TELEMETRY.sender().send(serve::telemetry(
                t, &lp.rig, &lp.cfg, &rep, s.angle, current,
            ));
        }
        if let Some(ok) = CONFIG_SAVED.try_take() {
            if let ConfigOrigin::Received { .. } = lp.origin {
                lp.origin = ConfigOrigin::Received { saved: ok };
            }
        }
        if let Ok(msg) = TO_CONTROL.try_receive() {
            let reply = lp.answer(msg, t, estop);
            if let FromControl::Done(Err(r)) = reply {
                defmt::info!("refused: {}", r);
            }
            // The link waits for each answer, so there is room.
            let _ = FROM_CONTROL.try_send(reply);
        }
    }
}
