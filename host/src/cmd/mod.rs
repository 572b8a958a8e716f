//! One module per subcommand: its arguments (doc comments are the help text) and `run()`.

pub mod bench;
pub mod boundary;
pub mod chart;
pub mod predict;
pub mod simulate;
