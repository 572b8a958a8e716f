//! `kapitza monitor`'s machinery: a live dashboard on a terminal, one JSON record per frame off
//! one, and a CSV log — all fed by a [`Feed`], so the same code watches a serial port or a
//! simulated rig in this process.
//!
//! | module | concept |
//! |---|---|
//! | [`feed`] | what the monitor reads ([`Event`]) and may ask ([`Command`]), and the [`Feed`] trait |
//! | [`owner_feed`] | a feed over the port's owner ([`crate::rig::owner`]) on its own thread: keep-alive, control socket, reconnects |
//! | [`state`] | the state machine fed by events and keys; the numbers of a frame ([`Readings`]) |
//! | [`draw`] | the dashboard drawn from the state alone |
//! | [`plain`] | JSON per frame and the CSV log |
//!
//! ```text
//! feed ──events──▶ State ◀──keys (terminal)
//!                   │  ├──▶ draw (terminal) │ JSON per frame (off one) │ CSV rows
//!                   ▼
//!          Driver (the demo's script) ──commands──▶ feed
//! ```

pub mod draw;
pub mod feed;
pub mod owner_feed;
pub mod plain;
pub mod state;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use ratatui::crossterm::event::{self, KeyCode, KeyEventKind, KeyModifiers};

pub use feed::{Command, Event, Feed};
pub use state::{Key, Readings, State};

/// Something that drives the rig from what it sees (the demo's script).
pub trait Driver {
    /// Called after every event: the command to send now, if any.
    fn next(&mut self, state: &mut State) -> Option<Command>;
    /// How the command it asked for went.
    fn sent(&mut self, state: &mut State, c: Command, result: &Result<(), String>);
    fn finished(&self) -> bool;
}

/// What a run keeps and when it ends.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// End after this many seconds of the rig's clock (or of the wall clock without a frame).
    pub duration: Option<f64>,
    /// Log every frame here.
    pub csv: Option<PathBuf>,
    /// What to do when the log exists (`--force`, `--append`).
    pub csv_existing: crate::files::Existing,
}

/// What the loop off a terminal prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plain {
    /// One JSON object per telemetry frame; the event log (a lost link, a mode change) goes to
    /// stderr, so the records stay one kind of line.
    Records,
    /// The event log, line by line.
    Log,
    Nothing,
}

/// The state, the optional driver and the outputs, between the feed and the screen.
struct Session<'a, 'b> {
    feed: &'a mut dyn Feed,
    state: State,
    driver: Option<&'b mut dyn Driver>,
    csv: Option<(plain::Csv<BufWriter<File>>, PathBuf)>,
    duration: Option<f64>,
    last_event: Instant,
}

impl<'a, 'b> Session<'a, 'b> {
    fn new(
        feed: &'a mut dyn Feed,
        driver: Option<&'b mut dyn Driver>,
        opts: &Options,
    ) -> Result<Self> {
        let csv = match &opts.csv {
            Some(p) => {
                let f = crate::files::create_output("--csv", p, opts.csv_existing)?;
                let continuing = !crate::files::is_empty(&f);
                let w = BufWriter::new(f);
                let csv = if continuing {
                    plain::Csv::continuing(w)
                } else {
                    plain::Csv::new(w)
                };
                Some((csv, p.clone()))
            }
            None => None,
        };
        Ok(Self {
            feed,
            state: State::new(),
            driver,
            csv,
            duration: opts.duration,
            last_event: Instant::now(),
        })
    }

