//! What survives a reset in RAM that is not initialised at boot (the firmware's `.uninit`):
//! the last θd commanded to the servo and the last fault, with the reset's cause read beside it.
//!
//! ```text
//! word 0  magic "KPZR"
//! word 1  θd (degrees, f32 bits)
//! word 2  the last fault latched (0: none; 1 + the fault's index)
//! word 3  CRC-32C over words 0..3 (little-endian bytes; the link's CRC)
//! ```
//! At power-up SRAM holds noise, which [`decode`] refuses (the CRC); after a watchdog or
//! software reset it holds the record as last written. Its contents are advice, never trusted
//! blindly: θd is range-checked again ([`super::servo::power_up_deg`]).

use super::bridge::Line;
use super::safety::Fault;
use crate::checksum::CRC;

/// "KPZR", little-endian.
pub const MAGIC: u32 = u32::from_le_bytes(*b"KPZR");

/// The retained state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Retained {
    pub theta_d_deg: f32,
    pub last_fault: Option<Fault>,
}

const FAULTS: [Fault; 10] = [
    Fault::EStop,
    Fault::OverCurrent,
    Fault::Stall,
    Fault::Sensor,
    Fault::WrongDirection,
    Fault::PhaseLockLost,
    Fault::OverCurrentRms,
    Fault::DutyCeiling,
    Fault::Bridge(Line::NFault),
    Fault::Bridge(Line::Break),
];

fn crc(words: &[u32; 3]) -> u32 {
    let mut b = [0u8; 12];
    for (i, w) in words.iter().enumerate() {
        b[4 * i..4 * i + 4].copy_from_slice(&w.to_le_bytes());
    }
    CRC.checksum(&b)
}

/// The four words to keep.
pub fn encode(r: &Retained) -> [u32; 4] {
    let fault = r
        .last_fault
        .and_then(|f| FAULTS.iter().position(|&x| x == f))
        .map_or(0, |i| i as u32 + 1);
    let w = [MAGIC, r.theta_d_deg.to_bits(), fault];
    [w[0], w[1], w[2], crc(&w)]
}

/// The record in `words`, if it is one.
pub fn decode(words: [u32; 4]) -> Option<Retained> {
    let w = [words[0], words[1], words[2]];
    if w[0] != MAGIC || crc(&w) != words[3] {
        return None;
    }
    let last_fault = match w[2] {
        0 => None,
        n => Some(*FAULTS.get(n as usize - 1)?),
    };
    Some(Retained {
        theta_d_deg: f32::from_bits(w[1]),
        last_fault,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_noise_refused() {
        for f in [
            None,
            Some(Fault::Stall),
            Some(Fault::WrongDirection),
            Some(Fault::DutyCeiling),
            Some(Fault::Bridge(Line::NFault)),
            Some(Fault::Bridge(Line::Break)),
        ] {
            let r = Retained {
                theta_d_deg: 123.5,
                last_fault: f,
            };
            assert_eq!(decode(encode(&r)), Some(r));
        }
        let good = encode(&Retained {
            theta_d_deg: 10.0,
            last_fault: Some(Fault::Sensor),
        });
        // Any one flipped bit is refused (CRC-32C detects every 1-bit error).
        for i in 0..128 {
            let mut w = good;
            w[i / 32] ^= 1 << (i % 32);
            assert_eq!(decode(w), None, "bit {i}");
        }
        assert_eq!(decode([0; 4]), None);
        assert_eq!(decode([0xFFFF_FFFF; 4]), None);
    }
}
