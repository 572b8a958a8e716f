//! Every message kind through a whole frame and back, with its size against the bound the
//! buffers are sized by; the frame reader on a stream; the CRC's check value.

mod link_samples;

use kapitza_core::link::frame::{
    self, encode, max_frame_len, receive_request, receive_response, Header, CRC,
};
use kapitza_core::link::message::{Mode, RMethod, StopReason, Telemetry, WireGeometry};
use kapitza_core::link::{
    FrameReader, Reason, Request, Response, Status, MAX_REQUEST_FRAME, MAX_RESPONSE_FRAME,
};
use link_samples::Msg;
use postcard::experimental::max_size::MaxSize;

fn frame_of(seq: u8, m: &Msg) -> Vec<u8> {
    let mut out = [0u8; 512];
    let n = match m {
        Msg::Req(r) => encode(Header::new(seq), r, &mut out).unwrap(),
        Msg::Resp(r) => encode(Header::new(seq), r, &mut out).unwrap(),
    };
    out[..n].to_vec()
}

#[test]
fn every_message_round_trips_within_its_bound() {
    for (name, seq, m) in link_samples::all() {
        let f = frame_of(seq, &m);
        // One zero, at the end: the delimiter.
        assert_eq!(f.iter().position(|&b| b == 0), Some(f.len() - 1), "{name}");
        let mut stuffed = f[..f.len() - 1].to_vec();
        match m {
            Msg::Req(r) => {
                assert!(f.len() <= MAX_REQUEST_FRAME, "{name}: {}", f.len());
                let n = postcard::to_slice(&r, &mut [0u8; 512]).unwrap().len();
                assert!(n <= Request::POSTCARD_MAX_SIZE, "{name}");
                assert_eq!(receive_request(&mut stuffed), (seq, Ok(r)), "{name}");
            }
            Msg::Resp(r) => {
                assert!(f.len() <= MAX_RESPONSE_FRAME, "{name}: {}", f.len());
                let n = postcard::to_slice(&r, &mut [0u8; 512]).unwrap().len();
                assert!(n <= Response::POSTCARD_MAX_SIZE, "{name}");
                assert_eq!(
                    receive_response(&mut stuffed),
                    Ok((Header::new(seq), r)),
                    "{name}"
                );
            }
        }
    }
}

#[test]
fn every_kind_is_sampled() {
    // The first payload byte is the variant index; the samples must cover 0..KINDS.
    let mut req = vec![false; Request::KINDS as usize];
    let mut resp = vec![false; Response::KINDS as usize];
    for (_, _, m) in link_samples::all() {
        let mut buf = [0u8; 512];
        match m {
            Msg::Req(r) => req[postcard::to_slice(&r, &mut buf).unwrap()[0] as usize] = true,
            Msg::Resp(r) => resp[postcard::to_slice(&r, &mut buf).unwrap()[0] as usize] = true,
        }
    }
    assert!(req.iter().all(|&x| x), "{req:?}");
    assert!(resp.iter().all(|&x| x), "{resp:?}");
    // Reason codes are distinct, link ones below 16.
    let reasons = link_samples::reasons();
    let mut codes: Vec<u8> = reasons.iter().map(|(_, r)| r.code()).collect();
    codes.sort();
    codes.dedup();
    assert_eq!(codes.len(), reasons.len());
    assert!(Reason::BadCrc.is_link() && !Reason::OmegaInvalid.is_link());
}

