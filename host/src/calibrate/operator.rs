//! The person at the rig: what a step asks them to do, and their answer. With `--yes` nothing
//! is waited for (a simulated rig's hand, `kapitza_core::simrig::hand`, does the lifting);
//! without it a line on stdin confirms, and `q` stops the calibration.

use std::io::{BufRead, IsTerminal, Write};

use anyhow::{bail, Result};

pub struct Operator<'a> {
    /// Go on without asking.
    pub yes: bool,
    /// Plain lines: no arrows or indentation.
    pub plain: bool,
    /// Where prompts and progress go (stdout, or stderr under `--json`).
    pub out: &'a mut dyn Write,
}

impl Operator<'_> {
    /// Says what to do, and waits for Enter unless `--yes`.
    pub fn ask(&mut self, what: &str) -> Result<()> {
        if self.plain {
            writeln!(self.out, "do: {what}")?;
        } else {
            writeln!(self.out, "  → {what}")?;
        }
        if self.yes {
            return Ok(());
        }
        write!(self.out, "    press Enter when done (q to stop): ")?;
        self.out.flush()?;
        let line = self.line()?;
        if line.trim() == "q" {
            bail!("calibration stopped at the prompt; nothing more was changed");
        }
        Ok(())
    }

    /// A line typed by the person (empty at end of input).
    pub fn line(&mut self) -> Result<String> {
        let mut s = String::new();
        std::io::stdin().lock().read_line(&mut s)?;
        Ok(s)
    }

    /// Whether a person can answer: not `--yes`, and stdin is a terminal.
    pub fn present(&self) -> bool {
        !self.yes && std::io::stdin().is_terminal()
    }

    pub fn say(&mut self, what: &str) -> Result<()> {
        writeln!(self.out, "{what}")?;
        Ok(())
    }
}
