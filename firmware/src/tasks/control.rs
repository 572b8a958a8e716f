//! The control loop: the rig logic of `kapitza_core::rig` on the real motor, at interrupt
//! priority.
//!
//! ```text
//! every sample (fs, from the pendulum task):   rig.sample(t, θ): DDS tick, estimator
//! every fs/fc samples (the control tick):      e-stop in, rig.control: safety check, DDS
//!                                              target, phase lock → duty; bridge on only while
//!                                              running or stopping; θd to the servo, heartbeat
//!                                              to the watchdog, telemetry (every 10th tick),
//!                                              one link request answered (RigServer::respond)
//! ```
//! The loop is clocked by the samples, so the DDS advances exactly once per sample. The
//! estimator runs inside `rig.sample` because it needs each sample with the drive phase of the
//! same tick; a separate task would need a queue of (t, θ, φ) at 10 kHz for nothing.
//! Requests are answered here, between two ticks, by `kapitza_core::link::serve::RigServer`:
//! commands all or nothing, a new configuration only while idle.

use kapitza_core::link::convert::deg_along_travel;
use kapitza_core::link::serve::{self, Effect, RigServer};
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::estimator::Tuning;
use kapitza_core::rig::fixed::{Amps, Angle, Duty};
use kapitza_core::rig::phase_lock::Motor;
use kapitza_core::rig::safety::Mode;

use crate::board::{Drive, AMPS_PER_COUNT_Q16, CRANK_COUNTS};
use crate::channels::{
    CONFIG_SAVED, ESTOP, FROM_CONTROL, HEARTBEAT, SAMPLES, SAMPLE_HZ, SAVE_CONFIG, TELEMETRY,
    THETA_D, TO_CONTROL,
};

/// Telemetry is published every this many control ticks (100 Hz at fc = 1 kHz).
const TELEMETRY_EVERY: u32 = 10;

/// This firmware's version, from its Cargo.toml.
const FIRMWARE: [u16; 3] = [
    parse_u16(env!("CARGO_PKG_VERSION_MAJOR")),
    parse_u16(env!("CARGO_PKG_VERSION_MINOR")),
    parse_u16(env!("CARGO_PKG_VERSION_PATCH")),
];

const fn parse_u16(s: &str) -> u16 {
    let b = s.as_bytes();
    let mut v = 0u16;
    let mut i = 0;
    while i < b.len() {
        v = v * 10 + (b[i] - b'0') as u16;
        i += 1;
    }
    v
}

/// The crank motor behind the phase lock's three-method trait.
struct Hw<'a> {
    drive: &'a mut Drive,
    current: Amps,
}

impl Motor for Hw<'_> {
    fn crank_angle(&mut self) -> Angle {
        // count · 2^32 / CRANK_COUNTS, exact (CRANK_COUNTS is a power of two).
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

fn samples_per_control(cfg: &RigConfig) -> u32 {
    cfg.derived().samples_per_control.max(1)
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
    let theta0 = Angle::from_deg(theta0_deg);
    let mut srv = RigServer::new(cfg, origin, Tuning::DEFAULT, theta0, t0, FIRMWARE);
    THETA_D.signal(theta0_deg);
    let mut last_theta_d = theta0;
    let mut per_control = samples_per_control(&cfg);
    let mut k = 0u32;
    let mut ticks = 0u32;
    drive.enable(false);
    loop {
        let s = SAMPLES.receive().await;
        let c = &mut srv.counters;
        if s.failed {
            c.sensor_errors = c.sensor_errors.saturating_add(1);
        }
        if s.late {
            c.overruns = c.overruns.saturating_add(1);
        }
        srv.rig.sample(s.t_us, s.angle);
        k += 1;
        if k < per_control {
            continue;
        }
        k = 0;
        ticks = ticks.wrapping_add(1);
        let t = s.t_us;

        // No e-stop reading yet counts as pressed: the rig cannot start blind.
        let estop = ESTOP.try_get().unwrap_or(true);
        let mut hw = Hw {
            drive: &mut drive,
            current: Amps::ZERO,
        };
        let rep = srv.rig.control(t, &mut hw, estop);
        let current = hw.current;
        drive.enable(matches!(rep.mode, Mode::Running | Mode::Stopping(_)));
        if rep.theta_d != last_theta_d {
            last_theta_d = rep.theta_d;
            let min = srv.cfg.limits.drive_angle_min_deg;
            THETA_D.signal(deg_along_travel(rep.theta_d, min));
        }
        HEARTBEAT.signal(());
        if ticks.is_multiple_of(TELEMETRY_EVERY) {
            let tm = serve::telemetry(t, &srv.rig, &srv.cfg, &rep, s.angle, current);
            TELEMETRY.sender().send(tm);
        }
        if let Some(ok) = CONFIG_SAVED.try_take() {
            srv.config_saved(ok);
        }
        if let Ok(req) = TO_CONTROL.try_receive() {
            let uptime_ms = embassy_time::Instant::now().as_millis() as u32;
            let (resp, effect) = srv.respond(req, t, estop, uptime_ms);
            if let Effect::StoreConfig(new) = effect {
                per_control = samples_per_control(&new);
                k = 0;
                SAMPLE_HZ.sender().send(new.sample_hz);
                SAVE_CONFIG.signal(new);
            }
            // The link waits for each answer, so there is room.
            let _ = FROM_CONTROL.try_send((resp, effect));
        }
    }
}
