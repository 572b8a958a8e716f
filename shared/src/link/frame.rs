//! Framing: header, postcard payload and CRC, COBS-stuffed and ended by a zero byte.
//!
//! ```text
//! on the line:   COBS( version ‖ seq ‖ postcard(message) ‖ CRC-32C ) ‖ 0x00
//! version  u8    PROTOCOL_VERSION of the sender
//! seq      u8    the request's number; a reply carries its request's seq; telemetry counts up
//! CRC-32C  u32   little-endian, over version ‖ seq ‖ payload (init 0xFFFFFFFF, reflected,
//!                xorout 0xFFFFFFFF; check value of "123456789" = 0xE3069283)
//! ```
//! COBS (Cheshire & Baker, "Consistent Overhead Byte Stuffing", IEEE/ACM Trans. Networking 7(2),
//! 1999) removes every zero byte from the frame at a cost of one byte per 254, so a zero always
//! means "end of frame": a receiver that starts mid-stream, or loses bytes, resynchronises at
//! the next zero. CRC-32C (Castagnoli) detects every error of up to 5 flipped bits in frames of
//! up to 5243 bits (655 bytes; ours are under 256) and all burst errors up to 32 bits; a random
//! garbage frame passes with probability 2^-32 (Koopman, "32-Bit Cyclic Redundancy Codes for
//! Internet Applications", DSN 2002, table 1). After the CRC, postcard decoding is strict: a
//! frame must be consumed exactly, with no bytes left over.
//!
//! Every failure has a [`Reason`]; nothing here panics on any input (property test in
//! `tests/link_props.rs`, fuzz target in `fuzz/`).

use postcard::experimental::max_size::MaxSize;
use serde::Serialize;

use super::message::{Request, Response, VersionInfo};
use super::reason::Reason;
use super::PROTOCOL_VERSION;

use crate::checksum::CRC;

/// Bytes before the payload: version, seq.
pub const HEADER_LEN: usize = 2;
/// Bytes of CRC after the payload.
pub const CRC_LEN: usize = 4;

/// Largest unstuffed frame (header, payload, CRC) for a message of at most `msg_max` bytes.
pub const fn max_raw_len(msg_max: usize) -> usize {
    HEADER_LEN + msg_max + CRC_LEN
}

/// Largest frame on the line, the terminating zero included, for a message of at most `msg_max`.
pub const fn max_frame_len(msg_max: usize) -> usize {
    corncobs::max_encoded_len(max_raw_len(msg_max))
}

/// Largest request frame on the line (terminator included).
pub const MAX_REQUEST_FRAME: usize = max_frame_len(Request::POSTCARD_MAX_SIZE);
/// Largest response frame on the line (terminator included).
pub const MAX_RESPONSE_FRAME: usize = max_frame_len(Response::POSTCARD_MAX_SIZE);

const fn max(a: usize, b: usize) -> usize {
    if a > b {
        a
    } else {
        b
    }
}
const RAW_MAX: usize = max(
    max_raw_len(Request::POSTCARD_MAX_SIZE),
    max_raw_len(Response::POSTCARD_MAX_SIZE),
);

/// The two bytes in front of every payload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Header {
    pub version: u8,
    pub seq: u8,
}

impl Header {
    /// This protocol version, with a sequence number.
    pub const fn new(seq: u8) -> Self {
        Self {
            version: PROTOCOL_VERSION,
            seq,
        }
    }
}

/// Why a frame could not be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// `out` is shorter than the frame could be ([`max_frame_len`]).
    BufferTooSmall,
}

/// Builds the frame of `msg` into `out` (terminator included); returns its length.
///
/// `out` must hold [`max_frame_len`]`(M::POSTCARD_MAX_SIZE)` bytes, [`MAX_RESPONSE_FRAME`] or
/// [`MAX_REQUEST_FRAME`] for the two message types.
pub fn encode<M: Serialize + MaxSize>(
    header: Header,
    msg: &M,
    out: &mut [u8],
) -> Result<usize, EncodeError> {
    if out.len() < max_frame_len(M::POSTCARD_MAX_SIZE) || M::POSTCARD_MAX_SIZE > RAW_MAX {
        return Err(EncodeError::BufferTooSmall);
    }
    let mut raw = [0u8; RAW_MAX];
    raw[0] = header.version;
    raw[1] = header.seq;
    let n = postcard::to_slice(msg, &mut raw[HEADER_LEN..RAW_MAX - CRC_LEN])
        .map_err(|_| EncodeError::BufferTooSmall)?
        .len();
    let end = HEADER_LEN + n;
    let crc = CRC.checksum(&raw[..end]);
    raw[end..end + CRC_LEN].copy_from_slice(&crc.to_le_bytes());
    Ok(corncobs::encode_buf(&raw[..end + CRC_LEN], out))
}

/// A frame that passed its CRC: header and payload, not yet decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame<'a> {
    pub header: Header,
    pub payload: &'a [u8],
}

