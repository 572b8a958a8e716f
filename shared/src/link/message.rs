//! The messages: what the laptop asks ([`Request`]) and what the rig answers or streams
//! ([`Response`]), with every field's unit and number format.
//!
//! Field formats (raw integer bits on the wire, postcard varints for the integers):
//!
//! ```text
//! type alias   bits  format   unit        holds
//! Q16          i32   I16F16   (see field) R, ω, rates, current, θd in degrees
//! Turns        i32   Q0.32    turn        pendulum angles: one turn = 2^32, wrapping (rig::fixed::Angle)
//! Q15          i16   I1F15    1           H-bridge duty in [−1, 1)
//! f64          8 B   IEEE     SI          the rig configuration (as RigConfig holds it: lossless)
//! ```
//! θd is always degrees along the actuator mount's travel (I16F16, not wrapped: 190° stays 190°,
//! so a range check on it means what it says), matching the unit the safety supervisor's
//! limits are written in. Pendulum angles wrap: a rotating pendulum's angle stays exact.
//!
//! The variant order of [`Request`] and [`Response`] *is* the wire encoding (postcard writes the
//! variant index as a varint). [`Request::GetVersion`] and [`Response::Version`] are variant 0
//! and frozen forever; see the compatibility policy in the [module doc](super).

use postcard::experimental::max_size::MaxSize;
use serde::{Deserialize, Serialize};

use super::origin::ConfigOrigin;
use super::reason::Reason;

/// Raw bits of an I16F16 value (unit given where it is used).
pub type Q16 = i32;
/// Raw bits of a wrapping angle, 2^-32 turn ([`crate::rig::fixed::Angle`]).
pub type Turns = i32;
/// Raw bits of an I1F15 duty.
pub type Q15 = i16;

/// From the laptop to the rig.
// No heap on the rig: the configuration travels inline, and a request is built once.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// Frozen forever (variant 0, no payload): answered with [`Response::Version`] whatever
    /// protocol version the frame's header carries.
    GetVersion,
    /// Answered with [`Response::Status`]. Also the keep-alive: any valid request resets the
    /// link-silence timer, and a running rig soft-stops after `link_timeout_ms` without one.
    GetStatus,
    /// Drive strength R and drive angle θd. `r > 0`: start (from idle) or change ω = ωc √R
    /// (running); `r = 0`: soft stop. θd is slewed to at the rate limit. Both parts are checked
    /// before either is applied: a refusal changes nothing.
    SetDrive {
        /// R, I16F16 (dimensionless), ≥ 0.
        r: Q16,
        /// θd in degrees along the mount's travel, I16F16.
        theta_d_deg: Q16,
    },
    /// Soft stop (ramped at the rate limit). Accepted in every mode; does nothing unless running.
    Stop,
    /// Leave a latched fault once its cause is gone.
    ClearFault,
    /// Replace the rig configuration (only while idle); stored in flash when accepted.
    SetConfig(WireConfig),
    /// Answered with [`Response::Config`].
    GetConfig,
    /// Stream [`Response::Telemetry`] every `period_ms` (0 stops the stream; the rig may
    /// raise a period shorter than its line can carry).
    Telemetry { period_ms: u16 },
    /// Bring-up mode (from idle, or to change it): the crank motor at an open-loop `duty`
    /// no larger than the bring-up cap (`station::bring_up`), the servo jogged to θd (degrees
    /// along the travel, I16F16, slewed), and [`Response::Raw`] streamed instead of
    /// [`Response::Telemetry`]. [`Request::Stop`], link silence or a new configuration leaves
    /// it (duty 0), and so does a start (for its pre-run check); faults stop it as they stop
    /// the drive.
    BringUp { duty: Q15, theta_d_deg: Q16 },
}

impl Request {
    /// How many kinds of request this protocol version has (variant indices 0..KINDS).
    pub const KINDS: u32 = 9;
}

