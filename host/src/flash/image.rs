//! The firmware image, checked before any probe is touched: a 32-bit little-endian ARM ELF
//! whose loadable segments fit memory.x's FLASH (below the configuration page) and RAM, with a
//! Cortex-M vector table at the start of flash (initial stack pointer in RAM, reset handler a
//! Thumb address in flash) and the entry point in flash.

use std::ops::Range;
use std::path::Path;

use anyhow::{Context, Result};
use object::elf::{EM_ARM, EM_RISCV, EM_X86_64, PT_LOAD};
use object::read::elf::{ElfFile32, FileHeader, ProgramHeader};
use object::{Endianness, FileKind, Object, ObjectSection};
use serde::Serialize;

use super::memory_map::{MemoryMap, Region};
use crate::rig::{Exit, Failure};

/// One run of bytes written to flash.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Write {
    /// Flash address (the segment's load address).
    pub address: u64,
    pub size: u64,
    /// Where the program sees it, when that is not where it is stored (`.data`: copied to RAM
    /// at start-up).
    pub runs_at: Option<u64>,
    /// The ELF sections it holds.
    pub sections: Vec<String>,
}

/// Use of one memory region.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Usage {
    pub region: Region,
    pub used: u64,
    /// `used` over the region's length.
    pub fraction: f64,
}

/// What flashing the image would do: the check's result, and `--dry-run`'s report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plan {
    pub entry: u64,
    pub writes: Vec<Write>,
    /// Bytes written, against all of FLASH (configuration page included).
    pub flash: Usage,
    /// Static RAM (`.data`, `.bss`, `.uninit`) against RAM; the stack takes what is left.
    pub ram: Usage,
    /// Never written.
    pub config_page: Region,
}

/// A loadable segment as read from the program headers.
#[derive(Debug, Clone, Copy)]
struct Segment {
    vaddr: u64,
    paddr: u64,
    file_size: u64,
    mem_size: u64,
}

fn refused(msg: String) -> anyhow::Error {
    Failure::new(Exit::Refused, msg).into()
}

/// Reads and checks the ELF at `path` against `map`.
pub fn check_file(path: &Path, map: &MemoryMap) -> Result<Plan> {
    let data = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    check(&data, map).with_context(|| format!("{}: not flashed", path.display()))
}

/// Checks an ELF image against `map`.
pub fn check(data: &[u8], map: &MemoryMap) -> Result<Plan> {
    let elf =
        match FileKind::parse(data) {
            Ok(FileKind::Elf32) => ElfFile32::<Endianness>::parse(data)?,
            Ok(FileKind::Elf64) => {
                return Err(refused(format!(
                "a 64-bit ELF for {}, not the firmware: the board needs the thumbv7em-none-eabihf \
                 build (run `kapitza flash` without an ELF to build it)",
                machine_name(elf64_machine(data))
            )))
            }
            _ => return Err(refused(
                "not an ELF file: give the firmware's ELF (firmware/target/thumbv7em-none-eabihf/\
                 release/kapitza-firmware), or no file to build it"
                    .into(),
            )),
        };
    let endian = elf.endian();
    let header = elf.elf_header();
    let machine = header.e_machine(endian);
    if machine != EM_ARM || !header.is_little_endian() {
        return Err(refused(format!(
            "an ELF for {}, not for the board's Cortex-M4 (32-bit little-endian ARM): build the \
             firmware for thumbv7em-none-eabihf",
            machine_name(machine)
        )));
    }
    let segments: Vec<Segment> = elf
        .elf_program_headers()
        .iter()
        .filter(|p| p.p_type(endian) == PT_LOAD && p.p_memsz(endian) > 0)
        .map(|p| Segment {
            vaddr: p.p_vaddr(endian).into(),
            paddr: p.p_paddr(endian).into(),
            file_size: p.p_filesz(endian).into(),
            mem_size: p.p_memsz(endian).into(),
        })
        .collect();
    if segments.iter().all(|s| s.file_size == 0) {
        return Err(refused(
            "the ELF has nothing to load (no loadable segment with data)".into(),
        ));
    }
    let program = map.program_flash();
    let mut writes = Vec::new();
    let mut flash_used = 0;
    let mut ram_used = 0;
    for s in &segments {
        if s.file_size > 0 {
            let stored = s.paddr..s.paddr + s.file_size;
            if !map.flash.overlaps(&stored) || stored.start < map.flash.start {
                return Err(refused(format!(
                    "a segment is stored at {} , outside flash {}: this ELF was linked for \
                     another memory map",
                    range(&stored),
                    range(&as_range(map.flash))
                )));
            }
            if map.config_page.overlaps(&stored) || !map.flash.contains(&stored) {
                return Err(refused(format!(
                    "the image is too large: a segment stored at {} reaches the configuration \
                     page {} (the image may use {} bytes of flash, {} KiB)",
                    range(&stored),
                    range(&as_range(map.config_page)),
                    program.len(),
                    program.len() / 1024
                )));
            }
            flash_used += s.file_size;
            writes.push(Write {
                address: s.paddr,
                size: s.file_size,
                runs_at: (s.vaddr != s.paddr).then_some(s.vaddr),
                sections: sections_in(&elf, s.vaddr..s.vaddr + s.file_size),
            });
        }
        let runs = s.vaddr..s.vaddr + s.mem_size;
        if !map.flash.contains(&runs) {
            if !map.ram.contains(&runs) {
                return Err(refused(format!(
                    "the image needs RAM at {}, outside RAM {}: too large, or linked for another \
                     memory map",
                    range(&runs),
                    range(&as_range(map.ram))
                )));
            }
            ram_used += s.mem_size;
        }
    }
    writes.sort_by_key(|w| w.address);
    let entry = elf.entry();
    if !program.contains(&(entry..entry + 1)) {
        return Err(refused(format!(
            "the entry point {entry:#010x} is not in flash {}",
            range(&as_range(program))
        )));
    }
    check_vector_table(&elf, map)?;
    Ok(Plan {
        entry,
        writes,
        flash: usage(map.flash, flash_used),
        ram: usage(map.ram, ram_used),
        config_page: map.config_page,
    })
}

