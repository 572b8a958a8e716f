//! A board that does not answer on serial after flashing: the core halted through the probe,
//! its program counter looked up in the image's symbols, and where it waits said in words.
//! The clock is checked in RCC_CR as well, since the release build inlines embassy-stm32's RCC
//! set-up into its callers.

use anyhow::Result;
use object::{Object, ObjectSymbol, SymbolKind};
use serde::Serialize;

use super::board::Board;

/// RCC_CR: RCC at 0x4002_1000 (RM0440 §2.2.2), CR at offset 0 (RM0440 §7.4.1).
pub const RCC_CR: u64 = 0x4002_1000;
/// RCC_CR bit 16 HSEON, bit 17 HSERDY (RM0440 §7.4.1).
const HSEON: u32 = 1 << 16;
const HSERDY: u32 = 1 << 17;

/// Where the core was found.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Diagnosis {
    pub pc: u64,
    /// The function of the image holding `pc`, demangled.
    pub symbol: Option<String>,
    /// RCC_CR as read (None if the read failed).
    pub rcc_cr: Option<u32>,
    pub cause: Cause,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Cause {
    /// HSE switched on and not ready: embassy-stm32 waits for HSERDY for ever.
    HseNotStarting,
    /// In the panic handler.
    Panic,
    /// In the HardFault handler.
    HardFault,
    /// In cortex-m-rt's handler for an interrupt without its own.
    DefaultHandler,
    /// Somewhere else in the image.
    Elsewhere,
    /// Outside every function of the image.
    Unknown,
}

impl Diagnosis {
    pub fn text(&self) -> String {
        let at = match &self.symbol {
            Some(s) => format!("pc {:#010x}, in {s}", self.pc),
            None => format!("pc {:#010x}", self.pc),
        };
        match self.cause {
            Cause::HseNotStarting => format!(
                "the core waits in embassy-stm32's RCC init for the HSE to be ready ({at}; \
                 RCC_CR HSEON set, HSERDY clear): no crystal / HSE not starting: check X3 and \
                 the SB jumpers (docs/hardware.md, \"The clock\")"
            ),
            Cause::Panic => format!(
                "the firmware panicked ({at}): its defmt log says why (`probe-rs attach \
                 --chip STM32G474RETx` with the ELF)"
            ),
            Cause::HardFault => format!(
                "the core is in the HardFault handler ({at}): a memory or bus fault; the \
                 defmt log and `probe-rs attach` show the stacked registers"
            ),
            Cause::DefaultHandler => format!(
                "the core is in the default interrupt handler ({at}): an interrupt fired that \
                 the firmware did not bind"
            ),
            Cause::Elsewhere => format!("the core runs but does not answer: {at}"),
            Cause::Unknown => format!(
                "the core is at {at}, outside every function of the image: is this the image \
                 that was flashed?"
            ),
        }
    }
}

/// Halts the core, reads where it is and the clock state, and lets it run on.
pub fn diagnose(board: &mut dyn Board, elf: &[u8]) -> Result<Diagnosis> {
    let pc = board.halt_pc()?;
    let rcc_cr = board.read_word(RCC_CR).ok();
    let resumed = board.resume();
    let symbol = symbol_at(elf, pc);
    let diagnosis = Diagnosis {
        pc,
        cause: cause(symbol.as_deref(), rcc_cr),
        symbol,
        rcc_cr,
    };
    resumed?;
    Ok(diagnosis)
}

fn cause(symbol: Option<&str>, rcc_cr: Option<u32>) -> Cause {
    let hse_waits = match rcc_cr {
        Some(cr) => cr & HSEON != 0 && cr & HSERDY == 0,
        None => symbol.is_some_and(|s| s.contains("embassy_stm32::rcc")),
    };
    if hse_waits {
        return Cause::HseNotStarting;
    }
    let Some(s) = symbol else {
        return Cause::Unknown;
    };
    let last = s.rsplit("::").next().unwrap_or(s);
    if last.contains("HardFault") {
        Cause::HardFault
    } else if s.contains("panic") || s == "rust_begin_unwind" {
        Cause::Panic
    } else if last.contains("DefaultHandler") {
        Cause::DefaultHandler
    } else {
        Cause::Elsewhere
    }
}

/// The demangled name of the function in `elf` whose range holds `pc` (Thumb bit ignored).
pub fn symbol_at(elf: &[u8], pc: u64) -> Option<String> {
    let file = object::File::parse(elf).ok()?;
    let pc = pc & !1;
    file.symbols()
        .filter(|s| s.kind() == SymbolKind::Text && s.size() > 0)
        .find(|s| {
            let start = s.address() & !1;
            start <= pc && pc < start + s.size()
        })
        .and_then(|s| s.name().ok().map(demangle))
}

/// Rust's legacy mangling (`_ZN` length-prefixed parts `E`, the last a hash `h…`) as a path;
/// any other name as it is.
pub fn demangle(name: &str) -> String {
    let Some(mut rest) = name.strip_prefix("_ZN") else {
        return name.to_string();
    };
    let mut parts = Vec::new();
    while !rest.starts_with('E') {
        let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
        let Ok(len) = rest[..digits].parse::<usize>() else {
            return name.to_string();
        };
        let Some(part) = rest.get(digits..digits + len) else {
            return name.to_string();
        };
        parts.push(part);
        rest = &rest[digits + len..];
    }
    if parts
        .last()
        .is_some_and(|p| p.len() == 17 && p.starts_with('h'))
    {
        parts.pop();
    }
    parts
        .iter()
        .map(|p| {
            p.replace("$LT$", "<")
                .replace("$GT$", ">")
                .replace("..", "::")
        })
        .collect::<Vec<_>>()
        .join("::")
}
