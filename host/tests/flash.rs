//! `kapitza flash` and `kapitza probes` without hardware: the image checks on crafted ELF files
//! (written here with `object`'s ELF writer), `--dry-run`'s report, `--chip` refusals, probe
//! selection against a fake probe lister (none, several, no permission), and the version check
//! after flashing against a simulated rig that speaks another protocol.

use std::process::Output;
use std::time::Duration;

use clap::Parser;
use kapitza::cli::{Cli, Command as Sub};
use kapitza::flash::confirm;
use kapitza::rig::{Exit, Failure};
use kapitza_test_support::binary::Binary;
use object::elf::{EM_ARM, EM_X86_64, ET_EXEC, PF_R, PF_W, PF_X, PT_LOAD};
use object::write::elf::{FileHeader, ProgramHeader, Writer};
use object::Endianness;
use probe_rs::probe::list::{Accessibility, Lister, ProbeListItem, ProbeLister};
use probe_rs::probe::{
    DebugProbe, DebugProbeError, DebugProbeInfo, DebugProbeSelector, Probe, ProbeCreationError,
    ProbeFactory,
};
use serde_json::Value;

const FLASH: u64 = 0x0800_0000;
const RAM: u64 = 0x2000_0000;
/// memory.x: 512 KiB of flash, 128 KiB of RAM; persist.x: the configuration area starts at
/// 0x0807_F000 (the last two 2 KiB pages).
const FLASH_LEN: u64 = 512 * 1024;
const RAM_LEN: u64 = 128 * 1024;
const CONFIG_PAGE: u64 = 0x0807_F000;

/// One loadable segment of a crafted image: stored at `paddr`, run at `vaddr`, `file` bytes of
/// data and `mem` bytes in memory.
struct Seg {
    vaddr: u64,
    paddr: u64,
    data: Vec<u8>,
    mem: u64,
}

impl Seg {
    fn flash(addr: u64, data: Vec<u8>) -> Self {
        let mem = data.len() as u64;
        Self {
            vaddr: addr,
            paddr: addr,
            data,
            mem,
        }
    }
}

/// A Cortex-M vector table: initial SP at the end of RAM, reset handler at 0x0800_0101 (Thumb).
fn vectors() -> Vec<u8> {
    let mut v = Vec::new();
    v.extend_from_slice(&((RAM + RAM_LEN) as u32).to_le_bytes());
    v.extend_from_slice(&((FLASH + 0x101) as u32).to_le_bytes());
    v.resize(0x100, 0);
    v
}

/// An executable ELF with these segments (program headers only, no sections).
fn elf(machine: u16, is_64: bool, entry: u64, segs: &[Seg]) -> Vec<u8> {
    let mut buf = Vec::new();
    let mut w = Writer::new(Endianness::Little, is_64, &mut buf);
    w.reserve_file_header();
    w.reserve_program_headers(segs.len() as u32);
    let offsets: Vec<usize> = segs.iter().map(|s| w.reserve(s.data.len(), 8)).collect();
    w.write_file_header(&FileHeader {
        os_abi: 0,
        abi_version: 0,
        e_type: ET_EXEC,
        e_machine: machine,
        e_entry: entry,
        e_flags: 0x0500_0400,
    })
    .unwrap();
    w.write_align_program_headers();
    for (s, &off) in segs.iter().zip(&offsets) {
        w.write_program_header(&ProgramHeader {
            p_type: PT_LOAD,
            p_flags: PF_R | if s.vaddr == s.paddr { PF_X } else { PF_W },
            p_offset: off as u64,
            p_vaddr: s.vaddr,
            p_paddr: s.paddr,
            p_filesz: s.data.len() as u64,
            p_memsz: s.mem,
            p_align: 8,
        });
    }
    for s in segs {
        w.write_align(8);
        w.write(&s.data);
    }
    buf
}

/// A firmware-shaped image: vectors, 4 KiB of code, 256 B of .data (stored after the code,
/// copied to RAM), 1 KiB of .bss.
fn good_image() -> Vec<u8> {
    elf(
        EM_ARM,
        false,
        FLASH + 0x101,
        &[
            Seg::flash(FLASH, vectors()),
            Seg::flash(FLASH + 0x100, vec![0xAA; 4096]),
            Seg {
                vaddr: RAM,
                paddr: FLASH + 0x1100,
                data: vec![1; 256],
                mem: 256,
            },
            Seg {
                vaddr: RAM + 256,
                paddr: RAM + 256,
                data: vec![],
                mem: 1024,
            },
        ],
    )
}