/// From the rig to the laptop.
// No heap on the rig: the configuration travels inline, as in `Request`.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Response {
    /// Frozen forever (variant 0): the answer to [`Request::GetVersion`].
    Version(VersionInfo),
    /// The request was carried out.
    Ok,
    /// The request was refused, or its frame was bad; nothing changed.
    Refused(Reason),
    Status(Status),
    Config(WireConfig),
    /// Unsolicited, at the period asked for by [`Request::Telemetry`].
    Telemetry(Telemetry),
    /// Unsolicited in bring-up mode, at the same period: the sensors as they read.
    Raw(RawTelemetry),
}

impl Response {
    /// How many kinds of response this protocol version has (variant indices 0..KINDS).
    pub const KINDS: u32 = 7;
}

/// Frozen forever: its encoding must never change (golden frame in `tests/link_golden.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VersionInfo {
    /// The link protocol version the rig speaks ([`super::PROTOCOL_VERSION`]).
    pub protocol: u8,
    /// The firmware's semantic version.
    pub firmware: [u16; 3],
}

/// The rig's state, answered to [`Request::GetStatus`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Status {
    pub mode: Mode,
    /// Why the drive last stopped, if it has.
    pub last_stop: Option<StopReason>,
    /// The e-stop input is active now.
    pub estop: bool,
    /// Drive reference ω now and the ω it ramps to (rad/s, I16F16).
    pub omega: Q16,
    pub omega_target: Q16,
    /// θd now (slewed) and its target, degrees along the mount's travel (I16F16).
    pub theta_d_deg: Q16,
    pub theta_d_target_deg: Q16,
    /// Where the configuration in use came from; says so when it fell back to defaults.
    pub config: ConfigOrigin,
    /// Milliseconds since power-up (wraps after 49.7 days).
    pub uptime_ms: u32,
    pub counters: Counters,
    /// Why the rig last reset, and the fault latched before it.
    pub reset: ResetInfo,
    /// The pre-run check of the last start: running, or its verdict (`None` before any).
    pub check: Option<Check>,
    /// In bring-up mode: its open-loop duty (I1F15).
    pub bring_up: Option<Q15>,
}

/// The pre-run check that every start from idle runs first (`station::precheck`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Check {
    /// Running: the drive starts when it passes.
    Running,
    /// Passed: the drive started.
    Passed,
    /// Failed: the drive did not start, for this reason.
    Failed(Verdict),
}

/// Why a pre-run check failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Verdict {
    /// The pendulum sensor gave no good angle through the check.
    SensorSilent,
    /// The sensor answers, but its diagnostics are missing, not ready, or the magnet is out
    /// of range: what a sensor that is not there, or a line stuck low, looks like.
    SensorNotReady,
    /// The current at rest (A, I16F16) is beyond the offset a healthy sense reads.
    CurrentOffset { amps: Q16 },
    /// The test pulse turned the crank backwards (crank speed, rad/s, I16F16): encoder
    /// channels or motor leads swapped.
    CrankReversed { speed: Q16 },
    /// The test pulse did not turn the crank (a stalled or unpowered motor).
    CrankStalled { speed: Q16 },
    /// The test pulse turned the crank far faster than the motor's gain says.
    CrankTooFast { speed: Q16 },
    /// Stopped before its verdict: a stop request, or a fault (the status says which).
    Aborted,
}

/// The sensors as they read, for bringing a bench up and for calibration: no estimator, no
/// calibration applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawTelemetry {
    /// The rig's clock (µs, wrapping) of the latest pendulum sample.
    pub t_us: u32,
    /// The pendulum sensor's count (0..2^14) at that sample; `None` if the read failed.
    pub pendulum: Option<u16>,
    /// The crank encoder as wired, before its calibrated sign (2^-32 turn, wrapping).
    pub crank: u32,
    /// The current sense's ADC reading (counts).
    pub current: u16,
    /// The duty commanded (I1F15).
    pub duty: Q15,
    /// The pendulum sensor's last diagnostics read, if any yet.
    pub diagnostics: Option<SensorDiagnostics>,
    /// Sensor reads that failed since power-up ([`Counters::sensor_errors`]).
    pub sensor_errors: u32,
    /// θd now, degrees along the mount's travel (I16F16).
    pub theta_d_deg: Q16,
    /// [`Counters::commands`] when the snapshot was taken.
    pub commands: u32,
}