/// A Cortex-M boots from the vector table at the start of flash: word 0 is the initial stack
/// pointer (in RAM, or just past its end), word 1 the reset handler (a Thumb address, odd, in
/// flash). Read from the segment that is stored there.
fn check_vector_table(elf: &ElfFile32<Endianness>, map: &MemoryMap) -> Result<()> {
    let endian = elf.endian();
    let base = map.flash.start;
    let words = elf.elf_program_headers().iter().find_map(|p| {
        let start: u64 = p.p_paddr(endian).into();
        if p.p_type(endian) != PT_LOAD || start > base {
            return None;
        }
        let data = p.data(endian, elf.data()).ok()?;
        let at = usize::try_from(base - start).ok()?;
        let word = |i: usize| -> Option<u64> {
            let b = data.get(at + 4 * i..at + 4 * i + 4)?;
            Some(u32::from_le_bytes(b.try_into().ok()?).into())
        };
        Some((word(0)?, word(1)?))
    });
    let Some((sp, reset)) = words else {
        return Err(refused(format!(
            "no vector table at the start of flash ({base:#010x}): not a Cortex-M image for this \
             board"
        )));
    };
    let sp_ok = map.ram.start < sp && sp <= map.ram.end;
    let reset_ok = reset & 1 == 1 && map.program_flash().contains(&(reset - 1..reset));
    if !sp_ok || !reset_ok {
        return Err(refused(format!(
            "the vector table at {base:#010x} is not a Cortex-M one for this memory map (initial \
             stack pointer {sp:#010x}, reset handler {reset:#010x})"
        )));
    }
    Ok(())
}

fn sections_in(elf: &ElfFile32<Endianness>, r: Range<u64>) -> Vec<String> {
    elf.sections()
        .filter(|s| s.size() > 0 && r.start <= s.address() && s.address() < r.end)
        .filter_map(|s| s.name().ok().map(str::to_string))
        .collect()
}

fn usage(region: Region, used: u64) -> Usage {
    Usage {
        region,
        used,
        fraction: used as f64 / region.len() as f64,
    }
}

fn as_range(r: Region) -> Range<u64> {
    r.start..r.end
}

fn range(r: &Range<u64>) -> String {
    format!("{:#010x}..{:#010x}", r.start, r.end)
}

/// e_machine of a 64-bit ELF (offset 18, in the file's byte order).
fn elf64_machine(data: &[u8]) -> u16 {
    let b = [data[18], data[19]];
    if data[5] == 2 {
        u16::from_be_bytes(b)
    } else {
        u16::from_le_bytes(b)
    }
}

fn machine_name(m: u16) -> String {
    match m {
        EM_ARM => "32-bit ARM".into(),
        EM_X86_64 => "x86-64".into(),
        object::elf::EM_AARCH64 => "AArch64 (64-bit ARM)".into(),
        object::elf::EM_386 => "x86 (32-bit)".into(),
        EM_RISCV => "RISC-V".into(),
        other => format!("machine {other}"),
    }
}

impl Plan {
    /// The report `--dry-run` prints.
    pub fn text(&self) -> String {
        let mut s = String::new();
        for w in &self.writes {
            s += &format!(
                "write  {:#010x}..{:#010x}  {:>9}  {}{}\n",
                w.address,
                w.address + w.size,
                kib(w.size),
                w.sections.join(" "),
                w.runs_at
                    .map(|a| format!(" (copied to {a:#010x} at start-up)"))
                    .unwrap_or_default()
            );
        }
        s += &format!(
            "flash  {} of {} ({:.1} %); the configuration area {:#010x}..{:#010x} ({}, two pages) \
             is left as it is\n",
            kib(self.flash.used),
            kib(self.flash.region.len()),
            100.0 * self.flash.fraction,
            self.config_page.start,
            self.config_page.end,
            kib(self.config_page.len())
        );
        s += &format!(
            "ram    {} of {} static ({:.1} %); the stack has the rest\n",
            kib(self.ram.used),
            kib(self.ram.region.len()),
            100.0 * self.ram.fraction
        );
        s += &format!("entry  {:#010x}", self.entry);
        s
    }
}

fn kib(n: u64) -> String {
    format!("{:.1} KiB", n as f64 / 1024.0)
}
