//! The rig from the laptop: which port, the simulated rig, a checked connection, and who owns
//! the port.
//!
//! | module | concept |
//! |---|---|
//! | [`port`] | `--port`: a device, `auto` (the one ST-LINK), `sim`; listing ports; opening one |
//! | [`fields`] | the core's safety table with each field's key, unit and reason: the checks before sending, `config_fallbacks`, docs/rig.md's table |
//! | [`file`] | rig files: a simulated rig's true physics and the configuration it is given |
//! | [`simhost`] | a simulated rig against the wall clock (real time × speed), on any line |
//! | [`live`] | which of the estimator's numbers describe the pendulum now (never a frozen one) |
//! | [`predicted`] | what the model expects of the configured pendulum at a drive (the `predict` code) |
//! | [`session`] | a checked connection (version, configuration) and the rig's state in user units |
//! | [`names`] | modes, faults and stop reasons as every output names them; wire angles in degrees |
//! | [`owner`] | the process that owns a port serves a control socket; one-shot commands use it |
//! | [`served`] | the control socket of a command that drives the link itself (`calibrate`) |
//!
//! Exit statuses of the rig commands ([`Exit`]): 0 done, 1 refused or failed (the message says
//! what, if anything, changed), 2 usage, 3 no rig / the line failed (a stop the rig did not
//! confirm included), 4 `--wait` timed out, 5 superseded, 129 / 130 / 143 ended by SIGHUP /
//! SIGINT / SIGTERM after the stop.

pub mod control_socket;
pub mod fields;
pub mod file;
pub mod live;
pub mod names;
pub mod owner;
pub mod port;
pub mod predicted;
pub mod served;
pub mod session;
pub mod simhost;

use std::fmt;

/// Why a rig command failed, as its exit status.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// The rig refused (or a pre-run check failed): nothing changed.
    Refused = 1,
    /// No rig found, or the line failed.
    NoRig = 3,
    /// `--wait` ran out of time.
    WaitTimeout = 4,
    /// `--wait`: another command replaced the target before it settled.
    Superseded = 5,
    /// Ended by SIGHUP (128 + 1), after the stop.
    HungUp = 129,
    /// Ended by SIGINT (Ctrl-C, 128 + 2), after the stop.
    Interrupted = 130,
    /// Ended by SIGTERM (128 + 15), after the stop.
    Terminated = 143,
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

/// Catches SIGINT, SIGTERM and SIGHUP from here on ([`crate::signals::catch`]): a command can
/// stop the drive before it exits.
pub fn catch_interrupt() {
    crate::signals::catch();
}

/// A signal arrived since [`catch_interrupt`].
pub fn interrupted() -> bool {
    crate::signals::caught().is_some()
}
