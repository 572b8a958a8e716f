//! The control loop: `kapitza_core::station::RigLoop` on the real motor, at interrupt priority.
//!
//! Every rig decision is the loop's (when the control tick runs, when the bridge is awake,
//! requests and their answers, telemetry pacing, counters); this task moves its inputs and
//! outputs to and from the peripherals and the other tasks:
//!
//! ```text
//! every sample (from the pendulum task):  loop.sample
//! when it says a control tick is due:     bytes from the link task → loop.receive (answered now)
//!                                         loop.control(encoder, ADC counts, nFAULT and TIM1's
//!                                         BIF, e-stop pin) → duty, a re-arm (BIF, MOE)
//!                                         bridge enable, servo pulse, a configuration to
//!                                         store, heartbeat to the watchdog, θd and the last
//!                                         fault to the retained RAM
//!                                         loop.transmit → frame bytes to the link task
//! ```
//! The loop is clocked by the samples, so the DDS advances exactly once per sample and the
//! estimator sees each sample with the drive phase of the same tick.

use kapitza_core::link::message::ResetInfo;
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::bridge::Lines;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::fixed::{Angle, Duty};
use kapitza_core::rig::retained::Retained;
use kapitza_core::rig::safety::Mode;
use kapitza_core::station::RigLoop;

use crate::board::{Drive, CRANK_COUNTS};
use crate::channels::{
    CONFIG_SAVED, FROM_LAPTOP, HEARTBEAT, LINE_ERROR, SAMPLES, SAMPLE_HZ, SAVE_CONFIG, SERVO_US,
    TO_LAPTOP,
};
use crate::retained;

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

/// The crank motor's hardware as the rig loop reads it: raw, calibrated in the loop.
struct Hw<'a> {
    drive: &'a mut Drive,
}

impl kapitza_core::station::drive::Drive for Hw<'_> {
    fn crank_raw(&mut self) -> Angle {
        // count · 2^32 / CRANK_COUNTS, exact (CRANK_COUNTS is a power of two).
        Angle::from_turns_u32(self.drive.crank_count() * (u32::MAX / CRANK_COUNTS + 1))
    }
    fn current_counts(&mut self) -> u16 {
        self.drive.current_counts()
    }
    fn set_duty(&mut self, duty: Duty) {
        self.drive.set_duty(duty.to_bits());
    }
    fn bridge_lines(&mut self) -> Lines {
        Lines {
            nfault_low: self.drive.nfault_low(),
            break_flag: self.drive.break_flag(),
        }
    }
    fn rearm(&mut self) {
        self.drive.rearm();
    }
}

/// `theta_d0`: where the servo starts (`kapitza_core::rig::servo::power_up_deg`); `kept`: what
/// the firmware left before the last reset; `reset`: its cause and last fault, for the status.
#[embassy_executor::task]
pub async fn run(
    mut drive: Drive,
    cfg: RigConfig,
    origin: ConfigOrigin,
    theta_d0: f64,
    kept: Option<Retained>,
    reset: ResetInfo,
) {
    let t0 = embassy_time::Instant::now().as_micros() as u32;
    let mut rig =
        RigLoop::new(cfg, origin, Angle::from_deg(theta_d0), t0, FIRMWARE).after_reset(reset);
    let mut keep = Retained {
        theta_d_deg: theta_d0 as f32,
        last_fault: kept.and_then(|k| k.last_fault),
    };
    retained::store(&keep);
    let mut inbox = [0u8; 64];
    let mut outbox = [0u8; 128];
    drive.enable(false);
    loop {
        let s = SAMPLES.receive().await;
        if !rig.sample(s) {
            continue;
        }
        let t = s.t_us;
        while let Ok(n) = FROM_LAPTOP.try_read(&mut inbox) {
            rig.receive(&inbox[..n], t);
        }
        if LINE_ERROR.try_take().is_some() {
            rig.line_error();
        }
        if let Some((tag, ok)) = CONFIG_SAVED.try_take() {
            rig.config_saved(tag, ok);
        }
        let estop = drive.estop_active();
        let tick = rig.control(t, &mut Hw { drive: &mut drive }, Some(estop));
        drive.enable(tick.bridge);
        let before = keep;
        if let Some(deg) = tick.servo_deg {
            keep.theta_d_deg = deg as f32;
        }
        if let Some(us) = tick.servo_us {
            SERVO_US.signal(us);
        }
        if let Mode::Faulted(f) = tick.report.mode {
            keep.last_fault = Some(f);
        }
        if keep != before {
            retained::store(&keep);
        }
        if let Some(new) = tick.store {
            SAMPLE_HZ.sender().send(new.cfg.sample_hz);
            SAVE_CONFIG.signal(new);
        }
        HEARTBEAT.signal(());
        // As many frame bytes as the link's pipe takes now; the rest wait in the loop.
        let room = TO_LAPTOP.free_capacity().min(outbox.len());
        let n = rig.transmit(&mut outbox[..room]);
        if n > 0 {
            // The room was measured above and only this task writes: it all fits.
            let _ = TO_LAPTOP.try_write(&outbox[..n]);
        }
    }
}
