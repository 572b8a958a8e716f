//! What several kapitza test binaries share, as a library so each takes what it needs.
//!
//! | module | concept |
//! |---|---|
//! | [`sim_bench`] | the simulated rig behind its link, spoken to frame by frame as the host does |
//! | [`closed_loop`] | the rig logic in virtual time against the simulated pendulum and motor, with a hand on the pendulum |
//! | [`binary`] | the `kapitza` binary run as a user runs it: one-shot commands, long-running ones, a served rig |
//! | [`cli_doc`] | the `--json` key tables of `docs/cli.md`, compared with what a command prints |

pub mod binary;
pub mod cli_doc;
pub mod closed_loop;
pub mod sim_bench;
