//! Property tests of the link: no byte sequence panics the decoders (frames, responses, the
//! stored configuration record); every valid message round-trips; damage never yields a
//! different valid message; valid frames survive garbage around them.

use kapitza_core::link::frame::{encode, open, receive_request, receive_response, Header};
use kapitza_core::link::message::{
    BridgeLine, Check, Counters, Fault, Mode, RMethod, RawTelemetry, ResetCause, ResetInfo,
    SensorDiagnostics, StopReason, Telemetry, Verdict, WireCalibration, WireClosedLoop, WireConfig,
    WireGeometry,
};
use kapitza_core::link::origin::FieldSet;
use kapitza_core::link::reason::ConfigField;
use kapitza_core::link::{
    FrameReader, Reason, Request, Response, Status, VersionInfo, MAX_REQUEST_FRAME,
};
use kapitza_core::persist::{self, ConfigOrigin, Fallback};
use proptest::prelude::*;

fn fault() -> impl Strategy<Value = Fault> {
    prop_oneof![
        Just(Fault::EStop),
        Just(Fault::OverCurrent),
        Just(Fault::Stall),
        Just(Fault::Sensor),
        Just(Fault::WrongDirection),
        Just(Fault::PhaseLockLost),
        Just(Fault::OverCurrentRms),
        Just(Fault::DutyCeiling),
        Just(Fault::Bridge(BridgeLine::NFault)),
        Just(Fault::Bridge(BridgeLine::Break))
    ]
}

fn stop_reason() -> impl Strategy<Value = StopReason> {
    prop_oneof![
        Just(StopReason::Requested),
        Just(StopReason::LinkSilent),
        fault().prop_map(StopReason::Fault),
    ]
}

fn mode() -> impl Strategy<Value = Mode> {
    prop_oneof![
        Just(Mode::Idle),
        Just(Mode::Running),
        stop_reason().prop_map(Mode::Stopping),
        fault().prop_map(Mode::Faulted),
        Just(Mode::Checking),
    ]
}

fn field() -> impl Strategy<Value = ConfigField> {
    prop_oneof![
        Just(ConfigField::Amplitude),
        Just(ConfigField::SampleHz),
        Just(ConfigField::CrankSign),
        Just(ConfigField::ClosedLoopRateMax),
        Just(ConfigField::ConnectingRod),
        Just(ConfigField::LinkTimeoutMs),
        Just(ConfigField::DriveAngleMax),
        Just(ConfigField::Other),
    ]
}

fn geometry() -> impl Strategy<Value = WireGeometry> {
    prop_oneof![
        any::<f64>().prop_map(|length| WireGeometry::Rod { length }),
        any::<f64>().prop_map(|length| WireGeometry::PointMass { length }),
        (any::<f64>(), any::<f64>(), any::<f64>())
            .prop_map(|(inertia, mass, com)| WireGeometry::General { inertia, mass, com }),
    ]
}

fn calibration() -> impl Strategy<Value = WireCalibration> {
    (
        (
            any::<u16>(),
            any::<i8>(),
            any::<i8>(),
            any::<u32>(),
            any::<u32>(),
        ),
        (any::<f64>(), any::<f64>(), any::<f64>(), any::<f64>()),
        (
            any::<f64>(),
            any::<f64>(),
            any::<f64>(),
            any::<f64>(),
            any::<u32>(),
        ),
    )
        .prop_map(|(a, b, c)| WireCalibration {
            pendulum_zero: a.0,
            pendulum_sign: a.1,
            crank_sign: a.2,
            servo_min_us: a.3,
            servo_max_us: a.4,
            servo_range_deg: b.0,
            servo_centre_deg: b.1,
            current_offset: b.2,
            current_scale: b.3,
            hysteresis: c.0,
            min_swing: c.1,
            settle_band: c.2,
            block_s: c.3,
            quiet_blocks: c.4,
        })
}

fn config() -> impl Strategy<Value = WireConfig> {
    (
        base_config(),
        any::<f64>(),
        calibration(),
        (any::<bool>(), any::<f64>(), any::<f64>()),
    )
        .prop_map(|(mut c, duty_max, calibration, l)| {
            c.duty_max = duty_max;
            c.calibration = calibration;
            c.closed_loop = WireClosedLoop {
                enabled: l.0,
                band: l.1,
                rate_max: l.2,
            };
            c
        })
}

