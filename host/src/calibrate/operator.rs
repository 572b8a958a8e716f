//! The person at the rig: what a step asks them to do, and their answer. With `--yes` nothing
//! is waited for (a simulated rig's hand, `kapitza_core::simrig::hand`, does the lifting);
//! without it a line on stdin confirms, and `q` stops the calibration. Lines are read on a
//! thread of their own, so a signal or a stop from elsewhere is seen while a prompt waits.

use std::io::{BufRead, IsTerminal, Write};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::Duration;

use anyhow::Result;

pub struct Operator<'a> {
    /// Go on without asking.
    pub yes: bool,
    /// Plain lines: no arrows or indentation.
    pub plain: bool,
    /// Where prompts and progress go (stdout, or stderr under `--json`).
    pub out: &'a mut dyn Write,
    /// Lines from stdin, once the first is asked for.
    lines: Option<Receiver<std::io::Result<String>>>,
}

impl<'a> Operator<'a> {
    pub fn new(yes: bool, plain: bool, out: &'a mut dyn Write) -> Self {
        Self {
            yes,
            plain,
            out,
            lines: None,
        }
    }

    /// Says what to do; returns whether an answer is awaited (not with `--yes`).
    pub fn ask(&mut self, what: &str) -> Result<bool> {
        if self.plain {
            writeln!(self.out, "do: {what}")?;
        } else {
            writeln!(self.out, "  → {what}")?;
        }
        if self.yes {
            return Ok(false);
        }
        write!(self.out, "    press Enter when done (q to stop): ")?;
        self.out.flush()?;
        Ok(true)
    }

    /// A line typed by the person if one arrives within `wait` (empty at end of input).
    pub fn poll_line(&mut self, wait: Duration) -> Result<Option<String>> {
        self.out.flush()?;
        let lines = self.lines.get_or_insert_with(|| {
            let (tx, rx) = mpsc::channel();
            std::thread::spawn(move || loop {
                let mut s = String::new();
                let r = std::io::stdin().lock().read_line(&mut s);
                let end = !matches!(r, Ok(n) if n > 0);
                if tx.send(r.map(|_| s)).is_err() || end {
                    return;
                }
            });
            rx
        });
        match lines.recv_timeout(wait) {
            Ok(r) => Ok(Some(r?)),
            Err(RecvTimeoutError::Timeout) => Ok(None),
            // At end of input every line is empty.
            Err(RecvTimeoutError::Disconnected) => Ok(Some(String::new())),
        }
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
