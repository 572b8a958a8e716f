//! The pseudo-terminal `rig serve` offers its rig on, and the symlink that names it. Only Unix
//! systems have pseudo-terminals; elsewhere [`open`] refuses and points to `--port sim`.

#[cfg(unix)]
pub use unix::{open, publish};

#[cfg(not(unix))]
pub use elsewhere::{open, publish};

#[cfg(unix)]
mod unix {
    use std::io;
    use std::os::fd::AsRawFd;
    use std::path::Path;

    use anyhow::{bail, Context, Result};
    use serialport::{SerialPort, TTYPort};

    use crate::rig::simhost::Line;

    /// The pty's master end, never blocking, and its slave end held open so that a client may
    /// come and go.
    pub struct Pty {
        master: TTYPort,
        _slave: TTYPort,
    }

    /// A new pseudo-terminal and the device path a serial client opens.
    pub fn open() -> Result<(Pty, String)> {
        let (mut master, slave) = TTYPort::pair().context("cannot open a pseudo-terminal")?;
        set_nonblocking(&master)?;
        master.set_timeout(std::time::Duration::ZERO)?;
        let path = slave.name().context("the pseudo-terminal has no name")?;
        Ok((
            Pty {
                master,
                _slave: slave,
            },
            path,
        ))
    }

    fn nonblocking(e: io::Error) -> io::Result<usize> {
        match e.kind() {
            io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut | io::ErrorKind::Interrupted => {
                Ok(0)
            }
            _ => Err(e),
        }
    }

    impl Line for Pty {
        fn take(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            io::Read::read(&mut self.master, buf).or_else(nonblocking)
        }
        fn give(&mut self, buf: &[u8]) -> io::Result<usize> {
            io::Write::write(&mut self.master, buf).or_else(nonblocking)
        }
    }

    fn set_nonblocking(port: &TTYPort) -> Result<()> {
        let fd = port.as_raw_fd();
        // SAFETY: fcntl on a descriptor this process owns, with flags it just read.
        let ok = unsafe {
            let flags = libc::fcntl(fd, libc::F_GETFL);
            flags >= 0 && libc::fcntl(fd, libc::F_SETFL, flags | libc::O_NONBLOCK) == 0
        };
        if !ok {
            bail!(
                "cannot make the pseudo-terminal non-blocking: {}",
                io::Error::last_os_error()
            );
        }
        Ok(())
    }

    /// Points `link` at `target`, replacing a symlink (never a regular file) that is there.
    pub fn publish(link: &Path, target: &str) -> Result<()> {
        if let Ok(meta) = std::fs::symlink_metadata(link) {
            if !meta.file_type().is_symlink() {
                bail!(
                    "--link {}: exists and is not a symlink; not replaced",
                    link.display()
                );
            }
            std::fs::remove_file(link).with_context(|| format!("--link {}", link.display()))?;
        }
        std::os::unix::fs::symlink(target, link)
            .with_context(|| format!("--link {}", link.display()))
    }
}

#[cfg(not(unix))]
mod elsewhere {
    use std::io;
    use std::path::Path;

    use anyhow::{bail, Result};

    use crate::rig::simhost::Line;

    /// No pseudo-terminal can exist here.
    pub enum Pty {}

    pub fn open() -> Result<(Pty, String)> {
        bail!(
            "rig serve needs a pseudo-terminal, which only Unix systems have; `--port sim` runs \
             a simulated rig inside any rig command instead"
        )
    }

    pub fn publish(_link: &Path, _target: &str) -> Result<()> {
        Ok(())
    }

    impl Line for Pty {
        fn take(&mut self, _: &mut [u8]) -> io::Result<usize> {
            match *self {}
        }
        fn give(&mut self, _: &[u8]) -> io::Result<usize> {
            match *self {}
        }
    }
}
