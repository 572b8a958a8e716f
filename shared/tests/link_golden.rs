//! Golden frames: every message's bytes on the line, compared with `tests/golden/v{N}/*.hex`
//! (N = the protocol version). An unintended change of any encoding fails here.
//!
//! After an intended change: bump `link::PROTOCOL_VERSION` (see the compatibility policy in
//! `link`'s module doc), then write the new directory with
//!
//! ```sh
//! KAPITZA_BLESS=1 cargo test -p kapitza-core --test link_golden
//! ```
//! The frozen frames (`GetVersion`, `Version`) are literals below, not files: blessing cannot
//! change them, and they must decode the same in every protocol version.

mod link_samples;

use std::collections::BTreeSet;
use std::path::PathBuf;

use kapitza_core::link::frame::{encode, receive_request, receive_response, Header};
use kapitza_core::link::{Request, Response, VersionInfo, PROTOCOL_VERSION};
use link_samples::Msg;

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("v{PROTOCOL_VERSION}"))
}

fn hex(bytes: &[u8]) -> String {
    let mut s: Vec<String> = bytes.iter().map(|b| format!("{b:02x}")).collect();
    s.push(String::new());
    s.join(" ").trim_end().to_string() + "\n"
}

fn frame_of(seq: u8, m: &Msg) -> Vec<u8> {
    let mut out = [0u8; 512];
    let n = match m {
        Msg::Req(r) => encode(Header::new(seq), r, &mut out).unwrap(),
        Msg::Resp(r) => encode(Header::new(seq), r, &mut out).unwrap(),
    };
    out[..n].to_vec()
}

#[test]
fn frames_match_the_golden_files() {
    let bless = std::env::var_os("KAPITZA_BLESS").is_some_and(|v| v == "1");
    let dir = dir();
    if bless {
        std::fs::create_dir_all(&dir).unwrap();
    }
    let mut names = BTreeSet::new();
    let mut failures = Vec::new();
    for (name, seq, m) in link_samples::all() {
        assert!(names.insert(name), "duplicate sample name {name}");
        let path = dir.join(format!("{name}.hex"));
        let got = hex(&frame_of(seq, &m));
        if bless {
            std::fs::write(&path, &got).unwrap();
            continue;
        }
        match std::fs::read_to_string(&path) {
            Ok(want) if want == got => {}
            Ok(want) => failures.push(format!("{name}:\n  file {want}  now  {got}")),
            Err(e) => failures.push(format!("{name}: {} ({e})", path.display())),
        }
    }
    // No stale files: every golden file is a sample's.
    for entry in std::fs::read_dir(&dir).unwrap() {
        let file = entry.unwrap().file_name().into_string().unwrap();
        let stem = file.strip_suffix(".hex").unwrap_or(&file);
        if !names.contains(stem) {
            failures.push(format!(
                "{file}: no sample of that name (stale golden file)"
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "golden frames differ (an encoding changed: bump PROTOCOL_VERSION and bless with \
         KAPITZA_BLESS=1 cargo test -p kapitza-core --test link_golden):\n{}",
        failures.join("\n")
    );
}

/// `GetVersion` with version byte 1, seq 0: frozen forever.
const FROZEN_GET_VERSION: [u8; 9] = [0x02, 0x01, 0x01, 0x05, 0x04, 0x31, 0x25, 0xc5, 0x00];
/// `Version { protocol: 1, firmware: [0, 1, 0] }` with version byte 1, seq 0: frozen forever.
const FROZEN_VERSION: [u8; 13] = [
    0x02, 0x01, 0x01, 0x02, 0x01, 0x02, 0x01, 0x05, 0x6a, 0x74, 0xda, 0x1d, 0x00,
];

#[test]
fn frozen_frames_never_change() {
    let mut out = [0u8; 512];
    let hdr = Header { version: 1, seq: 0 };
    let n = encode(hdr, &Request::GetVersion, &mut out).unwrap();
    assert_eq!(out[..n], FROZEN_GET_VERSION);
    let v = Response::Version(VersionInfo {
        protocol: 1,
        firmware: [0, 1, 0],
    });
    let n = encode(hdr, &v, &mut out).unwrap();
    assert_eq!(out[..n], FROZEN_VERSION);
    // And they decode, whatever PROTOCOL_VERSION is now.
    let mut f = FROZEN_GET_VERSION;
    assert_eq!(receive_request(&mut f[..8]), (0, Ok(Request::GetVersion)));
    let mut f = FROZEN_VERSION;
    assert_eq!(receive_response(&mut f[..12]), Ok((hdr, v)));
}
