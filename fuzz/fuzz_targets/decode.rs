//! Everything that reads bytes from outside: the frame reader, both decoders, the stored
//! configuration record, the pendulum sensor's answers (the AS5047P driver) and the words kept
//! in RAM across a reset. None may panic on any input; a frame that decodes must re-encode to
//! the same payload (no two encodings of one message slip through the strict decoder); the
//! sensor driver reports an angle only with its failure run reset. Every request that decodes is
//! also answered by a rig (`RigServer::respond`): a configuration with any calibration, a
//! bring-up duty or a start must be refused or taken, never panic.

#![no_main]

use kapitza_core::link::frame::{encode, open, receive_request, receive_response, Header};
use kapitza_core::link::{FrameReader, MAX_REQUEST_FRAME, MAX_RESPONSE_FRAME};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // As a stream from the line.
    let mut reader = FrameReader::<MAX_REQUEST_FRAME>::new();
    for &b in data {
        if let Some(Ok(stuffed)) = reader.push(b) {
            let mut copy = [0u8; MAX_REQUEST_FRAME];
            copy[..stuffed.len()].copy_from_slice(stuffed);
            let len = stuffed.len();
            if let (seq, Ok(req)) = receive_request(stuffed) {
                let mut rig = kapitza_core::link::serve::RigServer::new(
                    kapitza_core::rig::config::RigConfig::REFERENCE,
                    kapitza_core::persist::ConfigOrigin::Stored,
                    kapitza_core::rig::fixed::Angle::ZERO,
                    kapitza_core::link::serve::Clock::single(0, 0),
                    [0, 1, 0],
                );
                let _ = rig.respond(req, kapitza_core::link::serve::Clock::single(1000, 1), false);
                // Re-encode: the same payload as the one accepted.
                let mut out = [0u8; MAX_REQUEST_FRAME];
                let n = encode(Header::new(seq), &req, &mut out).expect("fits");
                let mut reopened = out;
                let again = open(&mut reopened[..n - 1]).expect("own frame opens");
                let mut orig = copy;
                let first = open(&mut orig[..len]).expect("accepted frame opens");
                if first.header.version == kapitza_core::link::PROTOCOL_VERSION {
                    assert_eq!(first.payload, again.payload);
                }
            }
            let _ = receive_response(&mut copy[..len]);
        }
    }
    // As one frame, and as a stored record.
    let mut whole = [0u8; 2 * MAX_RESPONSE_FRAME];
    let n = data.len().min(whole.len());
    whole[..n].copy_from_slice(&data[..n]);
    let _ = receive_request(&mut whole[..n].to_owned());
    let _ = receive_response(&mut whole[..n]);
    let _ = kapitza_core::persist::load(data);
    // As the sensor's answers on MISO, two bytes a frame (the bus may also fail: a missing word).
    let mut sensor = kapitza_core::rig::as5047::As5047::new();
    let mut words = data
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]));
    for k in 0..data.len() / 2 {
        let r = sensor.sample(k as u32 * 100, |_| words.next().ok_or(()));
        if r.count.is_ok() {
            assert_eq!(sensor.health().bad_run, 0);
        }
    }
    // As the retained RAM after a reset.
    if let Some(b) = data.get(..16) {
        let w = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        let _ = kapitza_core::rig::retained::decode([w(0), w(4), w(8), w(12)]);
    }
});
