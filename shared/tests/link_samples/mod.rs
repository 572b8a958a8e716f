//! One named sample of every message kind (and of every refusal reason), shared by the link's
//! round-trip, size and golden-frame tests.

use kapitza_core::link::message::{
    BridgeLine, Check, Counters, Fault, Mode, RMethod, RawTelemetry, ResetCause, ResetInfo,
    SensorDiagnostics, StopReason, Telemetry, Verdict, VersionInfo, WireConfig, WireGeometry,
};
use kapitza_core::link::origin::FieldSet;
use kapitza_core::link::reason::ConfigField;
use kapitza_core::link::{Reason, Request, Response, Status};
use kapitza_core::persist::{ConfigOrigin, Fallback};
use kapitza_core::rig::config::RigConfig;

/// A message of either direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Msg {
    Req(Request),
    Resp(Response),
}

pub fn reference_config() -> WireConfig {
    RigConfig::REFERENCE.into()
}

pub fn status() -> Status {
    Status {
        mode: Mode::Stopping(StopReason::LinkSilent),
        last_stop: Some(StopReason::Fault(Fault::Stall)),
        estop: false,
        omega: 313 << 16,
        omega_target: 0,
        theta_d_deg: 180 << 16,
        theta_d_target_deg: 190 << 16,
        config: ConfigOrigin::Defaults(Fallback::Corrupt),
        uptime_ms: 123_456,
        counters: Counters {
            frames_ok: 1000,
            frames_bad: 3,
            sensor_errors: 0,
            overruns: 1,
            frames_dropped: 2,
            commands: 77,
        },
        reset: ResetInfo {
            cause: ResetCause::Watchdog,
            last_fault: Some(Fault::PhaseLockLost),
            fault_pc: None,
        },
        check: Some(Check::Passed),
        bring_up: None,
    }
}

pub fn telemetry() -> Telemetry {
    Telemetry {
        t_us: 4_000_000_000,
        mode: Mode::Running,
        theta: i32::MIN,
        phi: -1_073_741_824,
        phi_rate: -3277,
        omega_p: Some(5 << 16),
        sigma: Some(-655),
        settled: true,
        equilibrium: Some(i32::MIN + 12_345),
        r: Some((3 << 16, RMethod::SlowFrequency)),
        periods: 1500,
        omega: 20_526_000,
        crank_speed: 20_525_000,
        phase_error: -1234,
        duty: 20_000,
        current: 98_304,
        theta_d_deg: 180 << 16,
        steady: true,
        commands: 4_000_000_000,
        wobble: 4_588,
    }
}

pub fn raw() -> RawTelemetry {
    RawTelemetry {
        t_us: 123_456_789,
        pendulum: Some(16_000),
        crank: 3_000_000_000,
        current: 2_048,
        duty: -3_277,
        diagnostics: Some(SensorDiagnostics {
            agc: 97,
            magnet_low: false,
            magnet_high: false,
            cordic_overflow: false,
            ready: true,
        }),
        sensor_errors: 12,
        theta_d_deg: 90 << 16,
        commands: 5,
    }
}

/// A configuration with every calibration field away from its default.
pub fn calibrated_config() -> WireConfig {
    let mut c = reference_config();
    c.duty_max = 0.8;
    c.calibration.pendulum_zero = 8_191;
    c.calibration.pendulum_sign = -1;
    c.calibration.crank_sign = -1;
    c.calibration.servo_min_us = 600;
    c.calibration.servo_max_us = 2_400;
    c.calibration.servo_range_deg = 180.0;
    c.calibration.servo_centre_deg = 85.5;
    c.calibration.current_offset = 12.5;
    c.calibration.current_scale = 1.2e-3;
    c.calibration.hysteresis = 0.01;
    c.calibration.min_swing = 0.02;
    c.calibration.settle_band = 0.004;
    c.calibration.block_s = 2.0;
    c.calibration.quiet_blocks = 3;
    c.closed_loop.enabled = true;
    c.closed_loop.band = 0.02;
    c.closed_loop.rate_max = 0.5;
    c
}

