//! The transport of the control socket beside an owned port: a Unix-domain socket. Systems
//! without one (Windows) have no control socket: no owner is ever found there, none is served,
//! and each command owns the port itself.

use std::path::Path;

/// Whether this system has control sockets.
pub const SUPPORTED: bool = cfg!(unix);

#[cfg(unix)]
pub use std::os::unix::net::{UnixListener as Listener, UnixStream as Stream};

#[cfg(not(unix))]
pub use elsewhere::{Listener, Stream};

/// The user's id, which names the folder of control sockets when there is no runtime folder.
pub fn uid() -> u32 {
    #[cfg(unix)]
    {
        // SAFETY: getuid has no preconditions and cannot fail.
        unsafe { libc::getuid() }
    }
    #[cfg(not(unix))]
    {
        0
    }
}

/// A connection to the socket at `path`, if something listens there.
pub fn connect(path: &Path) -> Option<Stream> {
    Stream::connect(path).ok()
}

#[cfg(not(unix))]
mod elsewhere {
    use std::io;
    use std::path::Path;
    use std::time::Duration;

    fn unsupported() -> io::Error {
        io::Error::new(
            io::ErrorKind::Unsupported,
            "control sockets need a Unix system",
        )
    }

    /// A connection that cannot exist here.
    pub enum Stream {}

    impl Stream {
        pub fn connect(_: impl AsRef<Path>) -> io::Result<Self> {
            Err(unsupported())
        }
        pub fn try_clone(&self) -> io::Result<Self> {
            match *self {}
        }
        pub fn set_read_timeout(&self, _: Option<Duration>) -> io::Result<()> {
            match *self {}
        }
        pub fn set_write_timeout(&self, _: Option<Duration>) -> io::Result<()> {
            match *self {}
        }
    }

    impl io::Read for Stream {
        fn read(&mut self, _: &mut [u8]) -> io::Result<usize> {
            match *self {}
        }
    }

    impl io::Write for Stream {
        fn write(&mut self, _: &[u8]) -> io::Result<usize> {
            match *self {}
        }
        fn flush(&mut self) -> io::Result<()> {
            match *self {}
        }
    }

    /// A listener that cannot exist here.
    pub enum Listener {}

    impl Listener {
        pub fn bind(_: impl AsRef<Path>) -> io::Result<Self> {
            Err(unsupported())
        }
        pub fn incoming(&self) -> std::iter::Empty<io::Result<Stream>> {
            match *self {}
        }
    }
}