/// Unstuffs (in place) and checks one frame: the bytes between two zeros, without them.
pub fn open(stuffed: &mut [u8]) -> Result<Frame<'_>, Reason> {
    if stuffed.contains(&0) {
        return Err(Reason::Malformed);
    }
    let n = corncobs::decode_in_place(stuffed).map_err(|_| Reason::Truncated)?;
    // A message is at least its one-byte variant index.
    if n < HEADER_LEN + 1 + CRC_LEN {
        return Err(Reason::Truncated);
    }
    let (body, crc) = stuffed[..n].split_at(n - CRC_LEN);
    let crc = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
    if CRC.checksum(body) != crc {
        return Err(Reason::BadCrc);
    }
    Ok(Frame {
        header: Header {
            version: body[0],
            seq: body[1],
        },
        payload: &body[HEADER_LEN..],
    })
}

/// The frozen payload of `GetVersion`: variant 0, no fields.
pub const GET_VERSION_PAYLOAD: [u8; 1] = [0];

/// The first varint of a payload: the message's variant index.
fn kind(payload: &[u8]) -> Result<u32, Reason> {
    postcard::take_from_bytes::<u32>(payload)
        .map(|(k, _)| k)
        .map_err(postcard_reason)
}

fn postcard_reason(e: postcard::Error) -> Reason {
    match e {
        postcard::Error::DeserializeUnexpectedEnd => Reason::Truncated,
        _ => Reason::Malformed,
    }
}

/// Decodes exactly `payload` as `M` (no bytes may be left over).
fn strict<'a, M: serde::Deserialize<'a>>(payload: &'a [u8]) -> Result<M, Reason> {
    match postcard::take_from_bytes::<M>(payload) {
        Ok((m, [])) => Ok(m),
        Ok(_) => Err(Reason::Malformed),
        Err(e) => Err(postcard_reason(e)),
    }
}

/// The rig's side: what a checked frame asks for. `GetVersion` is recognised whatever the
/// frame's version; every other request needs this protocol version.
pub fn decode_request(frame: &Frame<'_>) -> Result<Request, Reason> {
    decode_request_as(frame, PROTOCOL_VERSION)
}

/// [`decode_request`] for a rig that speaks protocol `version` (a simulated rig made to speak
/// another version, to test what a host does about version skew).
pub fn decode_request_as(frame: &Frame<'_>, version: u8) -> Result<Request, Reason> {
    if frame.payload == GET_VERSION_PAYLOAD {
        return Ok(Request::GetVersion);
    }
    if frame.header.version != version {
        return Err(Reason::VersionMismatch {
            rig: version,
            frame: frame.header.version,
        });
    }
    if kind(frame.payload)? >= Request::KINDS {
        return Err(Reason::UnknownMessage);
    }
    strict(frame.payload)
}

/// The host's side: what a checked frame says. A `Version` answer is understood from a rig of
/// any protocol version (its encoding is frozen); anything else needs this version.
pub fn decode_response(frame: &Frame<'_>) -> Result<Response, Reason> {
    if frame.header.version != PROTOCOL_VERSION {
        return match frame.payload.split_first() {
            Some((0, rest)) => strict::<VersionInfo>(rest).map(Response::Version),
            _ => Err(Reason::VersionMismatch {
                rig: frame.header.version,
                frame: PROTOCOL_VERSION,
            }),
        };
    }
    if kind(frame.payload)? >= Response::KINDS {
        return Err(Reason::UnknownMessage);
    }
    strict(frame.payload)
}

/// The rig's side in one call: unstuff, check and decode one frame. Returns the seq to answer
/// with (the frame's when its CRC passed, else 0) and the request or the reason it was bad.
pub fn receive_request(stuffed: &mut [u8]) -> (u8, Result<Request, Reason>) {
    match open(stuffed) {
        Ok(f) => (f.header.seq, decode_request(&f)),
        Err(r) => (0, Err(r)),
    }
}

/// The host's side in one call: unstuff, check and decode one frame.
pub fn receive_response(stuffed: &mut [u8]) -> Result<(Header, Response), Reason> {
    let f = open(stuffed)?;
    Ok((f.header, decode_response(&f)?))
}

/// Collects bytes from the line into frames. `N` bounds a frame (terminator excluded); a longer
/// one is dropped whole and reported once as [`Reason::TooLong`] at its terminator.
#[derive(Debug, Clone)]
pub struct FrameReader<const N: usize> {
    buf: [u8; N],
    len: usize,
    overflow: bool,
}

impl<const N: usize> Default for FrameReader<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> FrameReader<N> {
    pub const fn new() -> Self {
        Self {
            buf: [0; N],
            len: 0,
            overflow: false,
        }
    }

    /// One byte from the line. At a zero byte that ends a non-empty frame, returns the frame's
    /// stuffed bytes (for [`open`] or [`receive_request`]) or `Err(TooLong)`; otherwise `None`
    /// (zeros between frames are idle fill and ignored).
    pub fn push(&mut self, byte: u8) -> Option<Result<&mut [u8], Reason>> {
        if byte == 0 {
            let len = core::mem::take(&mut self.len);
            if core::mem::take(&mut self.overflow) {
                return Some(Err(Reason::TooLong));
            }
            return (len > 0).then(|| Ok(&mut self.buf[..len]));
        }
        if self.len < N {
            self.buf[self.len] = byte;
            self.len += 1;
        } else {
            self.overflow = true;
        }
        None
    }

    /// Forget a partial frame (e.g. after a line error).
    pub fn reset(&mut self) {
        self.len = 0;
        self.overflow = false;
    }
}
