//! Every channel between the tasks, in one place. Each line names its producer → consumer.
//!
//! `Signal` holds the latest setting, `Channel` queues messages, `Pipe` carries a byte stream,
//! `Watch` publishes a value to readers who want the newest one. The control loop runs in an interrupt, the rest in thread
//! mode, so everything is guarded by a critical-section mutex.

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex as Cs;
use embassy_sync::channel::Channel;
use embassy_sync::pipe::Pipe;
use embassy_sync::signal::Signal;
use embassy_sync::watch::Watch;
use kapitza_core::station::{Sample, StoreRequest};

/// pendulum → control: every sample, at the sample rate (a few in flight at most).
pub static SAMPLES: Channel<Cs, Sample, 8> = Channel::new();
/// control → pendulum: the sample rate (Hz) of the configuration in use.
pub static SAMPLE_HZ: Watch<Cs, u32, 1> = Watch::new();
/// link → control: bytes from the laptop, taken at every control tick (1 ms holds 12 bytes at
/// 115200 baud; the pipe holds 20 ms).
pub static FROM_LAPTOP: Pipe<Cs, 256> = Pipe::new();
/// link → control: the UART reported an error (overrun, framing, noise).
pub static LINE_ERROR: Signal<Cs, ()> = Signal::new();
/// control → link: frame bytes for the laptop (answers and telemetry).
pub static TO_LAPTOP: Pipe<Cs, 512> = Pipe::new();
/// control → tilt: the servo's pulse width (µs) for the slew-limited θd, through the
/// configuration's calibrated map (the first one is the power-up θd's: the tilt task sends no
/// pulse before it).
pub static SERVO_US: Signal<Cs, f64> = Signal::new();
/// control → safety: the control loop completed a tick (the watchdog is fed only then).
pub static HEARTBEAT: Signal<Cs, ()> = Signal::new();
/// control → persist: a configuration was accepted; store it (a newer one replaces one not
/// yet taken).
pub static SAVE_CONFIG: Signal<Cs, StoreRequest> = Signal::new();
/// persist → control: the tag of the store that finished, and whether it reached flash.
pub static CONFIG_SAVED: Signal<Cs, (u32, bool)> = Signal::new();
