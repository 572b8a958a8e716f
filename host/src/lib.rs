//! The `kapitza` host tool as a library, so end-to-end tests run its commands in-process.
//!
//! One module per subcommand under [`cmd`], each holding its `clap` arguments and `run()`.

pub mod cli;
pub mod cmd;
pub mod input;
pub mod timing;

pub use cli::run;
