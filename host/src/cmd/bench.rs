//! `kapitza bench`: work-precision measurements of every way the project computes an answer,
//! the ratio to a peer at matched error, and where accuracy stops mattering.

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;

use crate::bench::{self, plots, report, Plan, Progress};

/// Measure what accuracy costs: each integrator, step or tolerance, model fidelity and number
/// format against a converged reference on four scenes (settling, flutter, chaotic, long
/// undamped), side by side with the ode_solvers crate's Dopri5 and Dop853; the stability
/// criteria against Floquet; and the cheapest method that gets each scene's physical question
/// right.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// The reduced ladders and short horizons CI runs (well under a minute).
    #[arg(long)]
    pub quick: bool,
    /// Write bench.json, report.md, the CSV files and the PNG plots into DIR (created if
    /// missing).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print the results as JSON instead of the summary tables.
    #[arg(long)]
    pub json: bool,
}

struct Bar(ProgressBar);

impl Bar {
    fn new() -> Self {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(Some(1), target);
        if let Some(style) = crate::record::style(
            "measuring {wide_bar} {pos}/{len}  {elapsed}, about {eta} left  {msg}",
        ) {
            bar.set_style(style);
        }
        Bar(bar)
    }
}

impl Progress for Bar {
    fn set_total(&mut self, total: u64) {
        self.0.set_length(total);
    }
    fn tick(&mut self, what: &str) {
        self.0.set_message(what.to_string());
        self.0.inc(1);
    }
}

/// The command line that regenerates a run, for the report.
fn command(args: &Args) -> String {
    let mut c = String::from("cargo run --release -p kapitza -- bench");
    if args.quick {
        c.push_str(" --quick");
    }
    if let Some(dir) = &args.out {
        c.push_str(&format!(" --out {}", dir.display()));
    }
    c
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    // An unwritable --out must not throw away a whole benchmark: checked before it.
    if let Some(dir) = &args.out {
        crate::files::check_out_dir("--out", dir)?;
    }
    let plan = if args.quick {
        Plan::quick()
    } else {
        Plan::full()
    };
    let mut bar = Bar::new();
    let results = bench::run(&plan, &mut bar);
    bar.0.finish_and_clear();
    let results = results?;
    let json = serde_json::to_string_pretty(&results)?;
    if let Some(dir) = &args.out {
        let path = dir.join("bench.json");
        std::fs::write(&path, &json).with_context(|| format!("cannot write {}", path.display()))?;
        let path = dir.join("report.md");
        std::fs::write(&path, report::markdown(&results, &command(args)))
            .with_context(|| format!("cannot write {}", path.display()))?;
        report::csv(&results, dir)?;
        plots::all(&results, dir)?;
    }
    if args.json {
        writeln!(out, "{json}")?;
        return Ok(());
    }
    writeln!(
        out,
        "{} run: {} measurements on {} scenes in {:.0} s",
        if results.quick { "quick" } else { "full" },
        results.measurements.len(),
        results.scenes.len(),
        results.wall_s
    )?;
    writeln!(out, "\nOurs over the peer at matched error (goal ≤ 0.5):\n")?;
    write!(out, "{}", report::peer_table(&results.peer_ratios))?;
    writeln!(
        out,
        "\nReal-time factors, 60 s of the tilted scene (Q = 50) at a final error of 1e-6:\n"
    )?;
    write!(out, "{}", report::realtime_table(&results))?;
    writeln!(
        out,
        "\nThe physical question (outcome kind, angle to 0.1°):\n"
    )?;
    write!(out, "{}", report::physical_table(&results))?;
    if let Some(dir) = &args.out {
        writeln!(
            out,
            "\nWrote bench.json, report.md, CSV files and plots to {}",
            dir.display()
        )?;
    }
    Ok(())
}
