//! Every channel between the tasks, in one place. Each line names its producer → consumer.
//!
//! `Signal` holds the latest setting, `Channel` queues messages, `Watch` publishes a value to
//! readers who want the newest one. The control loop runs in an interrupt, the rest in thread
//! mode, so everything is guarded by a critical-section mutex.

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex as Cs;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use embassy_sync::watch::Watch;
use kapitza_core::link::serve::Effect;
use kapitza_core::link::{Request, Response, Telemetry};
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::fixed::Angle;

/// One pendulum-angle sample.
#[derive(Clone, Copy)]
pub struct Sample {
    /// When it was read (µs, wrapping).
    pub t_us: u32,
    /// The pendulum angle (the last good one if this read failed).
    pub angle: Angle,
    /// The read failed (bus error, parity, or the sensor's error flag).
    pub failed: bool,
    /// Taken more than one sample period late.
    pub late: bool,
}

/// pendulum → control: every sample, at the sample rate (a few in flight at most).
pub static SAMPLES: Channel<Cs, Sample, 8> = Channel::new();
/// control → pendulum: the sample rate (Hz) of the configuration in use.
pub static SAMPLE_HZ: Watch<Cs, u32, 1> = Watch::new();
/// link → control: each valid request, one at a time.
pub static TO_CONTROL: Channel<Cs, Request, 1> = Channel::new();
/// control → link: the answer to each `TO_CONTROL` request, and what the link must do with it.
pub static FROM_CONTROL: Channel<Cs, (Response, Effect), 1> = Channel::new();
/// control → link: the latest telemetry snapshot.
pub static TELEMETRY: Watch<Cs, Telemetry, 1> = Watch::new();
/// control → tilt: the slew-limited θd, degrees along the mount's travel.
pub static THETA_D: Signal<Cs, f64> = Signal::new();
/// safety → control: the e-stop input is active.
pub static ESTOP: Watch<Cs, bool, 1> = Watch::new();
/// control → safety: the control loop completed a tick (the watchdog is fed only then).
pub static HEARTBEAT: Signal<Cs, ()> = Signal::new();
/// control → persist: a configuration was accepted; store it.
pub static SAVE_CONFIG: Signal<Cs, RigConfig> = Signal::new();
/// persist → control: whether the last store reached flash.
pub static CONFIG_SAVED: Signal<Cs, bool> = Signal::new();