    /// Takes one event (waiting up to `timeout`) and lets the driver act on it. Returns the
    /// frame's readings when the event was telemetry.
    fn pump(&mut self, timeout: Duration) -> Result<Option<Readings>> {
        let Some(e) = self.feed.next_event(timeout) else {
            return Ok(None);
        };
        self.last_event = Instant::now();
        let telemetry = matches!(e, Event::Telemetry(_));
        self.state.on_event(e);
        let readings = telemetry.then(|| self.state.readings()).flatten();
        if let (Some(r), Some((csv, path))) = (&readings, &mut self.csv) {
            csv.row(r)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if let Some(d) = self.driver.as_deref_mut() {
            if let Some(c) = d.next(&mut self.state) {
                let result = self.feed.command(c);
                self.state.on_command(c, &result);
                d.sent(&mut self.state, c, &result);
            }
        }
        Ok(readings)
    }

    fn key(&mut self, k: Key) {
        if let Some(c) = self.state.on_key(k) {
            let result = self.feed.command(c);
            self.state.on_command(c, &result);
        }
    }

    fn done(&self) -> bool {
        let timed_out = self
            .duration
            .is_some_and(|d| self.state.t_s() >= d || self.last_event.elapsed().as_secs_f64() >= d);
        self.state.quit
            || timed_out
            || self.driver.as_ref().is_some_and(|d| d.finished())
            || crate::signals::caught().is_some()
    }

    fn finish(mut self) -> Result<State> {
        if let Some((csv, path)) = &mut self.csv {
            csv.flush()
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        Ok(self.state)
    }
}

/// Closes `feed` (the drive stopped) and says on stderr whether the rig confirmed the stop:
/// `Ok` if it did (or the feed drives nothing), exit 3 if it did not.
pub fn close(feed: &mut dyn Feed) -> Result<()> {
    match feed.close() {
        Some(true) => eprintln!("the drive is stopped: the rig confirmed the stop"),
        Some(false) => {
            return Err(crate::rig::Failure::new(
                crate::rig::Exit::NoRig,
                "the rig did not confirm the stop: it stops by itself once the line has been \
                 silent for its link timeout (link_timeout_ms, 1 s unless configured)",
            )
            .into())
        }
        None => {}
    }
    Ok(())
}

/// Runs off a terminal until the duration, the driver's end, or the feed's silence for the
/// duration; prints what `plain` says to `out`.
pub fn run_plain(
    feed: &mut dyn Feed,
    driver: Option<&mut dyn Driver>,
    opts: &Options,
    plain: Plain,
    out: &mut dyn Write,
) -> Result<State> {
    let mut s = Session::new(feed, driver, opts)?;
    let mut printed = 0;
    let mut stderr = std::io::stderr();
    while !s.done() {
        let r = s.pump(Duration::from_millis(100))?;
        let log: &mut dyn Write = match plain {
            Plain::Records => {
                if let Some(r) = r {
                    plain::json_line(&r, out)?;
                }
                &mut stderr
            }
            Plain::Log => &mut *out,
            Plain::Nothing => continue,
        };
        let new = (s.state.logged - printed) as usize;
        let skip = s.state.log.len().saturating_sub(new);
        for (t, line) in s.state.log.iter().skip(skip) {
            writeln!(log, "{t:9.2} s  {line}")?;
        }
        printed = s.state.logged;
    }
    s.finish()
}

/// Runs the dashboard on the terminal until `q`, the duration, or the driver's end (when
/// `stay` is false: with it the dashboard waits for `q`).
pub fn run_tui(
    feed: &mut dyn Feed,
    driver: Option<&mut dyn Driver>,
    opts: &Options,
    stay: bool,
) -> Result<State> {
    let mut s = Session::new(feed, driver, opts)?;
    let mut terminal = ratatui::init();
    let result = tui_loop(&mut s, &mut terminal, stay);
    ratatui::restore();
    result?;
    s.finish()
}

fn tui_loop(s: &mut Session, terminal: &mut ratatui::DefaultTerminal, stay: bool) -> Result<()> {
    let frame_period = Duration::from_millis(50);
    loop {
        terminal.draw(|f| draw::draw(f, &s.state))?;
        let until = Instant::now() + frame_period;
        while let Some(left) = until.checked_duration_since(Instant::now()) {
            s.pump(left.min(Duration::from_millis(10)))?;
        }
        while event::poll(Duration::ZERO)? {
            if let event::Event::Key(k) = event::read()? {
                if k.kind == KeyEventKind::Press {
                    if let Some(key) = key_of(k.code, k.modifiers) {
                        s.key(key);
                    }
                }
            }
        }
        let finished = s.driver.as_ref().is_some_and(|d| d.finished());
        if s.state.quit || crate::signals::caught().is_some() || (s.done() && !(stay && finished)) {
            return Ok(());
        }
    }
}

/// The terminal's key as the monitor's (Ctrl-C first: it must never read as `c`).
fn key_of(code: KeyCode, mods: KeyModifiers) -> Option<Key> {
    match code {
        KeyCode::Char('c') if mods.contains(KeyModifiers::CONTROL) => Some(Key::CtrlC),
        KeyCode::Char(ch) => Some(Key::Char(ch.to_ascii_lowercase())),
        KeyCode::Esc => Some(Key::Esc),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ctrl_c_quits_and_never_clears_a_fault() {
        assert_eq!(
            key_of(KeyCode::Char('c'), KeyModifiers::CONTROL),
            Some(Key::CtrlC)
        );
        assert_eq!(
            key_of(KeyCode::Char('c'), KeyModifiers::NONE),
            Some(Key::Char('c'))
        );
        // Caps lock or shift: the same keys.
        assert_eq!(
            key_of(KeyCode::Char('S'), KeyModifiers::SHIFT),
            Some(Key::Char('s'))
        );
        assert_eq!(key_of(KeyCode::Esc, KeyModifiers::NONE), Some(Key::Esc));
        assert_eq!(key_of(KeyCode::Enter, KeyModifiers::NONE), None);
    }
}
