//! The stored configuration record across format versions: records written by the firmware of
//! record formats 1 and 2 (`tests/golden/persist/record_v{1,2}.bin`, each made by that
//! version's `persist::encode`) load as the current configuration, with the fields their
//! format lacked at the values the firmware was built with then.
//!
//! * format 1: the reference rig with A = 12.5 mm, 8 kHz sampling and a 2.5 A trip;
//! * format 2: the reference rig with A = 12.7 mm, the sensor's zero at count 16316, the servo's
//!   centre at 92°, closed-loop R on and a duty ceiling of 0.9.

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
    let n = persist::encode(&cfg, 1, &mut buf);
    assert_eq!(&buf[4..6], &persist::RECORD_VERSION.to_le_bytes());
    assert_eq!(persist::decode(&buf[..n]), Ok(want));
}

#[test]
fn a_version_2_record_loads_without_a_connecting_rod() {
    let bytes = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/golden/persist/record_v2.bin"
    ))
    .unwrap();
    assert_eq!(&bytes[..6], b"KPZC\x02\x00", "a format-2 record");
    let mut want = RigConfig::REFERENCE;
    want.amplitude = 0.0127;
    want.calibration.pendulum_zero = 16316;
    want.calibration.servo.centre_deg = 92.0;
    want.closed_loop.enabled = true;
    want.limits.duty_max = 0.9;
    let (cfg, origin) = persist::load(&bytes);
    assert_eq!(origin, ConfigOrigin::Stored);
    assert_eq!(cfg, want);
    assert_eq!(cfg.connecting_rod, 0.0);
    let mut buf = [0u8; RECORD_MAX];
    let n = persist::encode(&cfg, 1, &mut buf);
    assert_eq!(&buf[4..6], &persist::RECORD_VERSION.to_le_bytes());
    assert_eq!(persist::decode(&buf[..n]), Ok(want));
}

#[test]
fn a_damaged_version_1_record_is_still_refused() {
    let mut bytes = v1_record();
    bytes[20] ^= 1;
    assert_eq!(persist::decode(&bytes), Err(Fallback::Corrupt));
}
