//! The configuration area in flash: two erase pages, A/B, each holding at most one record
//! ([`super::encode`]), behind `embedded-storage`'s [`NorFlash`] so that the firmware (on the
//! chip's flash) and the host's tests (on a model that loses power mid-word) run this code.
//!
//! ```text
//! load:   read both pages; the intact record with the newest sequence wins
//!         (newer(a, b) ⇔ (a − b) mod 2³² ∈ [1, 2³¹): wrapping-safe); a record of a format
//!         without a sequence (3 and older) is older than any with one
//! store:  s = newest + 1; erase the page NOT holding the newest intact record, program the
//!         record with sequence s, read it back
//! ```
//! A store never touches the page holding the newest intact record, so a power cut at any
//! word leaves it as it was; the page being written then holds either the whole new record
//! (which wins: its sequence is newer) or one whose CRC fails (which loses). Reads that the
//! flash refuses (a double ECC error in a half-programmed word) count as a corrupt page.
//!
//! Why a small A/B scheme and no log-structured crate (`sequential-storage`): there is one
//! record of a few hundred bytes, written only when a `SetConfig` changes it, and two 2 KiB
//! pages are the smallest area that always keeps a copy; a log's wear levelling buys nothing
//! at that rate (the G4 endures 10 000 cycles a page: DS12288 "Flash memory endurance") and
//! would cost flash for its code.

use embedded_storage::nor_flash::NorFlash;
use embedded_storage::nor_flash::ReadNorFlash;

use super::{encode, read, settle, Fallback, Record, RECORD_MAX};
use crate::link::origin::ConfigOrigin;
use crate::rig::config::RigConfig;

/// Two flash pages of `size / 2` bytes each, from `offset` (from the flash's start).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Area {
    pub offset: u32,
    /// Both pages together.
    pub size: u32,
}

impl Area {
    /// Page `i` (0 or 1): its offset.
    pub const fn page(&self, i: usize) -> u32 {
        self.offset + i as u32 * (self.size / 2)
    }
}

/// What a page holds: an intact record, or why not.
pub type Page = Result<Record, Fallback>;

/// Why a store did not reach flash.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StoreError {
    /// Erasing the page failed.
    Erase,
    /// Programming the record failed.
    Program,
    /// The record could not be read back, or read back different.
    ReadBack,
}

/// `a` is a newer sequence than `b`.
pub fn newer(a: Option<u32>, b: Option<u32>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => (a.wrapping_sub(b) as i32) > 0,
        (Some(_), None) => true,
        (None, _) => false,
    }
}

/// Both pages of `area`.
pub fn scan<F: ReadNorFlash>(flash: &mut F, area: &Area) -> [Page; 2] {
    core::array::from_fn(|i| {
        let mut buf = [0u8; RECORD_MAX];
        match flash.read(area.page(i), &mut buf) {
            Ok(()) => read(&buf),
            Err(_) => Err(Fallback::Corrupt),
        }
    })
}

/// The pages holding an intact record, the newest first.
fn by_age(pages: &[Page; 2]) -> [Option<usize>; 2] {
    match (&pages[0], &pages[1]) {
        (Ok(a), Ok(b)) if newer(b.seq, a.seq) => [Some(1), Some(0)],
        (Ok(_), Ok(_)) => [Some(0), Some(1)],
        (Ok(_), Err(_)) => [Some(0), None],
        (Err(_), Ok(_)) => [Some(1), None],
        (Err(_), Err(_)) => [None, None],
    }
}

