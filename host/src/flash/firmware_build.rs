//! `kapitza flash` without an ELF: build the firmware in release and take the image cargo
//! reports.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{bail, Context, Result};

/// The firmware crate: `firmware/` of the checkout the current directory is in, else of the
/// checkout this tool was built from.
pub fn firmware_dir() -> Result<PathBuf> {
    let is_firmware = |d: &Path| d.join("firmware").join("Cargo.toml").is_file();
    let here = std::env::current_dir()?;
    let built_from = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    here.ancestors()
        .find(|d| is_firmware(d))
        .map(Path::to_path_buf)
        .or_else(|| is_firmware(&built_from).then_some(built_from))
        .map(|d| d.join("firmware"))
        .context(
            "no firmware/ to build here (not in a kapitza checkout): give the firmware's ELF \
             as `kapitza flash FILE`",
        )
}

/// Runs `cargo build --release` in `dir` (cargo's own output goes to stderr) and returns the
/// path of the executable it built.
pub fn build(dir: &Path) -> Result<PathBuf> {
    eprintln!(
        "building the firmware: cargo build --release in {}",
        dir.display()
    );
    let out = Command::new("cargo")
        .args([
            "build",
            "--release",
            "--message-format=json-render-diagnostics",
        ])
        .current_dir(dir)
        // The firmware's own .cargo/config.toml and rust-toolchain.toml decide, not the
        // environment of a `cargo run` that started this tool.
        .env_remove("CARGO_TARGET_DIR")
        .env_remove("CARGO_BUILD_TARGET")
        .env_remove("RUSTUP_TOOLCHAIN")
        .stderr(Stdio::inherit())
        .output()
        .context("cannot run cargo to build the firmware")?;
    if !out.status.success() {
        bail!(
            "building the firmware failed (cargo build --release in {})",
            dir.display()
        );
    }
    executable(&String::from_utf8_lossy(&out.stdout))
        .context("cargo built the firmware but named no executable")
}

/// The last `executable` in cargo's JSON messages.
fn executable(messages: &str) -> Option<PathBuf> {
    messages
        .lines()
        .rev()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["reason"] == "compiler-artifact")
        .find_map(|m| m["executable"].as_str().map(PathBuf::from))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_executable_is_taken_from_cargos_messages() {
        let m = r#"{"reason":"compiler-artifact","executable":null}
{"reason":"compiler-artifact","executable":"/t/release/kapitza-firmware"}
{"reason":"build-finished","success":true}"#;
        assert_eq!(
            executable(m),
            Some(PathBuf::from("/t/release/kapitza-firmware"))
        );
        assert_eq!(executable("{\"reason\":\"build-finished\"}"), None);
    }
}
