//! The file policy of every command: a file the user named is never overwritten unless asked
//! (`--force`, or `--append` for a log), inputs are regular files (reading a FIFO or a device
//! would block or never end), and output directories are checked before any work starts.
//!
//! Outputs that are not regular files (a FIFO, `/dev/stdout`, `/dev/null`) are written as they
//! are: they hold nothing to lose.

use std::fs::{File, Metadata, OpenOptions};
use std::io::ErrorKind;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// What to do with an output file that exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Existing {
    /// Refuse before any work (the default).
    #[default]
    Refuse,
    /// Replace it (`--force`).
    Overwrite,
    /// Add to its end (`--append`).
    Append,
}

impl Existing {
    /// From a command's `--force` and `--append` flags (clap keeps them exclusive).
    pub fn from_flags(force: bool, append: bool) -> Self {
        match (force, append) {
            (_, true) => Self::Append,
            (true, false) => Self::Overwrite,
            (false, false) => Self::Refuse,
        }
    }
}

/// What a path that is not a regular file is, in a user's words.
fn kind(meta: &Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if meta.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// Refuses `path` (given as `what`, e.g. `--sim` or `the scene file`) unless it is a regular
/// file, without opening it.
pub fn check_input(what: &str, path: &Path) -> Result<()> {
    let meta = std::fs::metadata(path)
        .with_context(|| format!("{what} {}: cannot read", path.display()))?;
    if !meta.is_file() {
        bail!(
            "{what} {} is {}, not a regular file: nothing was read",
            path.display(),
            kind(&meta)
        );
    }
    Ok(())
}

/// The text of the regular file `path` ([`check_input`] first).
pub fn read_input(what: &str, path: &Path) -> Result<String> {
    check_input(what, path)?;
    std::fs::read_to_string(path).with_context(|| format!("{what} {}: cannot read", path.display()))
}

/// A device path (`/dev/stdout`, `/dev/null`): written as it is, whatever it resolves to.
fn is_device_path(path: &Path) -> bool {
    path.starts_with("/dev") || path.starts_with("/proc/self/fd")
}

/// Checks, before any work, that the output file `path` (given with `flag`) may be written
/// under `mode`: a regular file there is refused unless `mode` says what to do with it.
pub fn check_output(flag: &str, path: &Path, mode: Existing) -> Result<()> {
    if is_device_path(path) {
        return Ok(());
    }
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => {
            bail!("{flag} {} is a directory, not a file", path.display())
        }
        Ok(meta) if meta.is_file() && mode == Existing::Refuse => bail!(
            "{flag} {}: the file exists and is kept; nothing was done (--force replaces it{})",
            path.display(),
            if flag_appends(flag) {
                ", --append adds to it"
            } else {
                ""
            }
        ),
        Ok(_) => Ok(()),
        Err(e) if e.kind() == ErrorKind::NotFound => {
            let parent = match path.parent() {
                Some(p) if !p.as_os_str().is_empty() => p,
                _ => Path::new("."),
            };
            if !parent.is_dir() {
                bail!(
                    "{flag} {}: its folder {} does not exist",
                    path.display(),
                    parent.display()
                );
            }
            Ok(())
        }
        Err(e) => Err(e).with_context(|| format!("{flag} {}", path.display())),
    }
}

/// The logs that take `--append`.
fn flag_appends(flag: &str) -> bool {
    matches!(flag, "--csv" | "--truth")
}

/// Opens the output file `path` under `mode` ([`check_output`] first). A file that appears
/// between the check and the creation is still refused.
pub fn create_output(flag: &str, path: &Path, mode: Existing) -> Result<File> {
    check_output(flag, path, mode)?;
    let mut o = OpenOptions::new();
    o.write(true);
    let regular = std::fs::metadata(path).is_ok_and(|m| m.is_file());
    if is_device_path(path) || (path.exists() && !regular) {
        // A FIFO or a device: opened as it is (no truncation, no creation).
    } else {
        match mode {
            Existing::Refuse => o.create_new(true),
            Existing::Overwrite => o.create(true).truncate(true),
            Existing::Append => o.create(true).append(true),
        };
    }
    o.open(path).map_err(|e| {
        if e.kind() == ErrorKind::AlreadyExists {
            anyhow::anyhow!(
                "{flag} {}: the file exists and is kept (--force replaces it)",
                path.display()
            )
        } else {
            anyhow::Error::new(e).context(format!("{flag} {}: cannot create", path.display()))
        }
    })
}

