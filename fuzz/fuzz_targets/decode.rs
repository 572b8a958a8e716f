//! Everything that reads bytes from outside: the frame reader, both decoders, the stored
//! configuration record. None may panic on any input; a frame that decodes must re-encode to
//! the same payload (no two encodings of one message slip through the strict decoder).

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
});