/// The AS5047P's DIAAGC register ([`crate::rig::as5047::Diagnostics`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorDiagnostics {
    /// Automatic gain control: 0 strongest field, 255 weakest.
    pub agc: u8,
    pub magnet_low: bool,
    pub magnet_high: bool,
    pub cordic_overflow: bool,
    /// Offset compensation finished.
    pub ready: bool,
}

/// Why the rig last reset (the chip's reset flags), and the last fault latched before it (kept
/// in RAM across the reset: [`crate::rig::retained`]), so a watchdog reset mid-demo is seen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResetInfo {
    pub cause: ResetCause,
    pub last_fault: Option<Fault>,
    /// After [`ResetCause::HardFault`] or [`ResetCause::StackOverflow`]: the program counter
    /// the fault was taken at, when the exception frame was stacked intact.
    pub fault_pc: Option<u32>,
}

/// The cause of the last reset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResetCause {
    /// Power-on or brown-out: nothing survived.
    PowerOn,
    /// The reset pin (the board's button, or the probe).
    Pin,
    /// The independent watchdog: the control loop stopped ticking.
    Watchdog,
    /// A software reset.
    Software,
    /// Another cause (low-power, option-byte load, window watchdog).
    Other,
    /// The firmware panicked; its handler switched the outputs off and reset the chip.
    Panic,
    /// A HardFault (or an NMI other than the configuration read's ECC error); its handler
    /// switched the outputs off and reset the chip.
    HardFault,
    /// The stack ran into its guard region below it (the MPU's MemManage fault).
    StackOverflow,
}

impl ResetInfo {
    /// A cold start: nothing before it.
    pub const POWER_ON: Self = Self {
        cause: ResetCause::PowerOn,
        last_fault: None,
        fault_pc: None,
    };
}

/// Event counters since power-up (saturating).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// Frames received intact.
    pub frames_ok: u32,
    /// Frames dropped: bad CRC, truncated, malformed, too long.
    pub frames_bad: u32,
    /// Pendulum-sensor reads that failed (the last good angle was used).
    pub sensor_errors: u32,
    /// Pendulum samples taken more than half a period late.
    pub overruns: u32,
    /// Frames the rig had to drop because the line was not taking them (telemetry first; an
    /// answer only when the laptop sends faster than the line carries the answers back).
    pub frames_dropped: u32,
    /// Commands carried out (`SetDrive`, `Stop`, `ClearFault`, `SetConfig` answered `Ok`).
    /// Telemetry carries it too, so a host can tell a snapshot taken after its command from
    /// one taken before.
    pub commands: u32,
}

/// One snapshot of the control loop and the estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Telemetry {
    /// The rig's clock (µs, wrapping every 71.6 min) at the control tick it was taken.
    pub t_us: u32,
    pub mode: Mode,
    /// Latest pendulum angle sample θ, and the slow angle φ̄ of the latest drive period (turns).
    pub theta: Turns,
    pub phi: Turns,
    /// Slow angular velocity (rad/s, I16F16).
    pub phi_rate: Q16,
    /// Slow-oscillation frequency ωp and decay σ (1/s), I16F16, once measured.
    pub omega_p: Option<Q16>,
    pub sigma: Option<Q16>,
    pub settled: bool,
    /// The equilibrium angle φ0 once settled (turns).
    pub equilibrium: Option<Turns>,
    /// R in situ (I16F16) and the formula used, once settled.
    pub r: Option<(Q16, RMethod)>,
    /// Drive periods averaged since the estimator last restarted.
    pub periods: u32,
    /// Drive reference ω and measured crank speed (rad/s, I16F16).
    pub omega: Q16,
    pub crank_speed: Q16,
    /// Phase error φ_ref − φ_crank (rad, I16F16).
    pub phase_error: Q16,
    pub duty: Q15,
    /// Motor current (A, I16F16).
    pub current: Q16,
    /// θd now, degrees along the mount's travel (I16F16).
    pub theta_d_deg: Q16,
    /// The drive is at its set ω and θd at its target: the estimator is measuring.
    pub steady: bool,
    /// [`Counters::commands`] when the snapshot was taken.
    pub commands: u32,
    /// The fast wobble's amplitude at the drive frequency (rad, I16F16), from the estimator's
    /// I/Q demodulation over the latest drive period; 0 while the drive is not running.
    pub wobble: Q16,
}

