//! The STM32G4's user option bytes as FLASH_OPTR shows them (RM0440 §5.7.8): read-out
//! protection, which blocks the probe from flash, and the dual-bank layout the firmware is
//! linked for (embassy-stm32's `dual-bank` feature, 2 KiB pages).

use anyhow::Result;
use serde::Serialize;

use super::board::Board;
use crate::rig::{Exit, Failure};

/// FLASH_OPTR: the FLASH registers at 0x4002_2000 (RM0440 §2.2.2, memory map), OPTR at offset 0x20
/// (RM0440 §5.7.8).
pub const FLASH_OPTR: u64 = 0x4002_2020;

/// DBANK, FLASH_OPTR bit 22 (RM0440 §5.7.8): 1 = two banks of 256 KiB, 2 KiB pages.
const DBANK: u32 = 1 << 22;

/// What FLASH_OPTR says.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct OptionBytes {
    /// The register as read.
    pub optr: u32,
    /// RDP (bits 7:0, RM0440 §5.7.8; the levels in §5.5): 0xAA level 0, 0xCC level 2, anything else
    /// level 1.
    pub rdp_level: u8,
    pub dbank: bool,
}

impl OptionBytes {
    pub fn decode(optr: u32) -> Self {
        let rdp_level = match optr & 0xFF {
            0xAA => 0,
            0xCC => 2,
            _ => 1,
        };
        Self {
            optr,
            rdp_level,
            dbank: optr & DBANK != 0,
        }
    }

    /// One line for the report.
    pub fn text(&self) -> String {
        format!(
            "option bytes: FLASH_OPTR {:#010x}, read-out protection level {}, {}",
            self.optr,
            self.rdp_level,
            if self.dbank {
                "dual bank (DBANK = 1)"
            } else {
                "single bank (DBANK = 0)"
            }
        )
    }

    /// Refuses a chip the firmware cannot be flashed onto as it is, saying how to fix it.
    pub fn check(&self) -> Result<()> {
        let why = match (self.rdp_level, self.dbank) {
            (2, _) => format!(
                "read-out protection is level 2 (FLASH_OPTR {:#010x}): the chip is locked for \
                 good, its debug port closed; no tool can flash it. Replace the board (or the \
                 STM32G474RE)",
                self.optr
            ),
            (1, _) => format!(
                "read-out protection is level 1 (FLASH_OPTR {:#010x}): the probe may not read or \
                 write flash. Setting level 0 erases the whole flash, the stored configuration \
                 included: with STM32CubeProgrammer, `STM32_Programmer_CLI -c port=SWD mode=UR \
                 -ob RDP=0xAA` (or Option bytes → Read Out Protection → AA, Apply); then flash \
                 again",
                self.optr
            ),
            (_, false) => format!(
                "the flash is in single-bank mode (DBANK = 0, FLASH_OPTR {:#010x}) and the \
                 firmware is built for dual bank (2 KiB pages, the configuration area at the \
                 end of bank 2). Set DBANK = 1 with STM32CubeProgrammer, `STM32_Programmer_CLI -c \
                 port=SWD mode=UR -ob DBANK=1` (or Option bytes → User Configuration → DBANK \
                 ticked, Apply), then flash again; the stored configuration does not survive the \
                 change",
                self.optr
            ),
            (_, true) => return Ok(()),
        };
        Err(Failure::new(Exit::Refused, format!("{why}; nothing was written")).into())
    }
}

/// Reads and decodes FLASH_OPTR.
pub fn read(board: &mut dyn Board) -> Result<OptionBytes> {
    Ok(OptionBytes::decode(board.read_word(FLASH_OPTR)?))
}
