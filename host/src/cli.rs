//! The command line: parse, dispatch, and one error type that knows its exit status.

use clap::{Parser, Subcommand};
use std::ffi::OsString;
use std::io::Write;
use std::process::ExitCode;

use crate::cmd;

/// Software for the Kapitza shaker rig: predict equilibria and stability of a pendulum whose
/// pivot is shaken along a tilted line.
#[derive(Debug, Parser)]
#[command(name = "kapitza", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    Predict(cmd::predict::Args),
    Boundary(cmd::boundary::Args),
    Simulate(cmd::simulate::Args),
    Bench(cmd::bench::Args),
    Attach(cmd::attach::Args),
    Ports(cmd::ports::Args),
    Status(cmd::status::Args),
    Set(cmd::set::Args),
    Stop(cmd::stop::StopArgs),
    Clear(cmd::stop::ClearArgs),
    Config(cmd::config::Args),
    Calibrate(cmd::calibrate::Args),
    /// A simulated rig for serial clients.
    Rig(cmd::rig_serve::Args),
    Monitor(cmd::monitor::Args),
    Demo(cmd::demo::Args),
    Chart(cmd::chart::Args),
    Flash(cmd::flash::Args),
    Probes(cmd::probes::Args),
}

/// What went wrong, and how the process should exit.
#[derive(Debug)]
pub enum Error {
    /// Bad command-line syntax, or `--help`/`--version` (clap prints and picks the status).
    Usage(clap::Error),
    /// Well-formed arguments with a value out of range, or a failure while running.
    Run(anyhow::Error),
}

impl Error {
    /// Prints the error (to stderr) and returns the exit status: 2 for usage errors as clap does,
    /// 0 for `--help`, a rig command's own status ([`crate::rig::Exit`]: 3 no rig, 4 `--wait`
    /// timed out), 1 for anything else.
    pub fn report(&self) -> ExitCode {
        match self {
            Self::Usage(e) => {
                let _ = e.print();
                ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
            }
            Self::Run(e) => {
                eprintln!("error: {e:#}");
                let code = e
                    .downcast_ref::<crate::rig::Failure>()
                    .map_or(1, |f| f.exit as u8);
                ExitCode::from(code)
            }
        }
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Usage(e) => write!(f, "{e}"),
            Self::Run(e) => write!(f, "{e:#}"),
        }
    }
}

impl From<anyhow::Error> for Error {
    fn from(e: anyhow::Error) -> Self {
        Self::Run(e)
    }
}

/// Parses `args` (the first is the program name) and runs the command, writing its output to
/// `out`.
pub fn run<I, T>(args: I, out: &mut dyn Write) -> Result<(), Error>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = Cli::try_parse_from(args).map_err(Error::Usage)?;
    match cli.command {
        Command::Predict(a) => cmd::predict::run(&a, out)?,
        Command::Boundary(a) => cmd::boundary::run(&a, out)?,
        Command::Simulate(a) => cmd::simulate::run(&a, out)?,
        Command::Bench(a) => cmd::bench::run(&a, out)?,
        Command::Attach(a) => cmd::attach::run(&a, out)?,
        Command::Ports(a) => cmd::ports::run(&a, out)?,
        Command::Status(a) => cmd::status::run(&a, out)?,
        Command::Set(a) => cmd::set::run(&a, out)?,
        Command::Stop(a) => cmd::stop::stop(&a, out)?,
        Command::Clear(a) => cmd::stop::clear(&a, out)?,
        Command::Config(a) => cmd::config::run(&a, out)?,
        Command::Calibrate(a) => cmd::calibrate::run(&a, out)?,
        Command::Rig(a) => cmd::rig_serve::run(&a, out)?,
        Command::Monitor(a) => cmd::monitor::run(&a, out)?,
        Command::Demo(a) => cmd::demo::run(&a, out)?,
        Command::Chart(a) => cmd::chart::run(&a, out)?,
        Command::Flash(a) => cmd::flash::run(&a, out)?,
        Command::Probes(a) => cmd::probes::run(&a, out)?,
    }
    Ok(())
}
