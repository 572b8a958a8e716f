//! Where the rig's configuration in use came from, and why a stored one was not used: reported
//! in the status, so it is a wire type (pinned by the golden frames); the flash record
//! ([`crate::persist`]) decides it.

use postcard::experimental::max_size::MaxSize;
use serde::{Deserialize, Serialize};

use super::reason::ConfigField;

/// Why the stored configuration was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fallback {
    /// Nothing stored (the page is erased).
    Missing,
    /// Something is stored but its magic, length or checksum is wrong.
    Corrupt,
    /// A record of another format version (`version`).
    Incompatible { version: u16 },
    /// The record is intact but its configuration is out of range.
    Invalid { field: ConfigField },
}

/// A set of configuration fields, one bit per [`ConfigField`] (bit `field as u32`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FieldSet(pub u64);

impl FieldSet {
    pub const EMPTY: Self = Self(0);

    pub fn contains(self, f: ConfigField) -> bool {
        self.0 & (1 << f as u32) != 0
    }

    pub fn insert(&mut self, f: ConfigField) {
        self.0 |= 1 << f as u32;
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The fields in the set, in [`ConfigField::ALL`]'s order.
    pub fn iter(self) -> impl Iterator<Item = ConfigField> {
        ConfigField::ALL
            .into_iter()
            .filter(move |&f| self.contains(f))
    }
}

/// Where the configuration in use came from (reported in the status).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, MaxSize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigOrigin {
    /// Loaded from flash at power-up.
    Stored,
    /// Loaded from flash at power-up, but these fields were out of range: they run at their
    /// safe defaults ([`crate::rig::config::RigConfig::REFERENCE`]'s), the rest (the calibration
    /// above all) as stored.
    Repaired { defaulted: FieldSet },
    /// The stored one was unusable: running on the safe defaults ([`crate::rig::config::RigConfig::REFERENCE`]).
    Defaults(Fallback),
    /// Set over the link since power-up; `saved` says whether it reached flash.
    Received { saved: bool },
    /// The e-stop was held at power-up: running on the safe defaults, the stored configuration
    /// neither read nor erased (it loads at the next power-up without the e-stop).
    DefaultsByEstop,
}