/// The worst case of each message: every varint at its longest, every option present.
fn worst_cases() -> Vec<(&'static str, Msg, usize)> {
    let mut cfg = link_samples::reference_config();
    cfg.geometry = WireGeometry::General {
        inertia: 1.0,
        mass: 1.0,
        com: 1.0,
    };
    cfg.overcurrent_ms = u32::MAX;
    cfg.stall_ms = u32::MAX;
    cfg.link_timeout_ms = u32::MAX;
    cfg.sample_hz = u32::MAX;
    cfg.control_hz = u32::MAX;
    cfg.calibration.pendulum_zero = u16::MAX;
    cfg.calibration.servo_min_us = u32::MAX;
    cfg.calibration.servo_max_us = u32::MAX;
    cfg.calibration.quiet_blocks = u32::MAX;
    let raw = kapitza_core::link::message::RawTelemetry {
        t_us: u32::MAX,
        pendulum: Some(u16::MAX),
        crank: u32::MAX,
        current: u16::MAX,
        duty: i16::MIN,
        diagnostics: Some(Default::default()),
        sensor_errors: u32::MAX,
        theta_d_deg: i32::MIN,
        commands: u32::MAX,
    };
    let t = Telemetry {
        t_us: u32::MAX,
        mode: Mode::Stopping(StopReason::Fault(kapitza_core::link::message::Fault::Stall)),
        theta: i32::MIN,
        phi: i32::MIN,
        phi_rate: i32::MIN,
        omega_p: Some(i32::MIN),
        sigma: Some(i32::MIN),
        settled: true,
        equilibrium: Some(i32::MIN),
        r: Some((i32::MIN, RMethod::SlowFrequency)),
        periods: u32::MAX,
        omega: i32::MIN,
        crank_speed: i32::MIN,
        phase_error: i32::MIN,
        duty: i16::MIN,
        current: i32::MIN,
        theta_d_deg: i32::MIN,
        steady: true,
        commands: u32::MAX,
        wobble: i32::MIN,
    };
    let mut s: Status = link_samples::status();
    s.last_stop = Some(StopReason::Fault(kapitza_core::link::message::Fault::Stall));
    s.omega = i32::MIN;
    s.omega_target = i32::MIN;
    s.theta_d_deg = i32::MIN;
    s.theta_d_target_deg = i32::MIN;
    s.config = kapitza_core::persist::ConfigOrigin::Defaults(
        kapitza_core::persist::Fallback::Incompatible { version: u16::MAX },
    );
    s.uptime_ms = u32::MAX;
    s.counters.frames_ok = u32::MAX;
    s.counters.frames_bad = u32::MAX;
    s.counters.sensor_errors = u32::MAX;
    s.counters.overruns = u32::MAX;
    s.counters.frames_dropped = u32::MAX;
    s.counters.commands = u32::MAX;
    s.check = Some(kapitza_core::link::message::Check::Failed(
        kapitza_core::link::message::Verdict::CurrentOffset { amps: i32::MIN },
    ));
    s.bring_up = Some(i16::MIN);
    vec![
        (
            "set_config",
            Msg::Req(Request::SetConfig(cfg)),
            Request::POSTCARD_MAX_SIZE,
        ),
        ("config", Msg::Resp(Response::Config(cfg)), 0),
        ("telemetry", Msg::Resp(Response::Telemetry(t)), 0),
        ("raw", Msg::Resp(Response::Raw(raw)), 0),
        ("status", Msg::Resp(Response::Status(s)), 0),
    ]
}

#[test]
fn max_size_bounds_hold_and_are_reached() {
    let mut largest_resp = 0;
    for (name, m, exact) in worst_cases() {
        let mut buf = [0u8; 512];
        let n = match m {
            Msg::Req(r) => postcard::to_slice(&r, &mut buf).unwrap().len(),
            Msg::Resp(r) => postcard::to_slice(&r, &mut buf).unwrap().len(),
        };
        println!("{name}: {n} bytes");
        if exact > 0 {
            assert_eq!(n, exact, "{name}: the bound is the worst case");
        }
        if let Msg::Resp(_) = m {
            largest_resp = largest_resp.max(n);
            assert!(n <= Response::POSTCARD_MAX_SIZE, "{name}");
        }
        // Worst-case frames fit their buffers.
        let f = frame_of(255, &m);
        assert!(f.len() <= max_frame_len(n), "{name}");
    }
    // The response bound is the largest worst case (MaxSize adds nothing beyond it).
    assert_eq!(largest_resp, Response::POSTCARD_MAX_SIZE);
    println!(
        "request <= {} B payload, {MAX_REQUEST_FRAME} B frame; response <= {} B payload, \
         {MAX_RESPONSE_FRAME} B frame",
        Request::POSTCARD_MAX_SIZE,
        Response::POSTCARD_MAX_SIZE
    );
    // A response frame fits the firmware's 512-byte pipe to the line; at 115200 baud it takes
    // under 45 ms. (The configuration with its calibration is the largest message.)
    const { assert!(MAX_RESPONSE_FRAME <= 512) };
}

#[test]
fn crc_is_crc32c() {
    // The catalogued check value of CRC-32/ISCSI (CRC-32C).
    assert_eq!(CRC.checksum(b"123456789"), 0xE306_9283);
}

