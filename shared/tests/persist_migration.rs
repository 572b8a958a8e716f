//! The stored configuration record across format versions: a record written by the firmware
//! of record format 1 (`tests/golden/persist/record_v1.bin`, made by that version's
//! `persist::encode`: the reference rig with A = 12.5 mm, 8 kHz sampling and a 2.5 A trip)
//! loads as the current configuration, with the fields format 1 lacked at the values the
//! firmware was built with then.

use kapitza_core::persist::{self, ConfigOrigin, Fallback, RECORD_MAX};
use kapitza_core::rig::calibration::Calibration;
use kapitza_core::rig::closed_loop::ClosedLoopR;
use kapitza_core::rig::config::RigConfig;

fn v1_record() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/golden/persist/record_v1.bin"
    ))
    .unwrap()
}

#[test]
fn a_version_1_record_loads_with_the_former_build_constants() {
    let bytes = v1_record();
    assert_eq!(&bytes[..6], b"KPZC\x01\x00", "a format-1 record");
    let mut want = RigConfig::REFERENCE;
    want.amplitude = 0.0125;
    want.sample_hz = 8_000;
    want.limits.current_max = 2.5;
    let (cfg, origin) = persist::load(&bytes);
    assert_eq!(origin, ConfigOrigin::Stored);
    assert_eq!(cfg, want);
    assert_eq!(cfg.calibration, Calibration::DEFAULT);
    assert_eq!(cfg.closed_loop, ClosedLoopR::DEFAULT);
    assert_eq!(cfg.limits.duty_max, 1.0);
    // Rewritten, it is a current record of the same configuration.
    let mut buf = [0u8; RECORD_MAX];
    let n = persist::encode(&cfg, &mut buf);
    assert_eq!(&buf[4..6], &persist::RECORD_VERSION.to_le_bytes());
    assert_eq!(persist::decode(&buf[..n]), Ok(want));
}

#[test]
fn a_damaged_version_1_record_is_still_refused() {
    let mut bytes = v1_record();
    bytes[20] ^= 1;
    assert_eq!(persist::decode(&bytes), Err(Fallback::Corrupt));
}
