//! The on-target scenarios (`selftest::rig`, `selftest::station`) on the host: each must produce its expected digest,
//! the same one the emulated Cortex-M4F must produce (`qemu/`), so host and target agree bit
//! for bit. Prints every digest (`-- --nocapture`) for regeneration after a deliberate change.

use kapitza_core::selftest::rig::CASES;
use kapitza_core::selftest::station::CASES as LOOP_CASES;

#[test]
fn digests_match() {
    let mut bad = Vec::new();
    for c in CASES.iter().chain(LOOP_CASES) {
        let got = (c.run)();
        println!("{:<22} 0x{got:016x}", c.name);
        if got != c.expected {
            bad.push((c.name, got, c.expected));
        }
    }
    assert!(
        bad.is_empty(),
        "digest mismatches (name, got, expected): {bad:x?}"
    );
}
