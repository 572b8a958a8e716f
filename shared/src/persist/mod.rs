//! The rig configuration as a checksummed record in flash: encoding, checking, and the fallback
//! to safe defaults. Pure logic; the firmware reads and writes the bytes.
//!
//! ```text
//! offset  size  field
//! 0       4     magic "KPZC"
//! 4       2     record format version (RECORD_VERSION), little-endian
//! 6       2     payload length n, little-endian
//! 8       4     sequence number s, little-endian (the store's; formats before 4 have none)
//! 12      n     postcard(WireConfig): the RigConfig field for field, f64 (link::message)
//! 12+n    4     CRC-32C over bytes 0..12+n, little-endian (the link's CRC, crate::checksum::CRC)
//! …             0xFF up to a multiple of 8 bytes (the STM32G4 programs 64-bit double words)
//! ```
//! Formats 1 to 3 have no sequence field: their payload starts at byte 8. Where records live
//! in flash, and which one is loaded, is [`store`]'s.
//! [`load`] never fails: an erased page (all 0xFF) is [`Fallback::Missing`]; a wrong magic,
//! length or CRC is [`Fallback::Corrupt`]; another format version is [`Fallback::Incompatible`];
//! a record whose numbers [`RigConfig::validate`] refuses is [`Fallback::Invalid`] to
//! [`decode`]. In each case [`load`] runs the rig on [`RigConfig::REFERENCE`] (the safe
//! defaults) and the status says why ([`ConfigOrigin::Defaults`]), but for an intact record
//! with fields out of range: those take their defaults, the rest (the calibration above all) is
//! kept, and the status lists them ([`ConfigOrigin::Repaired`]). Bump [`RECORD_VERSION`] whenever [`WireConfig`]'s encoding
//! changes (the link's golden frames catch that).
//!
//! **Migration.** A record of an older format that this firmware still reads loads as the
//! current configuration, with the fields it lacked at their former build-time values:
//!
//! | version | payload | missing fields load as |
//! |---|---|---|
//! | 1 | [`v1::ConfigV1`] | `duty_max` 1, [`crate::rig::calibration::Calibration::DEFAULT`], closed loop off, no connecting rod |
//! | 2 | [`v2::ConfigV2`] | no connecting rod (`connecting_rod` 0) |
//! | 3 | [`WireConfig`], no sequence | — (it counts as older than any record with one) |
//! | 4 | [`WireConfig`] | — |
//!
//! The origin stays [`ConfigOrigin::Stored`]; the record is rewritten in the new format at the
//! next accepted `SetConfig`. Any other version is [`Fallback::Incompatible`].

pub mod repair;
pub mod store;
pub mod v1;
pub mod v2;

use postcard::experimental::max_size::MaxSize;
use serde::Deserialize;

use crate::checksum::CRC;
use crate::link::reason::ConfigField;
use crate::link::WireConfig;
use crate::rig::config::RigConfig;

/// "KPZC".
pub const MAGIC: [u8; 4] = *b"KPZC";
/// The record format version.
pub const RECORD_VERSION: u16 = 4;
/// The last format without a sequence number.
const UNSEQUENCED: u16 = 3;
/// Magic, version and length: what every format starts with.
const PREFIX: usize = 8;
const HEAD: usize = PREFIX + 4;
/// The largest record, padding included: what the firmware reserves and writes.
pub const RECORD_MAX: usize = (HEAD + WireConfig::POSTCARD_MAX_SIZE + 4).div_ceil(8) * 8;

/// An intact record: its configuration (not yet checked) and its sequence number (`None` for
/// a format before 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Record {
    pub cfg: RigConfig,
    pub seq: Option<u32>,
}

pub use crate::link::origin::{ConfigOrigin, Fallback};

/// Writes the record of `cfg` with sequence number `seq` into `out`; returns its length (a
/// multiple of 8).
pub fn encode(cfg: &RigConfig, seq: u32, out: &mut [u8; RECORD_MAX]) -> usize {
    out.fill(0xFF);
    out[..4].copy_from_slice(&MAGIC);
    out[4..6].copy_from_slice(&RECORD_VERSION.to_le_bytes());
    out[PREFIX..HEAD].copy_from_slice(&seq.to_le_bytes());
    let n = match postcard::to_slice(&WireConfig::from(*cfg), &mut out[HEAD..RECORD_MAX - 4]) {
        Ok(p) => p.len(),
        // Cannot happen: the slice holds WireConfig::POSTCARD_MAX_SIZE bytes.
        Err(_) => 0,
    };
    out[6..8].copy_from_slice(&(n as u16).to_le_bytes());
    let crc = CRC.checksum(&out[..HEAD + n]);
    out[HEAD + n..HEAD + n + 4].copy_from_slice(&crc.to_le_bytes());
    (HEAD + n + 4).div_ceil(8) * 8
}

