//! Where the firmware may live: the FLASH and RAM regions of the repository's `memory.x` (the
//! linker's own map, compiled in) and the configuration area the firmware keeps at the end of
//! flash, two 2 KiB pages (from the address `firmware/persist.x` asserts the program image stays
//! below).

use std::ops::Range;

use anyhow::{bail, Context, Result};
use serde::Serialize;

/// The linker memory map the firmware is linked with.
const MEMORY_X: &str = include_str!("../../../memory.x");
/// The link-time check that keeps the program image out of the configuration page.
const PERSIST_X: &str = include_str!("../../../firmware/persist.x");

/// One address range, `start..end`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Region {
    pub start: u64,
    pub end: u64,
}

impl Region {
    pub fn len(&self) -> u64 {
        self.end - self.start
    }

    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }

    pub fn contains(&self, r: &Range<u64>) -> bool {
        self.start <= r.start && r.end <= self.end
    }

    pub fn overlaps(&self, r: &Range<u64>) -> bool {
        r.start < self.end && self.start < r.end
    }
}

/// The regions an image is checked against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct MemoryMap {
    pub flash: Region,
    pub ram: Region,
    /// Kept by the firmware for its stored configuration (both pages of its store); flashing
    /// never touches it.
    pub config_page: Region,
}

impl MemoryMap {
    /// The firmware's map: `memory.x` and `persist.x` as this tool was built with them.
    pub fn firmware() -> Self {
        Self::parse(MEMORY_X, PERSIST_X).expect("memory.x and persist.x parse")
    }

    /// Parses a linker `MEMORY` block (regions FLASH and RAM) and the configuration page's
    /// start, the one address `persist.x` names; the page runs from there to the end of FLASH.
    pub fn parse(memory_x: &str, persist_x: &str) -> Result<Self> {
        let text = strip_comments(memory_x);
        let flash = region(&text, "FLASH")?;
        let ram = region(&text, "RAM")?;
        let start = config_page_start(persist_x)?;
        if !(flash.start < start && start < flash.end) {
            bail!("the configuration page's start {start:#010x} is not inside FLASH");
        }
        Ok(Self {
            flash,
            ram,
            config_page: Region {
                start,
                end: flash.end,
            },
        })
    }

    /// The flash a program image may use: FLASH up to the configuration page.
    pub fn program_flash(&self) -> Region {
        Region {
            start: self.flash.start,
            end: self.config_page.start,
        }
    }
}

fn strip_comments(s: &str) -> String {
    let mut out = String::new();
    let mut rest = s;
    while let Some(i) = rest.find("/*") {
        out.push_str(&rest[..i]);
        rest = rest[i + 2..]
            .find("*/")
            .map_or("", |j| &rest[i + 2 + j + 2..]);
    }
    out.push_str(rest);
    out
}

/// `NAME : ORIGIN = 0x…, LENGTH = 512K` (attributes in parentheses after the name allowed).
fn region(text: &str, name: &str) -> Result<Region> {
    let line = text
        .lines()
        .map(str::trim)
        .find(|l| {
            l.strip_prefix(name)
                .is_some_and(|r| r.trim_start().starts_with([':', '(']))
        })
        .with_context(|| format!("memory.x has no {name} region"))?;
    let field = |key: &str| -> Result<u64> {
        let at = line
            .find(key)
            .with_context(|| format!("memory.x: {name} has no {key}"))?;
        let value = line[at + key.len()..]
            .trim_start()
            .trim_start_matches('=')
            .trim_start();
        let end = value.find([',', ' ', ';']).unwrap_or(value.len());
        number(&value[..end]).with_context(|| format!("memory.x: {name}'s {key}"))
    };
    let start = field("ORIGIN")?;
    let len = field("LENGTH")?;
    Ok(Region {
        start,
        end: start + len,
    })
}

/// A linker-script number: decimal or 0x hex, with an optional K or M suffix.
fn number(s: &str) -> Result<u64> {
    let (digits, scale) = match s.chars().last() {
        Some('K' | 'k') => (&s[..s.len() - 1], 1024),
        Some('M' | 'm') => (&s[..s.len() - 1], 1024 * 1024),
        _ => (s, 1),
    };
    let n = match digits.strip_prefix("0x").or(digits.strip_prefix("0X")) {
        Some(hex) => u64::from_str_radix(hex, 16)?,
        None => digits.parse()?,
    };
    Ok(n * scale)
}

/// The single address `persist.x` compares the image's end against (outside comments and the
/// message string).
fn config_page_start(persist_x: &str) -> Result<u64> {
    let code: String = strip_comments(persist_x)
        .split('"')
        .step_by(2)
        .collect::<Vec<_>>()
        .join(" ");
    let mut found: Vec<u64> = code
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| w.starts_with("0x") || w.starts_with("0X"))
        .map(number)
        .collect::<Result<_>>()?;
    found.dedup();
    match found.as_slice() {
        [one] => Ok(*one),
        _ => bail!("persist.x should name one configuration-page address, found {found:x?}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The NUCLEO-G474RE's map (RM0440: 512 KiB flash at 0x0800_0000, 128 KiB SRAM at
    /// 0x2000_0000) and the last two 2 KiB pages for the configuration.
    #[test]
    fn the_firmware_map_is_the_g474s() {
        let m = MemoryMap::firmware();
        assert_eq!(
            m.flash,
            Region {
                start: 0x0800_0000,
                end: 0x0808_0000
            }
        );
        assert_eq!(
            m.ram,
            Region {
                start: 0x2000_0000,
                end: 0x2002_0000
            }
        );
        assert_eq!(
            m.config_page,
            Region {
                start: 0x0807_F000,
                end: 0x0808_0000
            }
        );
    }

    /// The area persist.x guards is the one the firmware writes (`board::CONFIG_PAGE_OFFSET`
    /// and `CONFIG_PAGE_SIZE`, read from the board file).
    #[test]
    fn the_config_page_is_the_boards() {
        let board = include_str!("../../../firmware/src/board/nucleo_g474re.rs");
        let constant = |name: &str| -> u64 {
            let line = board
                .lines()
                .find(|l| l.contains(&format!("const {name}:")))
                .unwrap();
            let v = line.split('=').nth(1).unwrap().trim().trim_end_matches(';');
            number(&v.replace('_', "")).unwrap()
        };
        let m = MemoryMap::firmware();
        assert_eq!(
            m.config_page.start - m.flash.start,
            constant("CONFIG_PAGE_OFFSET")
        );
        assert_eq!(m.config_page.len(), constant("CONFIG_PAGE_SIZE"));
    }

    #[test]
    fn numbers_and_attributes() {
        let m = MemoryMap::parse(
            "MEMORY {\n FLASH (rx) : ORIGIN = 0x0, LENGTH = 1M /* x */\n RAM : ORIGIN = 536870912, LENGTH = 0x100\n}",
            "ASSERT(x <= 0xFF000, \"0x1 in a message\");",
        )
        .unwrap();
        assert_eq!(m.flash.len(), 1 << 20);
        assert_eq!(
            m.ram,
            Region {
                start: 0x2000_0000,
                end: 0x2000_0100
            }
        );
        assert_eq!(m.config_page.start, 0xFF000);
    }

    #[test]
    fn a_missing_region_is_named() {
        let e = MemoryMap::parse("MEMORY {\n  FLASH : ORIGIN = 0, LENGTH = 1K\n}", "0x10")
            .unwrap_err()
            .to_string();
        assert!(e.contains("RAM"), "{e}");
    }
}