/// The configuration to run on, and where it came from ([`super::load`]'s semantics): the
/// newest intact record's, repaired if need be; the older one's if the newest cannot be
/// repaired; else the safe defaults, with the more telling of the two pages' reasons
/// (another format, then damage, then nothing stored).
pub fn load<F: ReadNorFlash>(flash: &mut F, area: &Area) -> (RigConfig, ConfigOrigin) {
    let pages = scan(flash, area);
    let mut refused = None;
    for i in by_age(&pages).into_iter().flatten() {
        if let Ok(r) = &pages[i] {
            match settle(r.cfg) {
                (_, o @ ConfigOrigin::Defaults(_)) => refused = refused.or(Some(o)),
                good => return good,
            }
        }
    }
    let rank = |f: &Fallback| match f {
        Fallback::Missing => 0,
        Fallback::Corrupt => 1,
        Fallback::Incompatible { .. } | Fallback::Invalid { .. } => 2,
    };
    let origin = refused.unwrap_or_else(|| {
        let reason = match (&pages[0], &pages[1]) {
            (Err(a), Err(b)) if rank(b) > rank(a) => *b,
            (Err(a), _) => *a,
            (_, Err(b)) => *b,
            _ => Fallback::Corrupt,
        };
        ConfigOrigin::Defaults(reason)
    });
    (RigConfig::REFERENCE, origin)
}

/// Power-up: [`load`], or, with the e-stop held ([`estop_held`]), the safe defaults without
/// reading or writing the flash (so a stored configuration that upsets the rig can be got
/// round, and is still there at the next power-up).
pub fn boot<F: ReadNorFlash>(flash: &mut F, area: &Area, estop: bool) -> (RigConfig, ConfigOrigin) {
    if estop {
        (RigConfig::REFERENCE, ConfigOrigin::DefaultsByEstop)
    } else {
        load(flash, area)
    }
}

/// Readings of the e-stop line at power-up, taken [`ESTOP_BOOT_READINGS`] times 1 ms apart.
pub const ESTOP_BOOT_READINGS: usize = 10;

/// The e-stop is held at power-up: every one of at least [`ESTOP_BOOT_READINGS`] readings says
/// pressed (`true`). A spike on the line never costs the stored configuration; a pressed
/// mushroom switch reads steady (its bounce is on release, `crate::rig::estop`).
pub fn estop_held(readings: impl IntoIterator<Item = bool>) -> bool {
    let mut n = 0;
    for pressed in readings {
        if !pressed {
            return false;
        }
        n += 1;
    }
    n >= ESTOP_BOOT_READINGS
}

/// Stores `cfg` as the newest record; returns its sequence number. On any error the newest
/// record before the call is still intact (the page it is in was not touched).
pub fn store<F: NorFlash>(flash: &mut F, area: &Area, cfg: &RigConfig) -> Result<u32, StoreError> {
    let pages = scan(flash, area);
    let newest = by_age(&pages)[0];
    let seq = newest
        .and_then(|i| pages[i].as_ref().ok())
        .and_then(|r| r.seq)
        .map_or(1, |s| s.wrapping_add(1));
    let target = area.page(match newest {
        Some(0) => 1,
        _ => 0,
    });
    let mut buf = [0u8; RECORD_MAX];
    let n = encode(cfg, seq, &mut buf).next_multiple_of(F::WRITE_SIZE.max(1));
    if n > RECORD_MAX || area.size / 2 < RECORD_MAX as u32 {
        return Err(StoreError::Program);
    }
    flash
        .erase(target, target + area.size / 2)
        .map_err(|_| StoreError::Erase)?;
    flash
        .write(target, &buf[..n])
        .map_err(|_| StoreError::Program)?;
    let mut back = [0u8; RECORD_MAX];
    match flash.read(target, &mut back[..n]) {
        Ok(()) if back[..n] == buf[..n] => Ok(seq),
        _ => Err(StoreError::ReadBack),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequences_compare_across_the_wrap() {
        assert!(newer(Some(1), Some(0)));
        assert!(newer(Some(0), Some(u32::MAX)));
        assert!(!newer(Some(u32::MAX), Some(0)));
        assert!(!newer(Some(5), Some(5)));
        assert!(newer(Some(0), None));
        assert!(!newer(None, Some(0)));
        assert!(!newer(None, None));
    }

    #[test]
    fn the_estop_counts_as_held_only_when_every_reading_says_so() {
        assert!(estop_held([true; ESTOP_BOOT_READINGS]));
        assert!(!estop_held([true; ESTOP_BOOT_READINGS - 1]));
        let mut r = [true; ESTOP_BOOT_READINGS];
        r[4] = false;
        assert!(!estop_held(r));
        assert!(!estop_held([false; ESTOP_BOOT_READINGS]));
    }
}