#[test]
fn reader_splits_a_stream_and_resynchronises() {
    let mut stream = vec![0x13, 0x37, 0x42]; // line noise before the first delimiter
    stream.push(0);
    stream.extend(frame_of(1, &Msg::Req(Request::GetStatus)));
    stream.extend([0, 0, 0]); // idle fill
    stream.extend(frame_of(2, &Msg::Req(Request::Stop)));
    stream.extend([0xAA; 600]); // a runaway frame
    stream.push(0);
    stream.extend(frame_of(3, &Msg::Req(Request::ClearFault)));
    let mut reader = FrameReader::<{ MAX_REQUEST_FRAME }>::new();
    let mut got = Vec::new();
    for b in stream {
        if let Some(r) = reader.push(b) {
            got.push(r.map(receive_request));
        }
    }
    assert_eq!(
        got,
        vec![
            Ok((0, Err(Reason::Truncated))),
            Ok((1, Ok(Request::GetStatus))),
            Ok((2, Ok(Request::Stop))),
            Err(Reason::TooLong),
            Ok((3, Ok(Request::ClearFault))),
        ]
    );
}

#[test]
fn damaged_frames_are_refused_with_their_reason() {
    let f = frame_of(
        9,
        &Msg::Req(Request::SetDrive {
            r: 3 << 16,
            theta_d_deg: 90 << 16,
        }),
    );
    let body = &f[..f.len() - 1];
    // Every single flipped bit: never a request, always a link-level reason.
    for i in 0..body.len() * 8 {
        let mut b = body.to_vec();
        b[i / 8] ^= 1 << (i % 8);
        let (_, r) = receive_request(&mut b);
        let e = r.expect_err("a flipped bit must not decode");
        assert!(e.is_link(), "bit {i}: {e:?}");
    }
    // Every truncation.
    for n in 0..body.len() {
        let mut b = body[..n].to_vec();
        let (_, r) = receive_request(&mut b);
        assert!(r.unwrap_err().is_link(), "{n} bytes");
    }
    // An unknown message kind from a newer peer, correctly framed.
    let mut raw = vec![kapitza_core::link::PROTOCOL_VERSION, 5, 40];
    let crc = CRC.checksum(&raw);
    raw.extend(crc.to_le_bytes());
    let mut stuffed = [0u8; 16];
    let n = corncobs_encode(&raw, &mut stuffed);
    assert_eq!(
        receive_request(&mut stuffed[..n]),
        (5, Err(Reason::UnknownMessage))
    );
    // Bytes left over after a valid message.
    let mut raw = vec![kapitza_core::link::PROTOCOL_VERSION, 6, 1, 0xFF];
    let crc = CRC.checksum(&raw);
    raw.extend(crc.to_le_bytes());
    let n = corncobs_encode(&raw, &mut stuffed);
    assert_eq!(
        receive_request(&mut stuffed[..n]),
        (6, Err(Reason::Malformed))
    );
}

/// Stuffs `raw` into `out` without its terminator; returns the length.
fn corncobs_encode(raw: &[u8], out: &mut [u8]) -> usize {
    // Hand-rolled COBS (Cheshire & Baker 1999) for frames under 254 bytes, independent of the
    // crate under test.
    let mut o = 0;
    for run in raw.split(|&b| b == 0) {
        out[o] = run.len() as u8 + 1;
        out[o + 1..o + 1 + run.len()].copy_from_slice(run);
        o += 1 + run.len();
    }
    o
}

#[test]
fn version_skew() {
    // GetVersion is answered from any version; anything else is refused as a mismatch.
    let other = kapitza_core::link::PROTOCOL_VERSION.wrapping_add(1);
    for (req, want) in [
        (Request::GetVersion, Ok(Request::GetVersion)),
        (
            Request::GetStatus,
            Err(Reason::VersionMismatch {
                rig: kapitza_core::link::PROTOCOL_VERSION,
                frame: other,
            }),
        ),
    ] {
        let mut out = [0u8; 512];
        let n = encode(
            Header {
                version: other,
                seq: 4,
            },
            &req,
            &mut out,
        )
        .unwrap();
        assert_eq!(receive_request(&mut out[..n - 1]), (4, want));
    }
    // The host decodes a Version answer from a rig of another version, and nothing else.
    let v = Response::Version(kapitza_core::link::VersionInfo {
        protocol: other,
        firmware: [9, 9, 9],
    });
    let mut out = [0u8; 512];
    let n = encode(
        Header {
            version: other,
            seq: 0,
        },
        &v,
        &mut out,
    )
    .unwrap();
    let (h, got) = receive_response(&mut out[..n - 1]).unwrap();
    assert_eq!((h.version, got), (other, v));
    let n = encode(
        Header {
            version: other,
            seq: 0,
        },
        &Response::Ok,
        &mut out,
    )
    .unwrap();
    assert!(matches!(
        receive_response(&mut out[..n - 1]),
        Err(Reason::VersionMismatch { .. })
    ));
    // A buffer too small is an error, not a panic.
    assert!(encode(Header::new(0), &Response::Ok, &mut [0u8; 8]).is_err());
    let _ = frame::GET_VERSION_PAYLOAD;
}