/// Every message kind, every refusal reason, every config origin: (file name, seq, message).
pub fn all() -> Vec<(&'static str, u8, Msg)> {
    use Msg::{Req, Resp};
    let mut point = reference_config();
    point.geometry = WireGeometry::PointMass { length: 0.3 };
    let mut general = reference_config();
    general.geometry = WireGeometry::General {
        inertia: 0.01,
        mass: 0.2,
        com: 0.15,
    };
    let mut v = vec![
        ("req_get_version", 0, Req(Request::GetVersion)),
        ("req_get_status", 1, Req(Request::GetStatus)),
        (
            "req_set_drive",
            2,
            Req(Request::SetDrive {
                r: 3 << 16,
                theta_d_deg: 180 << 16,
            }),
        ),
        (
            "req_set_drive_negative_angle",
            3,
            Req(Request::SetDrive {
                r: 0x1_8000,
                theta_d_deg: -(5 << 16),
            }),
        ),
        ("req_stop", 4, Req(Request::Stop)),
        ("req_clear_fault", 5, Req(Request::ClearFault)),
        (
            "req_set_config",
            6,
            Req(Request::SetConfig(reference_config())),
        ),
        (
            "req_set_config_point_mass",
            7,
            Req(Request::SetConfig(point)),
        ),
        (
            "req_set_config_general",
            8,
            Req(Request::SetConfig(general)),
        ),
        (
            "req_set_config_calibrated",
            12,
            Req(Request::SetConfig(calibrated_config())),
        ),
        ("req_get_config", 9, Req(Request::GetConfig)),
        (
            "req_bring_up",
            13,
            Req(Request::BringUp {
                duty: 3_277,
                theta_d_deg: 90 << 16,
            }),
        ),
        (
            "req_bring_up_reverse",
            14,
            Req(Request::BringUp {
                duty: -8_192,
                theta_d_deg: -(10 << 16),
            }),
        ),
        (
            "req_telemetry",
            10,
            Req(Request::Telemetry { period_ms: 20 }),
        ),
        (
            "req_telemetry_off",
            11,
            Req(Request::Telemetry { period_ms: 0 }),
        ),
        (
            "resp_version",
            0,
            Resp(Response::Version(VersionInfo {
                protocol: kapitza_core::link::PROTOCOL_VERSION,
                firmware: [0, 1, 0],
            })),
        ),
        ("resp_ok", 2, Resp(Response::Ok)),
        ("resp_status", 1, Resp(Response::Status(status()))),
        ("resp_config", 9, Resp(Response::Config(reference_config()))),
        (
            "resp_telemetry",
            200,
            Resp(Response::Telemetry(telemetry())),
        ),
        (
            "resp_telemetry_empty",
            201,
            Resp(Response::Telemetry(Telemetry::default())),
        ),
        ("resp_raw", 202, Resp(Response::Raw(raw()))),
        (
            "resp_raw_empty",
            203,
            Resp(Response::Raw(RawTelemetry::default())),
        ),
    ];
    for (i, (name, r)) in reasons().into_iter().enumerate() {
        v.push((name, 100 + i as u8, Resp(Response::Refused(r))));
    }
    for (i, (name, o)) in origins().into_iter().enumerate() {
        let mut s = status();
        s.config = o;
        v.push((name, 150 + i as u8, Resp(Response::Status(s))));
    }
    // The faults a bench latches, each as a status.
    for (i, (name, f)) in [
        ("status_faulted_sensor", Fault::Sensor),
        ("status_faulted_wrong_direction", Fault::WrongDirection),
        ("status_faulted_phase_lock_lost", Fault::PhaseLockLost),
        ("status_faulted_over_current_rms", Fault::OverCurrentRms),
        ("status_faulted_duty_ceiling", Fault::DutyCeiling),
        (
            "status_faulted_bridge_nfault",
            Fault::Bridge(BridgeLine::NFault),
        ),
        (
            "status_faulted_bridge_break",
            Fault::Bridge(BridgeLine::Break),
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let mut s = status();
        s.mode = Mode::Faulted(f);
        v.push((name, 170 + i as u8, Resp(Response::Status(s))));
    }
    // The pre-run check: running, and every verdict; bring-up mode.
    for (i, (name, c)) in [
        ("status_check_running", Check::Running),
        ("status_check_passed", Check::Passed),
        (
            "status_check_sensor_silent",
            Check::Failed(Verdict::SensorSilent),
        ),
        (
            "status_check_sensor_not_ready",
            Check::Failed(Verdict::SensorNotReady),
        ),
        (
            "status_check_current_offset",
            Check::Failed(Verdict::CurrentOffset { amps: 32_768 }),
        ),
        (
            "status_check_crank_reversed",
            Check::Failed(Verdict::CrankReversed { speed: -(45 << 16) }),
        ),
        (
            "status_check_crank_stalled",
            Check::Failed(Verdict::CrankStalled { speed: 0 }),
        ),
        (
            "status_check_crank_too_fast",
            Check::Failed(Verdict::CrankTooFast { speed: 400 << 16 }),
        ),
        ("status_check_aborted", Check::Failed(Verdict::Aborted)),
    ]
    .into_iter()
    .enumerate()
    {
        let mut s = status();
        s.mode = if c == Check::Running {
            Mode::Checking
        } else {
            Mode::Idle
        };
        s.check = Some(c);
        v.push((name, 180 + i as u8, Resp(Response::Status(s))));
    }
    let mut s = status();
    s.mode = Mode::Idle;
    s.check = None;
    s.bring_up = Some(3_277);
    v.push(("status_bring_up", 190, Resp(Response::Status(s))));
    // The resets a fault handler leaves: with a PC, and without one.
    for (i, (name, cause, pc)) in [
        ("status_after_panic", ResetCause::Panic, None),
        (
            "status_after_hard_fault",
            ResetCause::HardFault,
            Some(0x0800_1234),
        ),
        (
            "status_after_stack_overflow",
            ResetCause::StackOverflow,
            None,
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let mut s = status();
        s.reset = ResetInfo {
            cause,
            last_fault: None,
            fault_pc: pc,
        };
        v.push((name, 191 + i as u8, Resp(Response::Status(s))));
    }
    v
}

pub fn reasons() -> Vec<(&'static str, Reason)> {
    vec![
        ("refused_bad_crc", Reason::BadCrc),
        ("refused_truncated", Reason::Truncated),
        ("refused_malformed", Reason::Malformed),
        ("refused_unknown_message", Reason::UnknownMessage),
        (
            "refused_version_mismatch",
            Reason::VersionMismatch { rig: 1, frame: 2 },
        ),
        ("refused_too_long", Reason::TooLong),
        ("refused_r_invalid", Reason::RInvalid { requested: -65536 }),
        ("refused_omega_invalid", Reason::OmegaInvalid),
        (
            "refused_omega_above_limit",
            Reason::OmegaAboveLimit {
                requested: 500 << 16,
                limit: 420 << 16,
            },
        ),
        (
            "refused_drive_angle_out_of_range",
            Reason::DriveAngleOutOfRange {
                requested: 200 << 16,
                min: -(10 << 16),
                max: 190 << 16,
            },
        ),
        ("refused_faulted", Reason::Faulted(Fault::OverCurrent)),
        (
            "refused_wrong_mode",
            Reason::WrongMode(Mode::Faulted(Fault::EStop)),
        ),
        ("refused_estop_still_active", Reason::EStopStillActive),
        (
            "refused_config_invalid",
            Reason::ConfigInvalid {
                field: ConfigField::SampleHz,
            },
        ),
        ("refused_check_running", Reason::CheckRunning),
        (
            "refused_duty_above_cap",
            Reason::DutyAboveCap {
                requested: 16_384,
                cap: 8_192,
            },
        ),
        ("refused_bridge_fault_active", Reason::BridgeFaultActive),
    ]
}

pub fn origins() -> Vec<(&'static str, ConfigOrigin)> {
    vec![
        ("status_config_stored", ConfigOrigin::Stored),
        (
            "status_config_missing",
            ConfigOrigin::Defaults(Fallback::Missing),
        ),
        (
            "status_config_incompatible",
            ConfigOrigin::Defaults(Fallback::Incompatible { version: 7 }),
        ),
        (
            "status_config_invalid",
            ConfigOrigin::Defaults(Fallback::Invalid {
                field: ConfigField::OmegaMax,
            }),
        ),
        (
            "status_config_invalid_crank_sign",
            ConfigOrigin::Defaults(Fallback::Invalid {
                field: ConfigField::CrankSign,
            }),
        ),
        (
            "status_config_repaired",
            ConfigOrigin::Repaired {
                defaulted: {
                    let mut d = FieldSet::EMPTY;
                    d.insert(ConfigField::LinkTimeoutMs);
                    d.insert(ConfigField::OvercurrentMs);
                    d
                },
            },
        ),
        (
            "status_config_invalid_control_hz",
            ConfigOrigin::Defaults(Fallback::Invalid {
                field: ConfigField::ControlHz,
            }),
        ),
        (
            "status_config_received",
            ConfigOrigin::Received { saved: true },
        ),
        (
            "status_config_unsaved",
            ConfigOrigin::Received { saved: false },
        ),
    ]
}
