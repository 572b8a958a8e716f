//! One module per subcommand: its arguments (doc comments are the help text) and `run()`.

pub mod bench;
pub mod boundary;
pub mod demo;
pub mod monitor;
pub mod predict;
pub mod simulate;
