//! SIGINT, SIGTERM and SIGHUP: which one arrived, so a command that moves hardware can stop the
//! drive first and then exit with the shell's status for that signal (128 + its number).
//!
//! ```text
//! installed (main)   a signal ends the process at once with 130 / 143 / 129 (model commands:
//!                    nothing half-written is finished as if complete)
//! after catch()      a signal is remembered; the command polls caught(), stops the drive,
//!                    says whether the rig confirmed it, and exits with Signal::exit()
//! ```
//! SIGHUP is Unix-only; elsewhere Ctrl-C and SIGTERM are caught as far as the platform raises
//! them.

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::Once;

use crate::rig::{Exit, Failure};

/// The signal that arrived first (0: none yet).
static CAUGHT: AtomicI32 = AtomicI32::new(0);
/// Whether a signal is left to the command (true) or ends the process at once (false).
static CATCHING: AtomicBool = AtomicBool::new(false);
static INSTALL: Once = Once::new();

/// A signal that asks the process to end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Signal {
    /// Ctrl-C.
    Int,
    /// `kill`, a service manager, a job scheduler's time limit.
    Term,
    /// The terminal went away (a closed window, a dropped ssh session).
    Hup,
}

impl Signal {
    fn number(self) -> i32 {
        match self {
            Self::Int => signal_hook::consts::SIGINT,
            Self::Term => signal_hook::consts::SIGTERM,
            #[cfg(unix)]
            Self::Hup => signal_hook::consts::SIGHUP,
            #[cfg(not(unix))]
            Self::Hup => 1,
        }
    }

    fn from_number(n: i32) -> Option<Self> {
        [Self::Int, Self::Term, Self::Hup]
            .into_iter()
            .find(|s| s.number() == n)
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Int => "SIGINT",
            Self::Term => "SIGTERM",
            Self::Hup => "SIGHUP",
        }
    }

    /// The exit status the shell gives a process this signal ended: 130, 143, 129.
    pub fn exit(self) -> Exit {
        match self {
            Self::Int => Exit::Interrupted,
            Self::Term => Exit::Terminated,
            Self::Hup => Exit::HungUp,
        }
    }

    /// A failure that exits with this signal's status, saying what was done.
    pub fn failure(self, what: impl std::fmt::Display) -> anyhow::Error {
        Failure::new(self.exit(), format!("{}: {what}", self.name())).into()
    }
}

#[cfg(unix)]
const HANDLED: [i32; 3] = [
    signal_hook::consts::SIGINT,
    signal_hook::consts::SIGTERM,
    signal_hook::consts::SIGHUP,
];
#[cfg(not(unix))]
const HANDLED: [i32; 2] = [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM];

/// Installs the handlers (once): until [`catch`], a signal ends the process at once with its
/// status.
pub fn install() {
    INSTALL.call_once(|| {
        for n in HANDLED {
            // SAFETY: the action only touches atomics and calls _exit, both async-signal-safe.
            let _ = unsafe {
                signal_hook::low_level::register(n, move || {
                    if CATCHING.load(Ordering::SeqCst) {
                        let _ = CAUGHT.compare_exchange(0, n, Ordering::SeqCst, Ordering::SeqCst);
                    } else {
                        signal_hook::low_level::exit(128 + n);
                    }
                })
            };
        }
    });
}

/// From here on a signal is remembered instead of ending the process: the command polls
/// [`caught`] and stops the drive before it exits.
pub fn catch() {
    CATCHING.store(true, Ordering::SeqCst);
    install();
}

/// The first signal since [`catch`], if any.
pub fn caught() -> Option<Signal> {
    Signal::from_number(CAUGHT.load(Ordering::SeqCst))
}

/// The command's end after a signal: `Ok` if no signal came, else the signal's failure
/// carrying `what` (what was done about the drive).
pub fn check(what: impl FnOnce() -> String) -> anyhow::Result<()> {
    match caught() {
        Some(s) => Err(s.failure(what())),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statuses_are_the_shells() {
        // 128 + the signal's number (POSIX: SIGHUP 1, SIGINT 2, SIGTERM 15).
        assert_eq!(Signal::Int.exit() as u8, 130);
        assert_eq!(Signal::Term.exit() as u8, 143);
        assert_eq!(Signal::Hup.exit() as u8, 129);
        #[cfg(unix)]
        for s in [Signal::Int, Signal::Term, Signal::Hup] {
            assert_eq!(i32::from(s.exit() as u8), 128 + s.number());
            assert_eq!(Signal::from_number(s.number()), Some(s));
        }
        assert_eq!(Signal::from_number(0), None);
    }
}
