//! The stored configuration, kept before flashing: the whole configuration area read through
//! the probe (it works on a board that does not answer on serial) and saved as a new file,
//! never over an older one; `--erase-config` erases the area on purpose, `--restore-config`
//! writes a saved area back.

use std::ffi::OsString;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;

use super::board::Board;
use super::memory_map::Region;
use super::option_bytes::{self, OptionBytes};
use crate::files;
use crate::rig::{Exit, Failure};

/// What `kapitza flash` does to the configuration area around writing the image.
#[derive(Debug, Clone)]
pub struct Options {
    /// The area: `MemoryMap::firmware().config_page`.
    pub area: Region,
    /// Where backups go ([`backup_dir`]).
    pub dir: PathBuf,
    /// Names the board in the file name (the ST-LINK's serial number).
    pub board: String,
    /// Flash on when the area cannot be read (`--no-backup`).
    pub no_backup: bool,
    /// Erase the area after the backup (`--erase-config`).
    pub erase: bool,
    /// Write this saved area back after flashing (`--restore-config`).
    pub restore: Option<PathBuf>,
}

/// What became of the backup.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Backup {
    /// The area held something: saved to `path`.
    Saved { path: PathBuf, bytes: u64 },
    /// Every byte 0xFF, the erased state: no stored configuration, nothing saved.
    Blank { bytes: u64 },
    /// The read failed and `--no-backup` flashed on.
    Unread { error: String },
}

impl Backup {
    pub fn text(&self) -> String {
        match self {
            Backup::Saved { path, bytes } => format!(
                "configuration area backed up: {bytes} bytes to {}",
                path.display()
            ),
            Backup::Blank { .. } => {
                "no stored configuration (the area is erased, all 0xFF): nothing to back up".into()
            }
            Backup::Unread { error } => {
                format!("configuration area NOT backed up (--no-backup): {error}")
            }
        }
    }
}

/// The board's state before the image is written, and what was done to the area.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Prepared {
    pub option_bytes: OptionBytes,
    pub backup: Backup,
    /// `--erase-config` (or `--restore-config`, before writing the saved area) erased it.
    pub erased: bool,
}

/// Before flashing: checks the option bytes (refusing a protected or single-bank chip), backs
/// the configuration area up, and erases it if asked. Nothing is written when this fails.
pub fn prepare(board: &mut dyn Board, opts: &Options) -> Result<Prepared> {
    if let Some(p) = &opts.restore {
        read_saved(p, opts.area)?;
    }
    let option_bytes = option_bytes::read(board)
        .map_err(|e| no_rig(format!("cannot read the option bytes (FLASH_OPTR): {e:#}")))?;
    option_bytes.check()?;
    let mut area = vec![0; opts.area.len() as usize];
    let backup = match board.read(opts.area.start, &mut area) {
        Ok(()) if is_blank(&area) => Backup::Blank {
            bytes: area.len() as u64,
        },
        Ok(()) => Backup::Saved {
            path: save(&opts.dir, &opts.board, &area)?,
            bytes: area.len() as u64,
        },
        Err(e) if opts.no_backup => Backup::Unread {
            error: format!("{e:#}"),
        },
        Err(e) => {
            return Err(no_rig(format!(
                "cannot read the configuration area {:#010x}..{:#010x} through the probe ({e:#}), \
                 so it was not backed up; nothing was written. --no-backup flashes without a \
                 backup",
                opts.area.start, opts.area.end
            )))
        }
    };
    let erased = opts.erase || opts.restore.is_some();
    if erased {
        board
            .erase(opts.area)
            .context("erasing the configuration area")?;
    }
    Ok(Prepared {
        option_bytes,
        backup,
        erased,
    })
}

/// After flashing: writes the saved area of `--restore-config` back.
pub fn restore(board: &mut dyn Board, opts: &Options) -> Result<Option<PathBuf>> {
    let Some(path) = &opts.restore else {
        return Ok(None);
    };
    let data = read_saved(path, opts.area)?;
    board
        .write_flash(opts.area.start, &data)
        .with_context(|| format!("writing {} to the configuration area", path.display()))?;
    Ok(Some(path.clone()))
}

/// A saved area: a regular file exactly the area's size.
fn read_saved(path: &Path, area: Region) -> Result<Vec<u8>> {
    files::check_input("--restore-config", path)?;
    let data = std::fs::read(path)
        .with_context(|| format!("--restore-config {}: cannot read", path.display()))?;
    if data.len() as u64 != area.len() {
        return Err(Failure::new(
            Exit::Refused,
            format!(
                "--restore-config {}: {} bytes, and the configuration area is {} bytes \
                 ({:#010x}..{:#010x}): not a backup of this firmware's area; nothing was written",
                path.display(),
                data.len(),
                area.len(),
                area.start,
                area.end
            ),
        )
        .into());
    }
    Ok(data)
}

fn no_rig(msg: String) -> anyhow::Error {
    Failure::new(Exit::NoRig, msg).into()
}

/// Erased flash reads all ones.
pub fn is_blank(area: &[u8]) -> bool {
    area.iter().all(|&b| b == 0xFF)
}

/// Saves `area` as a new file in `dir` (created if missing): `config-BOARD-UTCTIME.bin`, with
/// `-2`, `-3`, … when that name is taken. An existing file is never replaced.
pub fn save(dir: &Path, board: &str, area: &[u8]) -> Result<PathBuf> {
    let stem = format!("config-{}-{}", file_safe(board), utc_stamp());
    let (mut file, path) = files::create_new_in(dir, &stem, "bin")?;
    file.write_all(area)
        .and_then(|()| file.sync_all())
        .with_context(|| format!("writing the backup {}", path.display()))?;
    Ok(path)
}

/// `YYYYMMDDTHHMMSSZ`, now.
fn utc_stamp() -> String {
    let t = time::OffsetDateTime::now_utc();
    format!(
        "{:04}{:02}{:02}T{:02}{:02}{:02}Z",
        t.year(),
        u8::from(t.month()),
        t.day(),
        t.hour(),
        t.minute(),
        t.second()
    )
}

/// Letters, digits, `-` and `_` kept; anything else (a path separator) becomes `_`.
fn file_safe(s: &str) -> String {
    let s: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "board".into()
    } else {
        s
    }
}

/// Where backups are kept: `kapitza/backups/` in the user's data folder.
pub fn backup_dir() -> Result<PathBuf> {
    data_dir(
        std::env::var_os("XDG_DATA_HOME"),
        std::env::var_os("HOME"),
        std::env::var_os("APPDATA"),
    )
    .map(|d| d.join("kapitza").join("backups"))
    .context("no data folder for backups: set XDG_DATA_HOME or HOME")
}

/// The user's data folder as the `dirs` crate defines it: on Linux and the BSDs
/// `$XDG_DATA_HOME` (an absolute path) or `~/.local/share`; on macOS
/// `~/Library/Application Support`; on Windows `%APPDATA%` (the roaming folder).
pub fn data_dir(
    xdg_data_home: Option<OsString>,
    home: Option<OsString>,
    appdata: Option<OsString>,
) -> Option<PathBuf> {
    let nonempty = |v: Option<OsString>| v.filter(|s| !s.is_empty()).map(PathBuf::from);
    if cfg!(windows) {
        return nonempty(appdata);
    }
    let home = nonempty(home);
    if cfg!(target_os = "macos") {
        return home.map(|h| h.join("Library").join("Application Support"));
    }
    nonempty(xdg_data_home)
        .filter(|p| p.is_absolute())
        .or_else(|| home.map(|h| h.join(".local").join("share")))
}
