//! The `kapitza` host tool as a library, so end-to-end tests run its commands in-process.
//!
//! One module per subcommand under [`cmd`], each holding its `clap` arguments and `run()`.
//!
//! | module | concept |
//! |---|---|
//! | [`bench`] | `kapitza bench`: work-precision, the peer, the stability ladder, the physical question |
//! | [`budget`] | cost known up front: estimates, the CPU budget, remaining time |
//! | [`calibrate`] | `kapitza calibrate`: the guided steps over the link, the person at the rig, what is written |
//! | [`chart`] | the field's charts: stability, equilibria and outcome maps, drawn as PNG and SVG |
//! | [`cli`] | parsing, dispatch, and the error type that picks the exit status |
//! | [`demo`] | the lecture demo as a script over the monitor's feed, measured against predicted |
//! | [`files`] | the file policy: named files never overwritten unless asked, inputs regular files, output directories checked first |
//! | [`flash`] | flashing the board through a debug probe: the image checked against memory.x first |
//! | [`input`] | checks of command-line numbers |
//! | [`link`] | the serial-link client: one method per command; "the line failed" apart from "the rig refused" |
//! | [`monitor`] | the live monitor: feeds, state machine, dashboard, JSON/CSV records |
//! | [`signals`] | SIGINT, SIGTERM, SIGHUP: which arrived, so a command stops the drive, then exits 130/143/129 |
//! | [`scene_file`] | scene files (TOML) and `--set` → the core's `Scene`, run options, `[expect]` |
//! | [`outcome`] | the simulator's verdict in user terms, and `[expect]` judged against it |
//! | [`record`] | what a run keeps for the output files, and its progress bar |
//! | [`rig`] | the rig from the laptop: ports, the simulated rig, checked connections, the port's owner |
//! | [`csv_out`] | CSV fields and files: the samples of a run, the fields of the bench's tables |
//! | [`plot`] | PNG plots with a bundled font |
//! | [`timing`] | measured cost of a call: wall and thread CPU time, medians of five batches |

pub mod bench;
pub mod budget;
pub mod calibrate;
pub mod chart;
pub mod cli;
pub mod cmd;
pub mod csv_out;
pub mod demo;
pub mod files;
pub mod flash;
pub mod input;
pub mod link;
pub mod monitor;
pub mod outcome;
pub mod plot;
pub mod record;
pub mod rig;
pub mod scene_file;
pub mod signals;
pub mod timing;

pub use cli::run;