fn write_temp(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> String {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p.to_str().unwrap().to_string()
}

const KAPITZA: Binary = Binary(env!("CARGO_BIN_EXE_kapitza"));

fn kapitza(args: &[&str]) -> Output {
    KAPITZA.run(args)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn dry_run_reports_what_goes_where() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_temp(&dir, "fw.elf", &good_image());
    let o = kapitza(&["flash", &path, "--dry-run", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let writes = v["writes"].as_array().unwrap();
    let at: Vec<(u64, u64)> = writes
        .iter()
        .map(|w| (w["address"].as_u64().unwrap(), w["size"].as_u64().unwrap()))
        .collect();
    // The three segments with data, by flash address; .bss writes nothing.
    assert_eq!(
        at,
        [(FLASH, 0x100), (FLASH + 0x100, 4096), (FLASH + 0x1100, 256)]
    );
    assert_eq!(writes[2]["runs_at"].as_u64(), Some(RAM));
    assert_eq!(v["flash"]["used"].as_u64(), Some(0x100 + 4096 + 256));
    let frac = v["flash"]["fraction"].as_f64().unwrap();
    assert!((frac - (0x100 + 4096 + 256) as f64 / FLASH_LEN as f64).abs() < 1e-12);
    // Static RAM: .data and .bss.
    assert_eq!(v["ram"]["used"].as_u64(), Some(256 + 1024));
    assert_eq!(v["ram"]["region"]["end"].as_u64(), Some(RAM + RAM_LEN));
    assert_eq!(v["config_page"]["start"].as_u64(), Some(CONFIG_PAGE));
    assert_eq!(v["config_page"]["end"].as_u64(), Some(FLASH + FLASH_LEN));
    assert_eq!(v["chip"], "STM32G474RETx");

    let o = kapitza(&["flash", &path, "--dry-run"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(text.contains("0x08001100..0x08001200"), "{text}");
    assert!(text.contains("copied to 0x20000000"), "{text}");
    assert!(text.contains("0x0807f000..0x08080000"), "{text}");
    assert!(text.contains("nothing written"), "{text}");
}

#[test]
fn an_elf_for_another_target_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let x86 = elf(
        EM_X86_64,
        true,
        0x40_1000,
        &[Seg::flash(0x40_0000, vec![0x90; 64])],
    );
    let path = write_temp(&dir, "x86.elf", &x86);
    let o = kapitza(&["flash", &path, "--dry-run"]);
    assert_eq!(o.status.code(), Some(Exit::Refused as i32));
    assert!(stderr(&o).contains("x86-64"), "{}", stderr(&o));

    let path = write_temp(&dir, "text.bin", b"not an ELF at all");
    let o = kapitza(&["flash", &path, "--dry-run"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("not an ELF"), "{}", stderr(&o));
}

#[test]
fn an_image_into_the_configuration_page_is_too_large() {
    let dir = tempfile::tempdir().unwrap();
    // Code up to 16 bytes past the page's start.
    let code = (CONFIG_PAGE + 16 - (FLASH + 0x100)) as usize;
    let big = elf(
        EM_ARM,
        false,
        FLASH + 0x101,
        &[
            Seg::flash(FLASH, vectors()),
            Seg::flash(FLASH + 0x100, vec![0; code]),
        ],
    );
    let path = write_temp(&dir, "big.elf", &big);
    let o = kapitza(&["flash", &path, "--dry-run"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("too large") && e.contains("0x0807f000"), "{e}");

    // One byte short of the page fits.
    let fits = elf(
        EM_ARM,
        false,
        FLASH + 0x101,
        &[
            Seg::flash(FLASH, vectors()),
            Seg::flash(FLASH + 0x100, vec![0; code - 16]),
        ],
    );
    let path = write_temp(&dir, "fits.elf", &fits);
    assert!(kapitza(&["flash", &path, "--dry-run"]).status.success());
}

#[test]
fn static_ram_beyond_ram_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let img = elf(
        EM_ARM,
        false,
        FLASH + 0x101,
        &[
            Seg::flash(FLASH, vectors()),
            Seg {
                vaddr: RAM,
                paddr: RAM,
                data: vec![],
                mem: RAM_LEN + 4,
            },
        ],
    );
    let path = write_temp(&dir, "ram.elf", &img);
    let o = kapitza(&["flash", &path, "--dry-run"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("RAM"), "{}", stderr(&o));
}

#[test]
fn an_image_without_a_cortex_m_vector_table_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    // An even reset handler (not Thumb) and a stack pointer in flash.
    let mut v = vectors();
    v[..8].copy_from_slice(&[0, 0, 0, 8, 0, 1, 0, 8]);
    let img = elf(EM_ARM, false, FLASH + 0x101, &[Seg::flash(FLASH, v)]);
    let path = write_temp(&dir, "vt.elf", &img);
    let o = kapitza(&["flash", &path, "--dry-run"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("vector table"), "{}", stderr(&o));
}

#[test]
fn a_wrong_chip_is_refused_before_the_board_is_touched() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_temp(&dir, "fw.elf", &good_image());
    let o = kapitza(&["flash", &path, "--dry-run", "--chip", "STM32X999"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("unknown chip"), "{}", stderr(&o));
    // A chip probe-rs knows whose flash (64 KiB) cannot hold memory.x's 512 KiB.
    let o = kapitza(&["flash", &path, "--dry-run", "--chip", "STM32F103C8"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("wrong chip") && e.contains("0x08000000..0x08080000"),
        "{e}"
    );
}

// ---- probes, through a fake lister -------------------------------------------------------

#[derive(Debug)]
struct NoDriver;

impl std::fmt::Display for NoDriver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ST-LINK")
    }
}

/// Lists nothing and opens nothing: the probes are the lister's.
impl ProbeFactory for NoDriver {
    fn open(&self, _: &DebugProbeSelector) -> Result<Box<dyn DebugProbe>, DebugProbeError> {
        Err(ProbeCreationError::NotFound.into())
    }
    fn list_probes(&self) -> Vec<ProbeListItem> {
        Vec::new()
    }
}

static DRIVER: NoDriver = NoDriver;

#[derive(Debug)]
struct FakeLister(Vec<ProbeListItem>);

impl ProbeLister for FakeLister {
    fn open(&self, _: &DebugProbeSelector) -> Result<Probe, DebugProbeError> {
        Err(ProbeCreationError::NotFound.into())
    }
    fn list_with_access(&self, selector: Option<&DebugProbeSelector>) -> Vec<ProbeListItem> {
        self.0
            .iter()
            .filter(|p| selector.is_none_or(|s| s.matches_probe(&p.info)))
            .cloned()
            .collect()
    }
}

/// A NUCLEO-G474RE's ST-LINK V3E (0483:374E) with this serial number.
fn stlink(serial: &str, accessibility: Accessibility) -> ProbeListItem {
    ProbeListItem {
        info: DebugProbeInfo::new(
            "STLink V3",
            0x0483,
            0x374E,
            Some(serial.into()),
            &DRIVER,
            None,
            false,
        ),
        accessibility,
    }
}

fn lister(items: Vec<ProbeListItem>) -> Lister {
    Lister::with_lister(Box::new(FakeLister(items)))
}

fn flash_args(extra: &[&str], elf: &str) -> kapitza::cmd::flash::Args {
    let mut argv = vec!["kapitza", "flash", elf];
    argv.extend_from_slice(extra);
    match Cli::try_parse_from(argv).unwrap().command {
        Sub::Flash(a) => a,
        other => panic!("{other:?}"),
    }
}

/// Runs `kapitza flash` on the good image with `probes` attached; the error and its exit.
fn flash_with(probes: Vec<ProbeListItem>, extra: &[&str]) -> (String, Exit) {
    let dir = tempfile::tempdir().unwrap();
    let path = write_temp(&dir, "fw.elf", &good_image());
    let mut out = Vec::new();
    let e = kapitza::cmd::flash::run_with(&flash_args(extra, &path), &lister(probes), &mut out)
        .unwrap_err();
    let exit = e.downcast_ref::<Failure>().expect("a Failure").exit;
    (format!("{e:#}"), exit)
}

#[test]
fn no_probe_says_how_to_plug_in() {
    let (e, exit) = flash_with(vec![], &[]);
    assert_eq!(exit, Exit::NoRig);
    assert!(
        e.contains("no debug probe found") && e.contains("CN1"),
        "{e}"
    );
}

#[test]
fn several_probes_are_listed_and_one_is_chosen_with_probe() {
    let two = || {
        vec![
            stlink("AAA111", Accessibility::Accessible),
            stlink("BBB222", Accessibility::Accessible),
        ]
    };
    let (e, exit) = flash_with(two(), &[]);
    assert_eq!(exit, Exit::NoRig);
    assert!(
        e.contains("2 debug probes")
            && e.contains("0483:374e:AAA111")
            && e.contains("0483:374e:BBB222"),
        "{e}"
    );
    let sel = kapitza::flash::probes::parse_selector("0483:374e:BBB222").unwrap();
    let chosen = kapitza::flash::probes::select(&lister(two()), Some(&sel)).unwrap();
    assert_eq!(chosen.serial_number.as_deref(), Some("BBB222"));

    let (e, _) = flash_with(two(), &["--probe", "0483:374e:CCC333"]);
    assert!(e.contains("no debug probe matches"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let path = write_temp(&dir, "fw.elf", &good_image());
    let bad = kapitza::cmd::flash::run_with(
        &flash_args(&["--probe", "not-a-probe"], &path),
        &lister(two()),
        &mut Vec::new(),
    )
    .unwrap_err();
    assert!(format!("{bad:#}").contains("VID:PID"), "{bad:#}");
}

#[test]
fn a_probe_without_permission_names_the_udev_rules() {
    let (e, exit) = flash_with(vec![stlink("AAA111", Accessibility::PermissionDenied)], &[]);
    assert_eq!(exit, Exit::NoRig);
    assert!(
        e.contains("may not open") && e.contains("69-probe-rs.rules"),
        "{e}"
    );
}

#[test]
fn probes_lists_selectors_and_permission() {
    let mut out = Vec::new();
    let args = kapitza::cmd::probes::Args { json: true };
    let found = lister(vec![
        stlink("AAA111", Accessibility::Accessible),
        stlink("BBB222", Accessibility::PermissionDenied),
    ]);
    kapitza::cmd::probes::run_with(&args, &found, &mut out).unwrap();
    let v: Value = serde_json::from_slice(&out).unwrap();
    assert_eq!(v[0]["selector"], "0483:374e:AAA111");
    assert_eq!(v[0]["accessible"], true);
    assert_eq!(v[1]["accessible"], false);

    let mut out = Vec::new();
    let args = kapitza::cmd::probes::Args { json: false };
    kapitza::cmd::probes::run_with(&args, &found, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains("[no permission]") && text.contains("69-probe-rs.rules"),
        "{text}"
    );
}

// ---- after flashing: the version check, against `kapitza rig serve` ----------------------

#[test]
fn the_version_is_confirmed_after_flashing() {
    let rig = KAPITZA.serve("20", &[]);
    let s = confirm::confirm(&rig.first_line, Duration::from_secs(10)).unwrap();
    assert_eq!(s.version.protocol, kapitza_core::link::PROTOCOL_VERSION);
}

#[test]
fn a_version_mismatch_after_flashing_is_an_error() {
    let rig = KAPITZA.serve("20", &["--protocol", "9"]);
    let Err(e) = confirm::confirm(&rig.first_line, Duration::from_secs(10)) else {
        panic!("protocol v9 was accepted");
    };
    let msg = format!("{e:#}");
    let ours = format!("v{}", kapitza_core::link::PROTOCOL_VERSION);
    assert!(
        msg.contains("after flashing") && msg.contains("v9") && msg.contains(&ours),
        "{msg}"
    );
}

#[test]
fn a_silent_port_times_out_with_a_hint() {
    let Err(e) = confirm::confirm("/dev/kapitza-no-such-port", Duration::from_millis(500)) else {
        panic!("a missing port answered");
    };
    assert!(format!("{e:#}").contains("did not answer"), "{e:#}");
    // The case `kapitza flash` diagnoses through the probe; a protocol mismatch is not it.
    assert!(confirm::is_silent(&e));
    let other = anyhow::Error::from(Failure::new(Exit::NoRig, "no serial port found"));
    assert!(!confirm::is_silent(&other));
}

// ---- The probe seam: backup, option bytes, erase, a silent board's diagnosis ----

use std::collections::BTreeMap;
use std::path::PathBuf;

use kapitza::flash::backup::{self, Backup, Options};
use kapitza::flash::board::Board;
use kapitza::flash::diagnose::{self, Cause};
use kapitza::flash::memory_map::{MemoryMap, Region};
use kapitza::flash::option_bytes::{OptionBytes, FLASH_OPTR};

/// FLASH_OPTR of a factory-fresh STM32G474, 0xFFEF_F8AA (the factory value RM0440 §5.7.8
/// gives for category 3 devices): RDP = 0xAA (level 0) and DBANK = 1 are the bits that matter
/// here; the other user options do not change the check.
const OPTR_FRESH: u32 = 0xFFEF_F8AA;
/// DBANK, bit 22 (RM0440 §5.7.8).
const DBANK: u32 = 1 << 22;
/// RCC_CR (RM0440 §7.4.1) at 0x4002_1000: HSEON bit 16, HSERDY bit 17.
const RCC_CR: u64 = 0x4002_1000;

/// A target without a probe: a sparse memory, a core at `pc`, and a log of what was done.
struct FakeBoard {
    words: BTreeMap<u64, u32>,
    area: Option<Vec<u8>>,
    area_start: u64,
    pc: u64,
    halted: bool,
    log: Vec<String>,
}

impl FakeBoard {
    fn new(optr: u32, area: Option<Vec<u8>>) -> Self {
        Self {
            words: BTreeMap::from([(FLASH_OPTR, optr)]),
            area,
            area_start: config_area().start,
            pc: 0,
            halted: false,
            log: Vec::new(),
        }
    }
}

impl Board for FakeBoard {
    fn read(&mut self, address: u64, buf: &mut [u8]) -> anyhow::Result<()> {
        let area = self
            .area
            .as_ref()
            .ok_or_else(|| anyhow::anyhow!("ST-LINK: SWD fault"))?;
        let off = (address - self.area_start) as usize;
        buf.copy_from_slice(&area[off..off + buf.len()]);
        self.log.push(format!("read {address:#x} {}", buf.len()));
        Ok(())
    }
    fn read_word(&mut self, address: u64) -> anyhow::Result<u32> {
        self.words
            .get(&address)
            .copied()
            .ok_or_else(|| anyhow::anyhow!("no word at {address:#x}"))
    }
    fn halt_pc(&mut self) -> anyhow::Result<u64> {
        self.halted = true;
        self.log.push("halt".into());
        Ok(self.pc)
    }
    fn resume(&mut self) -> anyhow::Result<()> {
        self.halted = false;
        self.log.push("resume".into());
        Ok(())
    }
    fn erase(&mut self, region: Region) -> anyhow::Result<()> {
        self.log
            .push(format!("erase {:#x}..{:#x}", region.start, region.end));
        if let Some(a) = &mut self.area {
            a.fill(0xFF);
        }
        Ok(())
    }
    fn write_flash(&mut self, address: u64, data: &[u8]) -> anyhow::Result<()> {
        self.log.push(format!("write {address:#x} {}", data.len()));
        self.area = Some(data.to_vec());
        Ok(())
    }
}

fn config_area() -> Region {
    MemoryMap::firmware().config_page
}

/// An area holding something: a record's first bytes, the rest erased.
fn stored_area() -> Vec<u8> {
    let mut a = vec![0xFF; config_area().len() as usize];
    a[..8].copy_from_slice(b"KPZC\x01\x00\x10\x00");
    a
}

fn options(dir: &std::path::Path) -> Options {
    Options {
        area: config_area(),
        dir: dir.to_path_buf(),
        board: "0670FF3632".into(),
        no_backup: false,
        erase: false,
        restore: None,
    }
}

fn saved_path(b: &Backup) -> PathBuf {
    match b {
        Backup::Saved { path, .. } => path.clone(),
        other => panic!("{other:?}"),
    }
}

#[test]
fn two_backups_are_two_files() {
    let dir = tempfile::tempdir().unwrap();
    let opts = options(dir.path());
    let mut a = Vec::new();
    for _ in 0..2 {
        let mut board = FakeBoard::new(OPTR_FRESH, Some(stored_area()));
        let p = backup::prepare(&mut board, &opts).unwrap();
        a.push(saved_path(&p.backup));
        // The whole area, in one read, and no erase without --erase-config.
        assert_eq!(
            board.log,
            [format!(
                "read {:#x} {}",
                config_area().start,
                config_area().len()
            )]
        );
        assert!(!p.erased);
    }
    assert_ne!(a[0], a[1]);
    for p in &a {
        assert_eq!(std::fs::read(p).unwrap(), stored_area());
        let name = p.file_name().unwrap().to_str().unwrap();
        assert!(
            name.starts_with("config-0670FF3632-") && name.ends_with(".bin"),
            "{name}"
        );
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn a_blank_area_is_no_stored_configuration_and_saves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    // Erased flash reads all ones.
    let mut board = FakeBoard::new(OPTR_FRESH, Some(vec![0xFF; config_area().len() as usize]));
    let p = backup::prepare(&mut board, &options(dir.path())).unwrap();
    assert_eq!(
        p.backup,
        Backup::Blank {
            bytes: config_area().len()
        }
    );
    assert!(p.backup.text().contains("no stored configuration"));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_failed_read_stops_unless_no_backup() {
    let dir = tempfile::tempdir().unwrap();
    let mut board = FakeBoard::new(OPTR_FRESH, None);
    let mut opts = options(dir.path());
    opts.erase = true;
    let e = backup::prepare(&mut board, &opts).unwrap_err();
    assert_eq!(e.downcast_ref::<Failure>().unwrap().exit, Exit::NoRig);
    let msg = format!("{e:#}");
    assert!(
        msg.contains("not backed up") && msg.contains("--no-backup") && msg.contains("SWD fault"),
        "{msg}"
    );
    // Nothing erased when the backup failed.
    assert!(
        board.log.iter().all(|l| !l.starts_with("erase")),
        "{:?}",
        board.log
    );

    opts.no_backup = true;
    let p = backup::prepare(&mut board, &opts).unwrap();
    assert!(matches!(&p.backup, Backup::Unread { error } if error.contains("SWD fault")));
    assert!(p.backup.text().contains("NOT backed up"));
}

#[test]
fn erase_config_erases_the_area_after_the_backup() {
    let dir = tempfile::tempdir().unwrap();
    let mut board = FakeBoard::new(OPTR_FRESH, Some(stored_area()));
    let mut opts = options(dir.path());
    opts.erase = true;
    let p = backup::prepare(&mut board, &opts).unwrap();
    let a = config_area();
    assert_eq!(
        board.log,
        [
            format!("read {:#x} {}", a.start, a.len()),
            format!("erase {:#x}..{:#x}", a.start, a.end)
        ]
    );
    assert!(p.erased);
    // The backup holds what was there before the erase.
    assert_eq!(std::fs::read(saved_path(&p.backup)).unwrap(), stored_area());
}

#[test]
fn restore_config_writes_a_backup_back_and_refuses_a_wrong_size() {
    let dir = tempfile::tempdir().unwrap();
    let saved = backup::save(dir.path(), "b", &stored_area()).unwrap();
    let mut board = FakeBoard::new(OPTR_FRESH, Some(vec![0xFF; config_area().len() as usize]));
    let mut opts = options(dir.path());
    opts.restore = Some(saved.clone());
    let p = backup::prepare(&mut board, &opts).unwrap();
    assert!(p.erased);
    assert_eq!(backup::restore(&mut board, &opts).unwrap(), Some(saved));
    assert_eq!(board.area.as_deref(), Some(&stored_area()[..]));

    let short = dir.path().join("short.bin");
    std::fs::write(&short, [0u8; 100]).unwrap();
    opts.restore = Some(short);
    let mut board = FakeBoard::new(OPTR_FRESH, Some(stored_area()));
    let e = format!("{:#}", backup::prepare(&mut board, &opts).unwrap_err());
    assert!(
        e.contains("100 bytes") && e.contains("nothing was written"),
        "{e}"
    );
    assert!(board.log.is_empty(), "{:?}", board.log);
}

/// RM0440 §5.7.8: RDP bits 7:0 (0xAA level 0, 0xCC level 2, any other value level 1), DBANK
/// bit 22.
#[test]
fn option_bytes_decode_and_refuse() {
    let cases = [
        (OPTR_FRESH, 0, true),
        ((OPTR_FRESH & !0xFF) | 0xCC, 2, true),
        ((OPTR_FRESH & !0xFF) | 0xBB, 1, true),
        (OPTR_FRESH & !0xFF, 1, true),
        (OPTR_FRESH & !DBANK, 0, false),
    ];
    for (optr, level, dbank) in cases {
        let o = OptionBytes::decode(optr);
        assert_eq!((o.rdp_level, o.dbank), (level, dbank), "{optr:#x}");
        let r = o.check();
        assert_eq!(r.is_ok(), level == 0 && dbank, "{optr:#x}");
        if let Err(e) = r {
            assert_eq!(e.downcast_ref::<Failure>().unwrap().exit, Exit::Refused);
            let m = e.to_string();
            assert!(m.contains("nothing was written"), "{m}");
            match (level, dbank) {
                (1, _) => assert!(m.contains("level 1") && m.contains("RDP=0xAA"), "{m}"),
                (2, _) => assert!(m.contains("level 2") && m.contains("no tool"), "{m}"),
                _ => assert!(m.contains("DBANK = 0") && m.contains("DBANK=1"), "{m}"),
            }
        }
    }
}

#[test]
fn a_protected_chip_is_refused_before_the_backup() {
    let dir = tempfile::tempdir().unwrap();
    let mut board = FakeBoard::new((OPTR_FRESH & !0xFF) | 0xBB, Some(stored_area()));
    let mut opts = options(dir.path());
    opts.erase = true;
    let e = backup::prepare(&mut board, &opts).unwrap_err();
    assert!(e.to_string().contains("level 1"), "{e}");
    assert!(board.log.is_empty(), "{:?}", board.log);
}

/// A small Arm ELF with function symbols at the addresses given (Thumb bit set, as rustc
/// emits them) and their sizes.
fn symbol_elf(symbols: &[(&str, u64, u64)]) -> Vec<u8> {
    use object::write::{Object, Symbol, SymbolSection};
    use object::{Architecture, BinaryFormat, SectionKind, SymbolFlags, SymbolKind, SymbolScope};
    let mut obj = Object::new(BinaryFormat::Elf, Architecture::Arm, Endianness::Little);
    let text = obj.add_section(Vec::new(), b".text".to_vec(), SectionKind::Text);
    for &(name, addr, size) in symbols {
        obj.add_symbol(Symbol {
            name: name.as_bytes().to_vec(),
            value: addr | 1,
            size,
            kind: SymbolKind::Text,
            scope: SymbolScope::Linkage,
            weak: false,
            section: SymbolSection::Section(text),
            flags: SymbolFlags::None,
        });
    }
    obj.write().unwrap()
}

fn symbols() -> Vec<u8> {
    symbol_elf(&[
        (
            "_ZN13embassy_stm323rcc4init17h0123456789abcdefE",
            0x0800_1000,
            0x200,
        ),
        ("HardFault_", 0x0800_2000, 0x10),
        ("rust_begin_unwind", 0x0800_3000, 0x40),
        (
            "_ZN16kapitza_firmware4main17hfedcba9876543210E",
            0x0800_4000,
            0x100,
        ),
    ])
}

/// The board at `pc` with RCC_CR `cr`: the diagnosis, and the core running again.
fn diagnose_at(pc: u64, cr: Option<u32>) -> diagnose::Diagnosis {
    let mut board = FakeBoard::new(OPTR_FRESH, None);
    board.pc = pc;
    if let Some(cr) = cr {
        board.words.insert(RCC_CR, cr);
    }
    let d = diagnose::diagnose(&mut board, &symbols()).unwrap();
    assert_eq!(board.log, ["halt", "resume"]);
    assert!(!board.halted);
    d
}

#[test]
fn a_silent_board_says_where_its_core_waits() {
    // HSEON set, HSERDY clear (RM0440 §7.4.1): waiting for the crystal, in rcc::init.
    let d = diagnose_at(0x0800_1084, Some(1 << 16 | 0x0000_0500));
    assert_eq!(d.cause, Cause::HseNotStarting);
    assert_eq!(d.symbol.as_deref(), Some("embassy_stm32::rcc::init"));
    let t = d.text();
    assert!(
        t.contains("no crystal") && t.contains("X3") && t.contains("SB"),
        "{t}"
    );
    // The same wait inlined into main: the register decides.
    let d = diagnose_at(0x0800_4010, Some(1 << 16));
    assert_eq!(d.cause, Cause::HseNotStarting);
    // HSE ready (HSERDY set): main is just main.
    let d = diagnose_at(0x0800_4010, Some(3 << 16));
    assert_eq!(d.cause, Cause::Elsewhere);
    assert!(d.text().contains("kapitza_firmware::main"), "{}", d.text());
    // Handlers.
    let d = diagnose_at(0x0800_2004, Some(3 << 16));
    assert_eq!(d.cause, Cause::HardFault);
    assert!(d.text().contains("HardFault handler"));
    let d = diagnose_at(0x0800_3000, Some(3 << 16));
    assert_eq!(d.cause, Cause::Panic);
    assert!(d.text().contains("panicked"));
    // One past the end of main's 0x100 bytes: in no function.
    let d = diagnose_at(0x0800_4100, Some(3 << 16));
    assert_eq!((d.cause, d.symbol), (Cause::Unknown, None));
    // RCC_CR unreadable: the symbol alone points at the clock set-up.
    let d = diagnose_at(0x0800_1000, None);
    assert_eq!(d.cause, Cause::HseNotStarting);
}

#[test]
fn demangling() {
    assert_eq!(
        diagnose::demangle("_ZN4core9panicking5panic17h0123456789abcdefE"),
        "core::panicking::panic"
    );
    assert_eq!(diagnose::demangle("HardFault"), "HardFault");
    assert_eq!(diagnose::demangle("_ZN3bad"), "_ZN3bad");
}

#[test]
fn the_data_folder_follows_xdg() {
    use std::ffi::OsString;
    let s = |v: &str| Some(OsString::from(v));
    if cfg!(any(windows, target_os = "macos")) {
        return;
    }
    // XDG Base Directory Specification: $XDG_DATA_HOME if set and absolute, else
    // $HOME/.local/share.
    assert_eq!(
        backup::data_dir(s("/d"), s("/h"), None),
        Some(PathBuf::from("/d"))
    );
    assert_eq!(
        backup::data_dir(s("rel"), s("/h"), None),
        Some(PathBuf::from("/h/.local/share"))
    );
    assert_eq!(
        backup::data_dir(None, s("/h"), None),
        Some(PathBuf::from("/h/.local/share"))
    );
    assert_eq!(backup::data_dir(s(""), None, None), None);
}

#[test]
fn dry_run_says_what_it_would_back_up_and_erase() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_temp(&dir, "fw.elf", &good_image());
    let data = dir.path().join("data");
    let env = [("XDG_DATA_HOME", data.to_str().unwrap())];
    let run = |args: &[&str]| {
        KAPITZA
            .run_within(args, &env, None, Duration::from_secs(60))
            .expect("kapitza flash --dry-run ends")
    };
    let o = run(&["flash", &path, "--dry-run", "--erase-config"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    let a = config_area();
    let want = format!("{:#010x}..{:#010x} ({} bytes)", a.start, a.end, a.len());
    assert!(text.contains(&want), "{text}");
    assert!(
        text.contains(&data.join("kapitza/backups").display().to_string()),
        "{text}"
    );
    assert!(text.contains("would erase it after the backup"), "{text}");
    // Nothing is created by a dry run.
    assert!(!data.exists());

    let o = run(&["flash", &path, "--dry-run", "--json"]);
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["erase_config"], false);
    assert_eq!(
        v["backup_dir"].as_str(),
        data.join("kapitza/backups").to_str()
    );
}