fn base_config() -> impl Strategy<Value = WireConfig> {
    (
        (
            any::<f64>(),
            geometry(),
            any::<f64>(),
            any::<f64>(),
            any::<f64>(),
        ),
        (
            any::<f64>(),
            any::<f64>(),
            any::<f64>(),
            any::<f64>(),
            any::<u32>(),
        ),
        (
            any::<f64>(),
            any::<f64>(),
            any::<u32>(),
            any::<u32>(),
            any::<f64>(),
        ),
        (any::<f64>(), any::<f64>(), any::<f64>(), any::<f64>()),
        (any::<u32>(), any::<u32>()),
    )
        .prop_map(|(a, b, c, d, e)| WireConfig {
            amplitude: a.0,
            geometry: a.1,
            gravity: a.2,
            omega_max: a.3,
            omega_rate_max: a.4,
            drive_angle_min_deg: b.0,
            drive_angle_max_deg: b.1,
            drive_angle_rate_max_deg: b.2,
            current_max: b.3,
            overcurrent_ms: b.4,
            stall_min_omega: c.0,
            stall_fraction: c.1,
            stall_ms: c.2,
            link_timeout_ms: c.3,
            omega_per_duty: c.4,
            lag: d.0,
            kp: d.1,
            ki: d.2,
            max_correction: d.3,
            sample_hz: e.0,
            control_hz: e.1,
            ..kapitza_core::rig::config::RigConfig::REFERENCE.into()
        })
}

fn request() -> impl Strategy<Value = Request> {
    prop_oneof![
        Just(Request::GetVersion),
        Just(Request::GetStatus),
        (any::<i32>(), any::<i32>())
            .prop_map(|(r, theta_d_deg)| Request::SetDrive { r, theta_d_deg }),
        Just(Request::Stop),
        Just(Request::ClearFault),
        config().prop_map(Request::SetConfig),
        Just(Request::GetConfig),
        any::<u16>().prop_map(|period_ms| Request::Telemetry { period_ms }),
        (any::<i16>(), any::<i32>())
            .prop_map(|(duty, theta_d_deg)| Request::BringUp { duty, theta_d_deg }),
    ]
}

fn reason() -> impl Strategy<Value = Reason> {
    prop_oneof![
        Just(Reason::BadCrc),
        Just(Reason::Truncated),
        (any::<u8>(), any::<u8>()).prop_map(|(rig, frame)| Reason::VersionMismatch { rig, frame }),
        any::<i32>().prop_map(|requested| Reason::RInvalid { requested }),
        (any::<i32>(), any::<i32>())
            .prop_map(|(requested, limit)| Reason::OmegaAboveLimit { requested, limit }),
        (any::<i32>(), any::<i32>(), any::<i32>()).prop_map(|(requested, min, max)| {
            Reason::DriveAngleOutOfRange {
                requested,
                min,
                max,
            }
        }),
        fault().prop_map(Reason::Faulted),
        mode().prop_map(Reason::WrongMode),
        field().prop_map(|field| Reason::ConfigInvalid { field }),
        Just(Reason::CheckRunning),
        (any::<i16>(), any::<i16>())
            .prop_map(|(requested, cap)| Reason::DutyAboveCap { requested, cap }),
        Just(Reason::BridgeFaultActive),
    ]
}

fn check() -> impl Strategy<Value = Check> {
    prop_oneof![
        Just(Check::Running),
        Just(Check::Passed),
        Just(Check::Failed(Verdict::SensorSilent)),
        Just(Check::Failed(Verdict::SensorNotReady)),
        any::<i32>().prop_map(|amps| Check::Failed(Verdict::CurrentOffset { amps })),
        any::<i32>().prop_map(|speed| Check::Failed(Verdict::CrankReversed { speed })),
        any::<i32>().prop_map(|speed| Check::Failed(Verdict::CrankStalled { speed })),
        any::<i32>().prop_map(|speed| Check::Failed(Verdict::CrankTooFast { speed })),
        Just(Check::Failed(Verdict::Aborted)),
    ]
}

fn origin() -> impl Strategy<Value = ConfigOrigin> {
    prop_oneof![
        Just(ConfigOrigin::Stored),
        any::<u64>().prop_map(|bits| ConfigOrigin::Repaired {
            defaulted: FieldSet(bits)
        }),
        Just(ConfigOrigin::Defaults(Fallback::Missing)),
        Just(ConfigOrigin::Defaults(Fallback::Corrupt)),
        any::<u16>().prop_map(|version| ConfigOrigin::Defaults(Fallback::Incompatible { version })),
        field().prop_map(|field| ConfigOrigin::Defaults(Fallback::Invalid { field })),
        any::<bool>().prop_map(|saved| ConfigOrigin::Received { saved }),
    ]
}