/// The supervisor's mode ([`crate::rig::safety::Mode`]), and `Checking` while a start waits
/// for its pre-run check (the supervisor is idle then).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    #[default]
    Idle,
    Running,
    Stopping(StopReason),
    Faulted(Fault),
    Checking,
}

/// [`crate::rig::safety::StopReason`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StopReason {
    Requested,
    LinkSilent,
    Fault(Fault),
}

/// [`crate::rig::safety::Fault`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fault {
    EStop,
    OverCurrent,
    Stall,
    Sensor,
    WrongDirection,
    PhaseLockLost,
    OverCurrentRms,
    DutyCeiling,
    /// The H-bridge signalled a fault while awake, on this line.
    Bridge(BridgeLine),
}

/// [`crate::rig::bridge::Line`]: which line showed a bridge fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BridgeLine {
    /// nFAULT read low.
    NFault,
    /// TIM1's break flag was set, nFAULT high again.
    Break,
}

/// [`crate::model::RMethod`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RMethod {
    EquilibriumAngle,
    SlowFrequency,
}

/// [`crate::model::Geometry`], on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WireGeometry {
    Rod { length: f64 },
    PointMass { length: f64 },
    General { inertia: f64, mass: f64, com: f64 },
}

/// [`crate::rig::config::RigConfig`] on the wire and in flash: the same numbers, field for field
/// (SI units, f64, so it round-trips exactly). Converted by `From` both ways, with exhaustive
/// destructuring so that a field added to `RigConfig` fails to compile here until the wire
/// format (and [`super::PROTOCOL_VERSION`]) follows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WireConfig {
    pub amplitude: f64,
    pub connecting_rod: f64,
    pub geometry: WireGeometry,
    pub gravity: f64,
    pub omega_max: f64,
    pub omega_rate_max: f64,
    pub drive_angle_min_deg: f64,
    pub drive_angle_max_deg: f64,
    pub drive_angle_rate_max_deg: f64,
    pub current_max: f64,
    pub overcurrent_ms: u32,
    pub stall_min_omega: f64,
    pub stall_fraction: f64,
    pub stall_ms: u32,
    pub link_timeout_ms: u32,
    pub omega_per_duty: f64,
    pub lag: f64,
    pub kp: f64,
    pub ki: f64,
    pub max_correction: f64,
    pub sample_hz: u32,
    pub control_hz: u32,
    pub duty_max: f64,
    pub calibration: WireCalibration,
    pub closed_loop: WireClosedLoop,
}

/// [`crate::rig::calibration::Calibration`], field for field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WireCalibration {
    pub pendulum_zero: u16,
    pub pendulum_sign: i8,
    pub crank_sign: i8,
    pub servo_min_us: u32,
    pub servo_max_us: u32,
    pub servo_range_deg: f64,
    pub servo_centre_deg: f64,
    pub current_offset: f64,
    pub current_scale: f64,
    pub hysteresis: f64,
    pub min_swing: f64,
    pub settle_band: f64,
    pub block_s: f64,
    pub quiet_blocks: u32,
}

/// [`crate::rig::closed_loop::ClosedLoopR`], field for field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WireClosedLoop {
    pub enabled: bool,
    pub band: f64,
    pub rate_max: f64,
}
