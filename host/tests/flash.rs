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
}