fn status() -> impl Strategy<Value = Status> {
    (
        (mode(), proptest::option::of(stop_reason()), any::<bool>()),
        (any::<i32>(), any::<i32>(), any::<i32>(), any::<i32>()),
        (origin(), any::<u32>(), any::<[u32; 6]>()),
        (
            reset_cause(),
            proptest::option::of(fault()),
            proptest::option::of(check()),
            proptest::option::of(any::<i16>()),
            proptest::option::of(any::<u32>()),
        ),
    )
        .prop_map(|(a, b, c, r)| Status {
            mode: a.0,
            last_stop: a.1,
            estop: a.2,
            omega: b.0,
            omega_target: b.1,
            theta_d_deg: b.2,
            theta_d_target_deg: b.3,
            config: c.0,
            uptime_ms: c.1,
            counters: Counters {
                frames_ok: c.2[0],
                frames_bad: c.2[1],
                sensor_errors: c.2[2],
                overruns: c.2[3],
                frames_dropped: c.2[4],
                commands: c.2[5],
            },
            reset: ResetInfo {
                cause: r.0,
                last_fault: r.1,
                fault_pc: r.4,
            },
            check: r.2,
            bring_up: r.3,
        })
}

fn reset_cause() -> impl Strategy<Value = ResetCause> {
    prop_oneof![
        Just(ResetCause::PowerOn),
        Just(ResetCause::Pin),
        Just(ResetCause::Watchdog),
        Just(ResetCause::Software),
        Just(ResetCause::Other),
        Just(ResetCause::Panic),
        Just(ResetCause::HardFault),
        Just(ResetCause::StackOverflow)
    ]
}

fn telemetry() -> impl Strategy<Value = Telemetry> {
    let rm = prop_oneof![
        Just(RMethod::EquilibriumAngle),
        Just(RMethod::SlowFrequency)
    ];
    (
        (
            any::<u32>(),
            mode(),
            any::<i32>(),
            any::<i32>(),
            any::<i32>(),
        ),
        (
            proptest::option::of(any::<i32>()),
            proptest::option::of(any::<i32>()),
            any::<bool>(),
            proptest::option::of(any::<i32>()),
            proptest::option::of((any::<i32>(), rm)),
        ),
        (
            any::<u32>(),
            any::<i32>(),
            any::<i32>(),
            any::<i32>(),
            any::<i16>(),
        ),
        (
            any::<i32>(),
            any::<i32>(),
            any::<bool>(),
            any::<u32>(),
            any::<i32>(),
        ),
    )
        .prop_map(|(a, b, c, d)| Telemetry {
            t_us: a.0,
            mode: a.1,
            theta: a.2,
            phi: a.3,
            phi_rate: a.4,
            omega_p: b.0,
            sigma: b.1,
            settled: b.2,
            equilibrium: b.3,
            r: b.4,
            periods: c.0,
            omega: c.1,
            crank_speed: c.2,
            phase_error: c.3,
            duty: c.4,
            current: d.0,
            theta_d_deg: d.1,
            steady: d.2,
            commands: d.3,
            wobble: d.4,
        })
}

fn raw() -> impl Strategy<Value = RawTelemetry> {
    (
        (
            any::<u32>(),
            proptest::option::of(any::<u16>()),
            any::<u32>(),
            any::<u16>(),
            any::<i16>(),
        ),
        proptest::option::of((any::<u8>(), any::<[bool; 4]>())),
        (any::<u32>(), any::<i32>(), any::<u32>()),
    )
        .prop_map(|(a, d, c)| RawTelemetry {
            t_us: a.0,
            pendulum: a.1,
            crank: a.2,
            current: a.3,
            duty: a.4,
            diagnostics: d.map(|(agc, b)| SensorDiagnostics {
                agc,
                magnet_low: b[0],
                magnet_high: b[1],
                cordic_overflow: b[2],
                ready: b[3],
            }),
            sensor_errors: c.0,
            theta_d_deg: c.1,
            commands: c.2,
        })
}

fn response() -> impl Strategy<Value = Response> {
    prop_oneof![
        (any::<u8>(), any::<[u16; 3]>())
            .prop_map(|(protocol, firmware)| Response::Version(VersionInfo { protocol, firmware })),
        Just(Response::Ok),
        reason().prop_map(Response::Refused),
        status().prop_map(Response::Status),
        config().prop_map(Response::Config),
        telemetry().prop_map(Response::Telemetry),
        raw().prop_map(Response::Raw),
    ]
}

fn frame<M: serde::Serialize + postcard::experimental::max_size::MaxSize>(
    seq: u8,
    m: &M,
) -> Vec<u8> {
    let mut out = [0u8; 512];
    let n = encode(Header::new(seq), m, &mut out).unwrap();
    out[..n].to_vec()
}

