//! The configuration store against power cuts: a flash model of the STM32G4's (2 KiB pages,
//! 64-bit program words, a double ECC error on a damaged word reported as a failed read, as
//! the firmware's NMI guard does) loses power at every word of a store — each word of the
//! erase and each word of the program — and every boot after it must load the old or the new
//! configuration, never the defaults.
//!
//! What a cut leaves (RM0440 "Flash memory", and embedded-storage's `NorFlash` contract: "if
//! power is lost during erase, contents of the page are undefined"; "during write, the
//! contents of the written words are undefined"):
//! * a cut erase: some words of the page erased, the rest still old, one word random;
//! * a cut program: the words before it programmed, that 64-bit word with a random subset of
//!   its 0 bits programmed, the rest erased;
//! * a word left partly written or random reads back as an ECC error half of the time.
//!
//! Run: `cargo test --workspace --test persist_power_cut -- --nocapture`.

use std::collections::HashSet;

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use kapitza_core::persist::store::{self, Area};
use kapitza_core::persist::{self, ConfigOrigin, Fallback, RECORD_MAX};
use kapitza_core::rig::config::RigConfig;

/// The firmware's area: the last 4 KiB of the G474RE's 512 KiB (board::CONFIG_PAGE_OFFSET).
const AREA: Area = Area {
    offset: 0x7_F000,
    size: 4096,
};
const CAPACITY: usize = 0x8_0000;
const PAGE: usize = 2048;
const WORD: usize = 8;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ModelError {
    /// A double ECC error.
    Ecc,
    /// Power is gone.
    Off,
    /// Programming a word that is not erased (the G4's PROGERR).
    NotErased,
    Bounds,
}

impl NorFlashError for ModelError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            Self::Bounds => NorFlashErrorKind::OutOfBounds,
            _ => NorFlashErrorKind::Other,
        }
    }
}

/// xorshift64*: a fixed seed, so every run cuts the same way.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
}

struct Flash {
    mem: Vec<u8>,
    /// Words (offset / 8) whose reads fail with a double ECC error.
    ecc: HashSet<usize>,
    /// Word steps (erased or programmed words) left before the power goes; `None`: never.
    budget: Option<usize>,
    off: bool,
    rng: Rng,
    erases: usize,
    programs: usize,
}

impl Flash {
    fn new(seed: u64) -> Self {
        Self {
            mem: vec![0xFF; CAPACITY],
            ecc: HashSet::new(),
            budget: None,
            off: false,
            rng: Rng(seed | 1),
            erases: 0,
            programs: 0,
        }
    }

    /// One word's step: false when the power goes at it.
    fn step(&mut self) -> bool {
        match &mut self.budget {
            Some(0) => {
                self.off = true;
                false
            }
            Some(n) => {
                *n -= 1;
                true
            }
            None => true,
        }
    }

    /// Power back on (a boot).
    fn restore(&mut self) {
        self.off = false;
        self.budget = None;
    }

    fn maybe_ecc(&mut self, word: usize) {
        if self.rng.next() & 1 == 1 {
            self.ecc.insert(word);
        }
    }
}

impl ErrorType for Flash {
    type Error = ModelError;
}

impl ReadNorFlash for Flash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), ModelError> {
        if self.off {
            return Err(ModelError::Off);
        }
        let (a, b) = (offset as usize, offset as usize + bytes.len());
        if b > CAPACITY {
            return Err(ModelError::Bounds);
        }
        if (a / WORD..b.div_ceil(WORD)).any(|w| self.ecc.contains(&w)) {
            return Err(ModelError::Ecc);
        }
        bytes.copy_from_slice(&self.mem[a..b]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        CAPACITY
    }
}

impl NorFlash for Flash {
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = PAGE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), ModelError> {
        if self.off {
            return Err(ModelError::Off);
        }
        let (from, to) = (from as usize, to as usize);
        if !from.is_multiple_of(PAGE) || !to.is_multiple_of(PAGE) || to > CAPACITY || from > to {
            return Err(ModelError::Bounds);
        }
        for page in (from..to).step_by(PAGE) {
            self.erases += 1;
            // The words in a random order: a cut leaves the erased ones anywhere in the page.
            let mut order: Vec<usize> = (0..PAGE / WORD).collect();
            for i in (1..order.len()).rev() {
                let j = (self.rng.next() % (i as u64 + 1)) as usize;
                order.swap(i, j);
            }
            for w in order {
                let word = page / WORD + w;
                if !self.step() {
                    let r = self.rng.next().to_le_bytes();
                    self.mem[word * WORD..][..WORD].copy_from_slice(&r);
                    self.maybe_ecc(word);
                    return Err(ModelError::Off);
                }
                self.mem[word * WORD..][..WORD].fill(0xFF);
                self.ecc.remove(&word);
            }
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), ModelError> {
        if self.off {
            return Err(ModelError::Off);
        }
        let a = offset as usize;
        if !a.is_multiple_of(WORD)
            || !bytes.len().is_multiple_of(WORD)
            || a + bytes.len() > CAPACITY
        {
            return Err(ModelError::Bounds);
        }
        for (i, chunk) in bytes.chunks(WORD).enumerate() {
            let word = a / WORD + i;
            let at = word * WORD;
            if self.mem[at..at + WORD].iter().any(|&b| b != 0xFF) {
                return Err(ModelError::NotErased);
            }
            let want = u64::from_le_bytes(chunk.try_into().unwrap());
            if !self.step() {
                // A random subset of the word's 0 bits programmed.
                let zeros = !want;
                let got = !(zeros & self.rng.next());
                self.mem[at..at + WORD].copy_from_slice(&got.to_le_bytes());
                if got != u64::MAX && got != want {
                    self.maybe_ecc(word);
                }
                return Err(ModelError::Off);
            }
            self.programs += 1;
            self.mem[at..at + WORD].copy_from_slice(chunk);
        }
        Ok(())
    }
}

