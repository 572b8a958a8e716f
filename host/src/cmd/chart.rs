//! `kapitza chart`: the field's classic pictures, each as PNG and SVG with the data behind it
//! (CSV, and `--json` on stdout).

use anyhow::Result;
use std::io::Write;

pub mod equilibria;
pub mod options;
pub mod outcomes;
pub mod regions;
pub mod stability;

/// Draw one of the classic pictures of the shaken pendulum (PNG, SVG and CSV into --out).
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub which: Which,
}

#[derive(Debug, Clone, clap::Subcommand)]
pub enum Which {
    Equilibria(equilibria::Args),
    Regions(regions::Args),
    Stability(stability::Args),
    Outcomes(outcomes::Args),
    Merge(outcomes::MergeArgs),
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    match &args.which {
        Which::Equilibria(a) => equilibria::run(a, out),
        Which::Regions(a) => regions::run(a, out),
        Which::Stability(a) => stability::run(a, out),
        Which::Outcomes(a) => outcomes::run(a, out),
        Which::Merge(a) => outcomes::merge(a, out),
    }
}
