//! The serial link between the laptop and the rig: typed messages, framing and refusal reasons.
//! Shared by the firmware and the host, tested on the host. The rig's side of the conversation,
//! which answers the messages, is [`crate::station::serve`].
//!
//! | module | concept |
//! |---|---|
//! | [`message`] | [`Request`] and [`Response`], with every field's unit and fixed-point format |
//! | [`frame`] | version ‖ seq ‖ postcard ‖ CRC-32C, COBS-stuffed, zero-terminated; the frame reader |
//! | [`reason`] | [`Reason`]: why a frame or a command was refused, with stable codes and text |
//! | [`convert`] | the rig's types ↔ their wire images; I16F16 and degree conversions |
//! | [`origin`] | where the configuration in use came from, and why a stored one was not used |
//!
//! The laptop's side is the host tool's `link` module: one method per command, and an error type
//! that keeps "the line failed" apart from "the rig refused".
//!
//! # The conversation
//!
//! ```text
//! laptop                                           rig (USART, 115200 8N1)
//! Request, seq = n   ──────────────────────────▶   decoded; applied or refused
//!                    ◀──────────────────────────   Response (Ok / Refused(reason) / data), seq = n
//!                    ◀──────────────────────────   Telemetry, unsolicited, when asked for
//! a bad frame        ──────────────────────────▶   Refused(BadCrc | Truncated | Malformed | TooLong
//!                                                  | UnknownMessage | VersionMismatch), seq = the
//!                                                  frame's if its CRC passed, else 0
//! ```
//! Noise, a lost byte or a truncated frame fails the CRC or the strict decode, and is answered
//! with a link-level reason; it can never be taken for another valid request (a wrong frame
//! passes CRC-32C with probability 2^-32). A refused command changes nothing on the rig.
//!
//! # Exactly once over a damaged line
//!
//! A request whose answer does not arrive in time, or arrives damaged, is sent again **with the
//! same seq**; the rig answers a repeat of the last request it answered (same seq, same bytes)
//! with the answer it already gave and does not carry it out again
//! ([`crate::station::repeat`]). So a command whose answer was lost is carried out once and its
//! answer still arrives; a late answer to an earlier copy is as good as the last one's.
//!
//! ```text
//! laptop                                  rig
//! SetDrive, seq 7  ───────────────────▶   carried out; answer Ok, seq 7 (lost on the way)
//!   no answer within the per-try timeout
//! SetDrive, seq 7  ───────────────────▶   a repeat: Ok, seq 7 again, nothing carried out
//!                  ◀───────────────────   Ok, seq 7
//! ```
//! The host's retry window is bounded (tries × per-try timeout; the host tool's `link` module
//! gives the numbers) and then reports the line as failed. Each new request takes the next seq
//! (1…255, 0 is the rig's answer to a frame it could not read), so two different requests in a
//! row never share one.
//!
//! One request, there and back:
//!
//! ```
//! use kapitza_core::link::frame::{encode, receive_request, Header};
//! use kapitza_core::link::{Request, MAX_REQUEST_FRAME};
//!
//! let req = Request::SetDrive { r: 3 << 16, theta_d_deg: 180 << 16 }; // R = 3, θd = 180°
//! let mut line = [0u8; MAX_REQUEST_FRAME];
//! let n = encode(Header::new(7), &req, &mut line).unwrap();
//! assert_eq!(line[n - 1], 0); // the frame ends with its only zero byte
//! let (seq, got) = receive_request(&mut line[..n - 1]);
//! assert_eq!((seq, got), (7, Ok(req)));
//! ```
//!
//! # Versions and the compatibility policy
//!
//! [`PROTOCOL_VERSION`] is the first byte of every frame. postcard is not self-describing, so
//! two sides agree on a message only if they agree on the version; the rules:
//!
//! 1. **Frozen forever**: the frame format (COBS, header bytes `version, seq`, CRC-32C at the end),
//!    [`Request::GetVersion`] (variant 0, no fields: payload `00`) and [`Response::Version`]
//!    (variant 0, [`VersionInfo`]: `protocol: u8, firmware: [u16; 3]`). The rig answers
//!    `GetVersion` whatever version byte it arrives with, and the host decodes a `Version`
//!    answer from a rig of any version. So a host can always find out what it is talking to.
//! 2. **Any other change bumps the version**: a new, removed or reordered variant or field, a
//!    changed type or unit, a new [`Reason`]. There are no "compatible" additions: an older
//!    peer would misread or refuse them, so the version says so up front instead.
//! 3. **A version mismatch is refused, never guessed at**: the rig answers every request but
//!    `GetVersion` from another version with `Refused(VersionMismatch { rig, frame })` and does
//!    nothing; the host, seeing a frame of another version that is not `Version`, reports the
//!    mismatch. Host and firmware are built from the same `kapitza-core`, so the fix is to
//!    flash the firmware that matches the host (or the reverse).
//! 4. **The golden frames hold the line**: `tests/link_golden.rs` compares every message's frame
//!    with `tests/golden/v{PROTOCOL_VERSION}/`; an unintended encoding change fails it. After an
//!    intended one, bump [`PROTOCOL_VERSION`] and bless the new directory
//!    (`KAPITZA_BLESS=1 cargo test -p kapitza-core --test link_golden`); the frozen frames are
//!    literals in the test and cannot be blessed away.
//!
//! The stored configuration record ([`crate::persist`]) has its own format version and falls
//! back to safe defaults when it does not match.

pub mod convert;
pub mod frame;
pub mod message;
pub mod origin;
pub mod reason;

pub use frame::{FrameReader, Header, MAX_REQUEST_FRAME, MAX_RESPONSE_FRAME};
pub use message::{Request, Response, Status, Telemetry, VersionInfo, WireConfig};
pub use reason::Reason;

/// The link protocol version: the first byte of every frame. See the policy above.
pub const PROTOCOL_VERSION: u8 = 6;

/// Line speed of the rig's serial port (8 data bits, no parity, 1 stop bit).
pub const BAUD: u32 = 115_200;
