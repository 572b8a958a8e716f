//! Link setup for the firmware binary.
//!
//! The memory map lives in `memory.x` at the repository root (one level above this crate). It is
//! copied into `OUT_DIR`, which is then put on the linker search path, so that cortex-m-rt's
//! `link.x` finds it by name without the repository root itself becoming a search directory.

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() {
    let manifest_dir =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let out_dir = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));

    let memory_x = manifest_dir.join("..").join("memory.x");
    fs::copy(&memory_x, out_dir.join("memory.x"))
        .unwrap_or_else(|e| panic!("cannot copy {}: {e}", memory_x.display()));
    // The flash page reserved for the configuration record, checked at link time.
    let persist_x = manifest_dir.join("persist.x");
    fs::copy(&persist_x, out_dir.join("persist.x"))
        .unwrap_or_else(|e| panic!("cannot copy {}: {e}", persist_x.display()));
    println!("cargo:rustc-link-search={}", out_dir.display());

    // --nmagic: do not page-align sections, so the flash image is not padded.
    println!("cargo:rustc-link-arg-bins=--nmagic");
    // cortex-m-rt's linker script (it INCLUDEs memory.x).
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    // defmt's linker script: the interned log strings.
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    // The program image must stay below the configuration page.
    println!("cargo:rustc-link-arg-bins=-Tpersist.x");

    println!("cargo:rerun-if-changed=../memory.x");
    println!("cargo:rerun-if-changed=persist.x");
    println!("cargo:rerun-if-changed=build.rs");
}
