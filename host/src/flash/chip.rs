//! `--chip`: the target in probe-rs's built-in registry, checked against memory.x before the
//! board is touched, and against the device ID the board reports once attached.

use std::ops::Range;

use anyhow::Result;
use probe_rs::config::{MemoryRegion, Registry};
use probe_rs::Target;

use super::memory_map::{MemoryMap, Region};
use crate::rig::{Exit, Failure};

/// The NUCLEO-G474RE's microcontroller, as probe-rs names it.
pub const DEFAULT_CHIP: &str = "STM32G474RETx";

/// Where an STM32G4 reports its device ID: DBGMCU_IDCODE (RM0440 §46.6.1), DEV_ID in bits 11:0.
pub const DBGMCU_IDCODE: u64 = 0xE004_2000;

fn refused(msg: String) -> anyhow::Error {
    Failure::new(Exit::Refused, msg).into()
}

/// The chip named `name`, or an error with the nearest names probe-rs knows.
pub fn resolve(name: &str) -> Result<Target> {
    let registry = Registry::from_builtin_families();
    registry.get_target_by_name(name).map_err(|_| {
        let mut near = registry.search_chips(name);
        near.dedup();
        let hint = match near.len() {
            0 => {
                format!("probe-rs knows no such chip; the board's is {DEFAULT_CHIP} (the default)")
            }
            n => format!(
                "it matches {n} chips ({}{}); name one exactly, the board's is {DEFAULT_CHIP}",
                near[..n.min(6)].join(", "),
                if n > 6 { ", …" } else { "" }
            ),
        };
        refused(format!("unknown chip {name:?}: {hint}"))
    })
}

/// Refuses a chip whose flash and RAM do not hold memory.x's FLASH and RAM: the image was
/// linked for another chip.
pub fn check_memory(target: &Target, map: &MemoryMap) -> Result<()> {
    let nvm = ranges(target, |r| matches!(r, MemoryRegion::Nvm(_)));
    let ram = ranges(target, |r| matches!(r, MemoryRegion::Ram(_)));
    for (what, region, have) in [("flash", map.flash, &nvm), ("RAM", map.ram, &ram)] {
        if !covered(region, have) {
            return Err(refused(format!(
                "wrong chip: {} has no {what} at {:#010x}..{:#010x}, where memory.x puts it \
                 (its {what}: {}); the firmware is built for {DEFAULT_CHIP}",
                target.name,
                region.start,
                region.end,
                list(have)
            )));
        }
    }
    Ok(())
}

/// The address ranges of the chip's memory regions of one kind.
fn ranges(target: &Target, kind: impl Fn(&MemoryRegion) -> bool) -> Vec<Range<u64>> {
    target
        .memory_map
        .iter()
        .filter(|r| kind(r))
        .map(|r| r.address_range())
        .collect()
}

/// Whether `ranges` together cover `region` without a gap.
fn covered(region: Region, ranges: &[Range<u64>]) -> bool {
    let mut sorted = ranges.to_vec();
    sorted.sort_by_key(|r| r.start);
    let mut reached = region.start;
    for r in sorted {
        if r.start <= reached && r.end > reached {
            reached = r.end;
        }
    }
    reached >= region.end
}

fn list(ranges: &[Range<u64>]) -> String {
    if ranges.is_empty() {
        return "none".into();
    }
    ranges
        .iter()
        .map(|r| format!("{:#010x}..{:#010x}", r.start, r.end))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The DEV_ID an STM32G4 chip reports (RM0440 §46.6.1: 0x469 for the STM32G47x/G48x
/// category 3 devices), or None for chips this tool does not know the ID of.
pub fn expected_dev_id(chip: &str) -> Option<u16> {
    let c = chip.to_ascii_uppercase();
    (c.starts_with("STM32G47") || c.starts_with("STM32G48")).then_some(0x469)
}

/// Refuses a board whose device ID is not the chip's (`idcode`: DBGMCU_IDCODE as read).
pub fn check_dev_id(chip: &str, idcode: u32) -> Result<()> {
    let Some(want) = expected_dev_id(chip) else {
        return Ok(());
    };
    let got = (idcode & 0xFFF) as u16;
    if got == want {
        return Ok(());
    }
    Err(refused(format!(
        "wrong chip: the board reports device ID {got:#05x}, and {chip} is {want:#05x}; nothing \
         was written. Is this a NUCLEO-G474RE? Name its chip with --chip"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_chip_holds_the_firmware_map() {
        let t = resolve(DEFAULT_CHIP).unwrap();
        check_memory(&t, &MemoryMap::firmware()).unwrap();
    }

    #[test]
    fn gaps_are_not_covered() {
        let r = Region { start: 0, end: 10 };
        assert!(covered(r, &[5..10, 0..5]));
        assert!(!covered(r, &[0..4, 5..10]));
        assert!(!covered(r, &[0..9, 20..30]));
    }

    /// 0x469 (RM0440) in the low 12 bits; REV_ID in the high half is ignored.
    #[test]
    fn device_id() {
        check_dev_id(DEFAULT_CHIP, 0x2000_6469).unwrap();
        let e = check_dev_id(DEFAULT_CHIP, 0x1000_6413)
            .unwrap_err()
            .to_string();
        assert!(e.contains("0x413") && e.contains("0x469"), "{e}");
        check_dev_id("nRF52840_xxAA", 0x1234).unwrap();
    }
}
