//! One named sample of every message kind (and of every refusal reason), shared by the link's
//! round-trip, size and golden-frame tests.

use kapitza_core::link::message::{
    Counters, Fault, Mode, RMethod, ResetCause, ResetInfo, StopReason, Telemetry, VersionInfo,
    WireConfig, WireGeometry,
};
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
        },
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
    }
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
        ("req_get_config", 9, Req(Request::GetConfig)),
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
    ]
    .into_iter()
    .enumerate()
    {
        let mut s = status();
        s.mode = Mode::Faulted(f);
        v.push((name, 170 + i as u8, Resp(Response::Status(s))));
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
                field: ConfigField::Rates,
            },
        ),
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
            "status_config_received",
            ConfigOrigin::Received { saved: true },
        ),
        (
            "status_config_unsaved",
            ConfigOrigin::Received { saved: false },
        ),
    ]
}