/// A configuration unlike the reference in its calibration, numbered `k`.
fn config(k: u32) -> RigConfig {
    let mut c = RigConfig::REFERENCE;
    c.amplitude = 0.010 + 0.0005 * f64::from(k);
    c.calibration.pendulum_zero = 1000 + 37 * k as u16;
    c.calibration.servo.centre_deg = 80.0 + f64::from(k);
    c.validate().unwrap()
}

/// Writes a record of `cfg` with sequence `seq` straight into page `page` (a flash as a
/// store of the past left it).
fn put(flash: &mut Flash, page: usize, cfg: &RigConfig, seq: u32) {
    let mut buf = [0u8; RECORD_MAX];
    let n = persist::encode(cfg, seq, &mut buf);
    let at = AREA.page(page) as usize;
    flash.mem[at..at + PAGE].fill(0xFF);
    flash.mem[at..at + n].copy_from_slice(&buf[..n]);
}

fn legacy_v3() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/tests/golden/persist/record_v3.bin"
    ))
    .unwrap()
}

/// One starting state: the old configuration as the newest record, and what else is there.
struct Case {
    name: &'static str,
    old: RigConfig,
    new: RigConfig,
    setup: fn(&mut Flash, &RigConfig),
}

/// The word steps of one uninterrupted store from `setup`'s state (erase + program).
fn steps_of(case: &Case, seed: u64) -> usize {
    let mut f = Flash::new(seed);
    (case.setup)(&mut f, &case.old);
    f.budget = Some(usize::MAX);
    store::store(&mut f, &AREA, &case.new).unwrap();
    usize::MAX - f.budget.unwrap()
}

fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "old in page 0, older in page 1",
            old: config(1),
            new: config(2),
            setup: |f, old| {
                put(f, 1, &config(9), 41);
                put(f, 0, old, 42);
            },
        },
        Case {
            name: "old in page 1, older in page 0",
            old: config(3),
            new: config(4),
            setup: |f, old| {
                put(f, 0, &config(9), 1000);
                put(f, 1, old, 1001);
            },
        },
        Case {
            name: "old in page 1, page 0 erased",
            old: config(5),
            new: config(6),
            setup: |f, old| put(f, 1, old, 1),
        },
        Case {
            name: "sequence wraps: old u32::MAX in page 0, older in page 1",
            old: config(7),
            new: config(8),
            setup: |f, old| {
                put(f, 1, &config(9), u32::MAX - 1);
                put(f, 0, old, u32::MAX);
            },
        },
        Case {
            name: "old is a format-3 record (no sequence) in page 1",
            old: persist::decode(&legacy_v3()).unwrap(),
            new: config(10),
            setup: |f, _| {
                let b = legacy_v3();
                let at = AREA.page(1) as usize;
                f.mem[at..at + b.len()].copy_from_slice(&b);
            },
        },
        Case {
            name: "old in page 0, page 1 left half-erased with ECC errors",
            old: config(11),
            new: config(12),
            setup: |f, old| {
                put(f, 0, old, 7);
                let at = AREA.page(1) as usize;
                f.mem[at..at + 64].copy_from_slice(&[0x5A; 64]);
                f.ecc.insert(at / WORD + 3);
            },
        },
    ]
}

#[test]
fn a_cut_at_any_word_of_a_store_leaves_the_old_or_the_new_configuration() {
    let mut cuts = 0;
    let (mut olds, mut news) = (0, 0);
    for (ci, case) in cases().iter().enumerate() {
        for seed in 1..=2u64 {
            let seed = seed * 7919 + ci as u64;
            let steps = steps_of(case, seed);
            // At least the page's 256 erase words and the record's words.
            assert!(steps > PAGE / WORD, "{}: {steps} steps", case.name);
            for cut in 0..=steps {
                let mut f = Flash::new(seed ^ ((cut as u64) << 20));
                (case.setup)(&mut f, &case.old);
                f.budget = Some(cut);
                let r = store::store(&mut f, &AREA, &case.new);
                assert_eq!(r.is_ok(), cut == steps, "{}: cut {cut}", case.name);
                f.restore();
                let (cfg, origin) = store::load(&mut f, &AREA);
                assert_eq!(origin, ConfigOrigin::Stored, "{}: cut {cut}", case.name);
                if cfg == case.new {
                    news += 1;
                } else {
                    assert_eq!(cfg, case.old, "{}: cut {cut}", case.name);
                    olds += 1;
                }
                // The next store after the cut goes through, and wins.
                let next = config(20);
                store::store(&mut f, &AREA, &next).unwrap();
                assert_eq!(store::load(&mut f, &AREA), (next, ConfigOrigin::Stored));
                cuts += 1;
            }
        }
    }
    println!(
        "{cuts} cut points: {olds} loaded the old configuration, {news} the new, none the defaults"
    );
    assert_eq!(cuts, olds + news);
    // Every completed store loads the new one (a cut whose last word happened to program
    // whole loads it too).
    assert!(news >= cases().len() * 2);
}

