//! Flashing the board from the laptop through a debug probe (probe-rs): the image is checked
//! against the firmware's memory map before any probe is touched.
//!
//! | module | concept |
//! |---|---|
//! | [`memory_map`] | memory.x's FLASH and RAM, and the configuration page kept free at the end of flash |
//! | [`image`] | the ELF checked (architecture, vector table, fits) and what would be written where |
//! | [`chip`] | `--chip` in probe-rs's registry, against memory.x and the board's device ID |
//! | [`probes`] | listing probes and choosing one (`--probe`); no probe, several, no permission |
//! | [`firmware_build`] | building the firmware in release when no ELF is given |
//! | [`board`] | the probe behind a trait (read, option bytes, halt and PC, erase), attach with a fall-back under reset |
//! | [`option_bytes`] | FLASH_OPTR: read-out protection and the dual-bank layout, refused with what to do |
//! | [`backup`] | the configuration area saved before flashing, `--erase-config`, `--restore-config` |
//! | [`program`] | erase, program, verify with a progress bar, reset |
//! | [`confirm`] | the board's virtual COM port and the link's version after flashing |
//! | [`diagnose`] | a silent board: where its core waits (HSE, panic, HardFault, a symbol) |

pub mod backup;
pub mod board;
pub mod chip;
pub mod confirm;
pub mod diagnose;
pub mod firmware_build;
pub mod image;
pub mod memory_map;
pub mod option_bytes;
pub mod probes;
pub mod program;