/// Postcard bytes: the comparison for messages with f64 fields (NaN ≠ NaN).
fn bytes<M: serde::Serialize>(m: &M) -> Vec<u8> {
    postcard::to_slice(m, &mut [0u8; 512]).unwrap().to_vec()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// No byte sequence panics the frame reader or either decoder.
    #[test]
    fn no_bytes_panic_the_decoders(data in proptest::collection::vec(any::<u8>(), 0..700)) {
        let mut reader = FrameReader::<{ MAX_REQUEST_FRAME }>::new();
        for &b in &data {
            if let Some(Ok(f)) = reader.push(b) {
                let mut copy = f.to_vec();
                let _ = receive_request(f);
                let _ = receive_response(&mut copy);
            }
        }
        let mut whole = data.clone();
        let _ = receive_request(&mut whole);
        let mut whole = data.clone();
        let _ = receive_response(&mut whole);
        let _ = persist::decode(&data);
        let _ = persist::load(&data);
    }

    /// Nearly valid frames (a valid frame with a few bytes replaced) are the hard inputs for a
    /// decoder; they never panic, and never decode to a different message.
    #[test]
    fn damage_never_yields_another_message(
        req in request(),
        seq in any::<u8>(),
        hits in proptest::collection::vec((any::<prop::sample::Index>(), 1u8..=255), 1..5),
    ) {
        let f = frame(seq, &req);
        let mut body = f[..f.len() - 1].to_vec();
        for (i, x) in hits {
            let i = i.index(body.len());
            body[i] ^= x;
        }
        // A replaced byte may be a zero: the reader would split there; decode each piece.
        for piece in body.split_mut(|&b| b == 0) {
            if let (_, Ok(got)) = receive_request(piece) {
                prop_assert_eq!(bytes(&got), bytes(&req));
            }
        }
    }

    #[test]
    fn requests_round_trip(req in request(), seq in any::<u8>()) {
        let f = frame(seq, &req);
        prop_assert!(f.len() <= MAX_REQUEST_FRAME);
        let mut b = f[..f.len() - 1].to_vec();
        let (s, got) = receive_request(&mut b);
        prop_assert_eq!(s, seq);
        prop_assert_eq!(bytes(&got.unwrap()), bytes(&req));
    }

    #[test]
    fn responses_round_trip(resp in response(), seq in any::<u8>()) {
        let f = frame(seq, &resp);
        prop_assert!(f.len() <= kapitza_core::link::MAX_RESPONSE_FRAME);
        let mut b = f[..f.len() - 1].to_vec();
        let (h, got) = receive_response(&mut b).unwrap();
        prop_assert_eq!(h.seq, seq);
        prop_assert_eq!(bytes(&got), bytes(&resp));
    }

    /// Valid frames among garbage: each frame that follows a zero is recovered intact.
    #[test]
    fn frames_survive_garbage_around_them(
        reqs in proptest::collection::vec((request(), proptest::collection::vec(any::<u8>(), 0..40)), 1..6),
    ) {
        let mut stream = Vec::new();
        for (i, (r, junk)) in reqs.iter().enumerate() {
            stream.extend(junk);
            stream.push(0);
            stream.extend(frame(i as u8, r));
        }
        let mut reader = FrameReader::<{ MAX_REQUEST_FRAME }>::new();
        let mut got = Vec::new();
        for b in stream {
            if let Some(Ok(f)) = reader.push(b) {
                if let (s, Ok(r)) = receive_request(f) {
                    got.push((s, bytes(&r)));
                }
            }
        }
        // Junk may itself happen to form a valid frame only with probability ~2^-32.
        let want: Vec<_> = reqs.iter().enumerate().map(|(i, (r, _))| (i as u8, bytes(r))).collect();
        prop_assert_eq!(got, want);
    }

    /// The stored record: any configuration round-trips; damage falls back, never panics.
    #[test]
    fn config_record_round_trips_or_falls_back(
        cfg in config(),
        hit in any::<prop::sample::Index>(),
        x in 1u8..=255,
    ) {
        let rig: kapitza_core::rig::config::RigConfig = cfg.into();
        let mut buf = [0u8; persist::RECORD_MAX];
        let n = persist::encode(&rig, 1, &mut buf);
        match (persist::decode(&buf), rig.validate()) {
            (Ok(c), Ok(_)) => prop_assert_eq!(bytes(&WireConfig::from(c)), bytes(&cfg)),
            (Err(Fallback::Invalid { .. }), Err(_)) => {}
            (got, v) => prop_assert!(false, "{:?} vs validate {:?}", got, v.map(|_| ())),
        }
        let i = hit.index(n);
        buf[i] ^= x;
        let (_, origin) = persist::load(&buf);
        // A damaged record is never taken as stored, unless the byte hit was padding.
        let used = 8 + usize::from(u16::from_le_bytes([buf[6], buf[7]])) + 4;
        if i < used {
            prop_assert!(
                !matches!(origin, ConfigOrigin::Stored | ConfigOrigin::Repaired { .. }),
                "{:?}",
                origin
            );
        }
    }
}

#[test]
fn open_rejects_embedded_zero() {
    let mut b = [1u8, 0, 3];
    assert_eq!(open(&mut b), Err(Reason::Malformed));
}
