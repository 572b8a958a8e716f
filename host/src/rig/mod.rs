//! The rig from the laptop: which port, the simulated rig, a checked connection, and who owns
//! the port.
//!
//! | module | concept |
//! |---|---|
//! | [`port`] | `--port`: a device, `auto` (the one ST-LINK), `sim`; listing ports; opening one |
//! | [`file`] | rig files: a simulated rig's true physics and the configuration it is given |
//! | [`simhost`] | a simulated rig against the wall clock (real time × speed), on any line |
//! | [`live`] | which of the estimator's numbers describe the pendulum now (never a frozen one) |
//! | [`predicted`] | what the model expects of the configured pendulum at a drive (the `predict` code) |
//! | [`session`] | a checked connection (version, configuration) and the rig's state in user units |
//! | [`names`] | modes, faults and stop reasons as every output names them; wire angles in degrees |
//! | [`owner`] | the process that owns a port serves a control socket; one-shot commands use it |
//!
//! Exit statuses of the rig commands: 0 done, 1 refused, 2 usage, 3 no rig / the line failed,
//! 4 `--wait` timed out ([`Exit`]).

pub mod file;
pub mod live;
pub mod names;
pub mod owner;
pub mod port;
pub mod predicted;
pub mod session;
pub mod simhost;

use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

/// Why a rig command failed, as its exit status.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// The rig refused (or a pre-run check failed): nothing changed.
    Refused = 1,
    /// No rig found, or the line failed.
    NoRig = 3,
    /// `--wait` ran out of time.
    WaitTimeout = 4,
}

/// A failure with the exit status it calls for.
#[derive(Debug)]
pub struct Failure {
    pub exit: Exit,
    pub message: String,
}

impl Failure {
    pub fn new(exit: Exit, message: impl Into<String>) -> Self {
        Self {
            exit,
            message: message.into(),
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Failure {}

static INTERRUPTED: AtomicBool = AtomicBool::new(false);
static HANDLER: Once = Once::new();

/// Catches Ctrl-C from here on: [`interrupted`] turns true instead of the process dying, so a
/// command can stop the drive before it exits.
pub fn catch_interrupt() {
    HANDLER.call_once(|| {
        let _ = ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst));
    });
}

/// Ctrl-C was pressed since [`catch_interrupt`].
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}
