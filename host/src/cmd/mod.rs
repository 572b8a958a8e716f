//! One module per subcommand: its arguments (doc comments are the help text) and `run()`.

pub mod attach;
pub mod bench;
pub mod boundary;
pub mod calibrate;
pub mod chart;
pub mod config;
pub mod demo;
pub mod flash;
pub mod monitor;
pub mod ports;
pub mod predict;
pub mod probes;
pub mod progress;
pub mod rig_args;
pub mod rig_serve;
pub mod set;
pub mod simulate;
pub mod status;
pub mod stop;