/// The configuration stored in `bytes` (a flash page, or any prefix of it that holds the
/// record), checked, or why it cannot be used.
pub fn decode(bytes: &[u8]) -> Result<RigConfig, Fallback> {
    let cfg = read(bytes)?.cfg;
    cfg.validate().map_err(|e| Fallback::Invalid {
        field: ConfigField::from_param_name(e.name),
    })
}

/// The record in `bytes`, intact, its configuration not yet checked.
pub fn read(bytes: &[u8]) -> Result<Record, Fallback> {
    let head = bytes.get(..PREFIX).ok_or(Fallback::Corrupt)?;
    if head.iter().all(|&b| b == 0xFF) {
        return Err(Fallback::Missing);
    }
    if head[..4] != MAGIC {
        return Err(Fallback::Corrupt);
    }
    let version = u16::from_le_bytes([head[4], head[5]]);
    let n = usize::from(u16::from_le_bytes([head[6], head[7]]));
    let start = if version > UNSEQUENCED { HEAD } else { PREFIX };
    if n > WireConfig::POSTCARD_MAX_SIZE {
        return Err(if version == RECORD_VERSION {
            Fallback::Corrupt
        } else {
            Fallback::Incompatible { version }
        });
    }
    let body = bytes.get(..start + n).ok_or(Fallback::Corrupt)?;
    let crc = bytes
        .get(start + n..start + n + 4)
        .ok_or(Fallback::Corrupt)?;
    if CRC.checksum(body) != u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]) {
        return Err(Fallback::Corrupt);
    }
    let p = &body[start..];
    let cfg = match version {
        1 => RigConfig::from(payload::<v1::ConfigV1>(p)?),
        2 => RigConfig::from(payload::<v2::ConfigV2>(p)?),
        UNSEQUENCED | RECORD_VERSION => RigConfig::from(payload::<WireConfig>(p)?),
        _ => return Err(Fallback::Incompatible { version }),
    };
    let seq =
        (version > UNSEQUENCED).then(|| u32::from_le_bytes([body[8], body[9], body[10], body[11]]));
    Ok(Record { cfg, seq })
}

/// A record's payload, all of it.
fn payload<'a, T: Deserialize<'a>>(bytes: &'a [u8]) -> Result<T, Fallback> {
    match postcard::take_from_bytes(bytes) {
        Ok((w, [])) => Ok(w),
        _ => Err(Fallback::Corrupt),
    }
}

/// The configuration to run on, and where it came from: the stored one if it is intact and
/// valid; an intact one with fields out of range with those at their defaults and the rest
/// (the calibration above all) kept ([`repair::repair`]); else the safe defaults with the
/// reason.
pub fn load(bytes: &[u8]) -> (RigConfig, ConfigOrigin) {
    match read(bytes) {
        Ok(r) => settle(r.cfg),
        Err(f) => (RigConfig::REFERENCE, ConfigOrigin::Defaults(f)),
    }
}

