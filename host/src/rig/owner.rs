//! Who holds the port. A serial port has one owner at a time, and the rig soft-stops about a
//! second after the laptop goes silent, so a drive that outlives one command needs a process
//! that keeps the link alive: `kapitza attach` or `kapitza monitor`. The owner serves a
//! control socket beside the port; one-shot commands find it there and send their requests
//! through it, in the link's own framing, so the same client works on both.

use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The control socket of the owner of `port` (a device path or a symlink to one).
pub fn socket_path(port: &str) -> PathBuf {
    let real = std::fs::canonicalize(port).unwrap_or_else(|_| PathBuf::from(port));
    let name: String = real
        .to_string_lossy()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    runtime_dir().join(format!("{name}.sock"))
}

/// Where control sockets live: `$XDG_RUNTIME_DIR/kapitza`, else a per-user folder in the
/// system's temporary directory.
fn runtime_dir() -> PathBuf {
    match std::env::var_os("XDG_RUNTIME_DIR") {
        Some(d) if Path::new(&d).is_dir() => PathBuf::from(d).join("kapitza"),
        _ => std::env::temp_dir().join(format!("kapitza-{}", uid())),
    }
}

fn uid() -> u32 {
    // SAFETY: getuid has no preconditions and cannot fail.
    unsafe { libc::getuid() }
}

/// A connection to the running owner of `port`, if there is one.
pub fn connect(port: &str) -> Option<UnixStream> {
    let s = UnixStream::connect(socket_path(port)).ok()?;
    s.set_read_timeout(Some(Duration::from_millis(5))).ok()?;
    Some(s)
}