#[test]
fn a_format_3_record_at_the_old_address_loads() {
    let mut f = Flash::new(5);
    let b = legacy_v3();
    assert_eq!(&b[..6], b"KPZC\x03\x00", "a format-3 record");
    let at = AREA.page(1) as usize;
    assert_eq!(at, 0x7_F800, "the page format 3 was stored in");
    f.mem[at..at + b.len()].copy_from_slice(&b);
    // The configuration format 3's `persist::encode` made the file of: the reference rig with
    // A = 12.3 mm, the sensor's zero at count 9001, the servo's centre at 88°, a 60 mm rod.
    let mut want = RigConfig::REFERENCE;
    want.amplitude = 0.0123;
    want.calibration.pendulum_zero = 9001;
    want.calibration.servo.centre_deg = 88.0;
    want.connecting_rod = 0.06;
    assert_eq!(store::load(&mut f, &AREA), (want, ConfigOrigin::Stored));
    // The first store goes to the other page and keeps the old record as the fallback.
    let seq = store::store(&mut f, &AREA, &config(1)).unwrap();
    assert_eq!(seq, 1);
    assert_eq!(&f.mem[at..at + b.len()], &b[..]);
    assert_eq!(
        store::load(&mut f, &AREA),
        (config(1), ConfigOrigin::Stored)
    );
}

#[test]
fn stores_in_a_row_alternate_pages_and_the_newest_loads() {
    let mut f = Flash::new(9);
    assert_eq!(
        store::load(&mut f, &AREA),
        (
            RigConfig::REFERENCE,
            ConfigOrigin::Defaults(Fallback::Missing)
        )
    );
    for k in 1..=5 {
        let seq = store::store(&mut f, &AREA, &config(k)).unwrap();
        assert_eq!(seq, k);
        assert_eq!(
            store::load(&mut f, &AREA),
            (config(k), ConfigOrigin::Stored)
        );
    }
    // Five stores from empty: pages 0,1,0,1,0, one erase each.
    assert_eq!(f.erases, 5);
    let r = persist::read(&f.mem[AREA.page(0) as usize..][..RECORD_MAX]).unwrap();
    assert_eq!(r.seq, Some(5));
}

#[test]
fn both_pages_damaged_load_the_defaults_and_say_why() {
    let mut f = Flash::new(11);
    put(&mut f, 0, &config(1), 1);
    put(&mut f, 1, &config(2), 2);
    // A flipped bit in each record: the CRC fails.
    f.mem[AREA.page(0) as usize + 20] ^= 0x10;
    f.mem[AREA.page(1) as usize + 33] ^= 0x01;
    assert_eq!(
        store::load(&mut f, &AREA),
        (
            RigConfig::REFERENCE,
            ConfigOrigin::Defaults(Fallback::Corrupt)
        )
    );
    // An ECC error in one and an erased other: still "corrupt", the more telling reason.
    let mut f = Flash::new(12);
    put(&mut f, 1, &config(2), 2);
    f.ecc.insert(AREA.page(1) as usize / WORD);
    assert_eq!(
        store::load(&mut f, &AREA),
        (
            RigConfig::REFERENCE,
            ConfigOrigin::Defaults(Fallback::Corrupt)
        )
    );
}

#[test]
fn the_estop_held_at_power_up_boots_on_defaults_and_touches_nothing() {
    let mut f = Flash::new(13);
    store::store(&mut f, &AREA, &config(3)).unwrap();
    let before = f.mem.clone();
    let (erases, programs) = (f.erases, f.programs);
    // A read would fail: boot must not even read.
    f.off = true;
    let held = store::estop_held([true; store::ESTOP_BOOT_READINGS]);
    assert_eq!(
        store::boot(&mut f, &AREA, held),
        (RigConfig::REFERENCE, ConfigOrigin::DefaultsByEstop)
    );
    assert_eq!((f.erases, f.programs), (erases, programs));
    assert!(f.mem == before);
    // Released at the next power-up: the stored configuration is back.
    f.off = false;
    let held = store::estop_held([false; store::ESTOP_BOOT_READINGS]);
    assert_eq!(
        store::boot(&mut f, &AREA, held),
        (config(3), ConfigOrigin::Stored)
    );
}