/// Creates a new file `STEM.EXT` in `dir` (made if missing), or `STEM-2.EXT`, `STEM-3.EXT`, …
/// when that name is taken: for the files the tool writes on its own (backups), which must
/// never replace one. Returns the file and its path.
pub fn create_new_in(dir: &Path, stem: &str, ext: &str) -> Result<(File, PathBuf)> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    for n in 1..=1000 {
        let name = match n {
            1 => format!("{stem}.{ext}"),
            n => format!("{stem}-{n}.{ext}"),
        };
        let path = dir.join(name);
        match OpenOptions::new().write(true).create_new(true).open(&path) {
            Ok(f) => return Ok((f, path)),
            Err(e) if e.kind() == ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e).with_context(|| format!("cannot create {}", path.display())),
        }
    }
    bail!("{}: no free name for {stem}.{ext}", dir.display())
}

/// Whether `file` (just opened) is empty: a log appended to writes its header only then.
pub fn is_empty(file: &File) -> bool {
    file.metadata()
        .map_or(true, |m| !m.is_file() || m.len() == 0)
}

/// Checks before any work that the output directory `dir` (given with `flag`) exists (creating
/// it) and is writable. Its generated files are regenerated.
pub fn check_out_dir(flag: &str, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| {
        format!(
            "{flag} {}: cannot create the output directory",
            dir.display()
        )
    })?;
    let probe = dir.join(".kapitza-write-check");
    std::fs::write(&probe, b"").with_context(|| {
        format!(
            "{flag} {}: cannot write into the output directory",
            dir.display()
        )
    })?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_existing_file_is_kept_unless_asked() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("log.csv");
        std::fs::write(&p, b"earlier").unwrap();
        let e = check_output("--csv", &p, Existing::Refuse).unwrap_err();
        let msg = format!("{e:#}");
        assert!(msg.contains("--csv") && msg.contains("--append"), "{msg}");
        assert!(create_output("--csv", &p, Existing::Refuse).is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"earlier");
        use std::io::Write;
        let mut f = create_output("--csv", &p, Existing::Append).unwrap();
        assert!(!is_empty(&f));
        f.write_all(b"+more").unwrap();
        drop(f);
        assert_eq!(std::fs::read(&p).unwrap(), b"earlier+more");
        create_output("--csv", &p, Existing::Overwrite).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"");
    }

    #[test]
    fn a_new_file_needs_its_folder() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing").join("x.toml");
        let msg = format!(
            "{:#}",
            check_output("--backup", &p, Existing::Refuse).unwrap_err()
        );
        assert!(msg.contains("does not exist"), "{msg}");
        let p = dir.path().join("x.toml");
        create_output("--backup", &p, Existing::Refuse).unwrap();
        assert!(p.is_file());
    }

    #[test]
    fn directories_are_not_inputs_or_files() {
        let dir = tempfile::tempdir().unwrap();
        let msg = format!("{:#}", check_input("--sim", dir.path()).unwrap_err());
        assert!(msg.contains("a directory, not a regular file"), "{msg}");
        let msg = format!(
            "{:#}",
            check_output("--truth", dir.path(), Existing::Overwrite).unwrap_err()
        );
        assert!(msg.contains("is a directory"), "{msg}");
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_input_is_refused_without_opening_it() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("fifo");
        let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo on a path this test owns.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        // A read would block here forever: the refusal comes from the metadata alone.
        let msg = format!("{:#}", read_input("the scene file", &p).unwrap_err());
        assert!(msg.contains("a FIFO"), "{msg}");
        // As an output it is fine (nothing to lose).
        check_output("--csv", &p, Existing::Refuse).unwrap();
    }

    #[test]
    fn device_paths_are_outputs_as_they_are() {
        check_output("--truth", Path::new("/dev/stdout"), Existing::Refuse).unwrap();
        check_output("--truth", Path::new("/dev/null"), Existing::Refuse).unwrap();
    }
}