/// An intact record's configuration made one to run on ([`load`]'s second half).
pub fn settle(stored: RigConfig) -> (RigConfig, ConfigOrigin) {
    match repair::repair(stored) {
        Ok((c, defaulted)) if defaulted.is_empty() => (c, ConfigOrigin::Stored),
        Ok((c, defaulted)) => (c, ConfigOrigin::Repaired { defaulted }),
        Err(field) => (
            RigConfig::REFERENCE,
            ConfigOrigin::Defaults(Fallback::Invalid { field }),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_fallbacks() {
        let mut buf = [0u8; RECORD_MAX];
        let mut cfg = RigConfig::REFERENCE;
        cfg.amplitude = 0.0125;
        let n = encode(&cfg, 7, &mut buf);
        assert_eq!(n % 8, 0);
        assert!(n <= RECORD_MAX);
        assert_eq!(load(&buf), (cfg, ConfigOrigin::Stored));
        assert_eq!(decode(&buf[..n]), Ok(cfg));
        assert_eq!(read(&buf).map(|r| r.seq), Ok(Some(7)));
        // An erased page.
        assert_eq!(decode(&[0xFF; 2048]), Err(Fallback::Missing));
        let (c, o) = load(&[0xFF; 2048]);
        assert_eq!(c, RigConfig::REFERENCE);
        assert_eq!(o, ConfigOrigin::Defaults(Fallback::Missing));
        // Every single flipped bit of the record (padding excluded) is caught.
        let used = HEAD + usize::from(u16::from_le_bytes([buf[6], buf[7]])) + 4;
        for i in 0..used * 8 {
            let mut b = buf;
            b[i / 8] ^= 1 << (i % 8);
            assert!(decode(&b).is_err(), "bit {i}");
        }
        // Cut short.
        assert_eq!(decode(&buf[..n - 9]), Err(Fallback::Corrupt));
        assert_eq!(decode(&buf[..3]), Err(Fallback::Corrupt));
        // The calibration and closed-loop fields are stored too.
        cfg.calibration.pendulum_zero = 1234;
        cfg.calibration.crank_sign = -1;
        cfg.closed_loop.enabled = true;
        cfg.limits.duty_max = 0.8;
        cfg.connecting_rod = 0.06;
        encode(&cfg, 7, &mut buf);
        assert_eq!(decode(&buf), Ok(cfg));
    }

    #[test]
    fn other_version_and_invalid_values() {
        let mut buf = [0u8; RECORD_MAX];
        encode(&RigConfig::REFERENCE, 7, &mut buf);
        // Re-seal with another version number: intact, but not ours.
        let n = usize::from(u16::from_le_bytes([buf[6], buf[7]]));
        buf[4] = 5;
        let crc = CRC.checksum(&buf[..HEAD + n]);
        buf[HEAD + n..HEAD + n + 4].copy_from_slice(&crc.to_le_bytes());
        assert_eq!(decode(&buf), Err(Fallback::Incompatible { version: 5 }));
        // Intact but out of range: refused by `decode`, repaired by `load`.
        let mut bad = RigConfig::REFERENCE;
        bad.gravity = -1.0;
        encode(&bad, 7, &mut buf);
        assert_eq!(
            decode(&buf),
            Err(Fallback::Invalid {
                field: ConfigField::Gravity
            })
        );
        let mut defaulted = crate::link::origin::FieldSet::EMPTY;
        defaulted.insert(ConfigField::Gravity);
        assert_eq!(
            load(&buf),
            (RigConfig::REFERENCE, ConfigOrigin::Repaired { defaulted })
        );
    }

    /// A record stored before the safety table (issue 23's `link_timeout_ms = 0` and
    /// `overcurrent_ms = 4294967295`) loads with those two at their defaults and the rest as
    /// stored: the calibration, the stall time and the stroke.
    #[test]
    fn a_stored_field_out_of_range_takes_its_default_and_keeps_the_calibration() {
        let mut stored = RigConfig::REFERENCE;
        stored.amplitude = 0.0125;
        stored.calibration.pendulum_zero = 4321;
        stored.calibration.crank_sign = -1;
        stored.calibration.servo.centre_deg = 85.0;
        stored.limits.stall_ms = 400;
        stored.limits.link_timeout_ms = 0;
        stored.limits.overcurrent_ms = u32::MAX;
        let mut buf = [0u8; RECORD_MAX];
        encode(&stored, 7, &mut buf);
        let (cfg, origin) = load(&buf);
        let mut want = stored;
        want.limits.link_timeout_ms = RigConfig::REFERENCE.limits.link_timeout_ms;
        want.limits.overcurrent_ms = RigConfig::REFERENCE.limits.overcurrent_ms;
        assert_eq!(cfg, want);
        assert_eq!(cfg.calibration, stored.calibration);
        let ConfigOrigin::Repaired { defaulted } = origin else {
            panic!("{origin:?}");
        };
        let got: Vec<_> = defaulted.iter().collect();
        assert_eq!(
            got,
            [ConfigField::OvercurrentMs, ConfigField::LinkTimeoutMs]
        );
    }

    /// A control rate of 5 Hz takes its default of 1 kHz; then the stored sample rate, no
    /// multiple of it, is refused and takes its own: each refused field in turn, the
    /// calibration and ω_max kept.
    #[test]
    fn fields_refused_together_are_repaired_in_turn() {
        let mut stored = RigConfig::REFERENCE;
        stored.calibration.pendulum_zero = 77;
        stored.control_hz = 5;
        stored.limits.omega_max = 15.0;
        stored.limits.stall_min_omega = 10.0;
        stored.sample_hz = 2_500;
        let mut buf = [0u8; RECORD_MAX];
        encode(&stored, 7, &mut buf);
        let (cfg, origin) = load(&buf);
        assert_eq!(cfg.calibration, stored.calibration);
        assert_eq!(cfg.control_hz, 1_000);
        assert_eq!(cfg.sample_hz, 10_000);
        assert_eq!(cfg.limits.omega_max, 15.0);
        let ConfigOrigin::Repaired { defaulted } = origin else {
            panic!("{origin:?}");
        };
        let got: Vec<_> = defaulted.iter().collect();
        assert_eq!(got, [ConfigField::SampleHz, ConfigField::ControlHz]);
    }
}
