//! `kapitza set`: drive strength R and drive angle θd.
//!
//! A start from idle waits for the rig's pre-run check: a failed check exits 1 with its reason
//! (with `--json`, the status printed first, `check` = `"failed"` and `check_reason`).
//! Through a running owner of the port (`kapitza attach`, `kapitza monitor`) it returns once
//! the rig has taken the command, or with `--wait` once the pendulum has settled. On its own it
//! owns the port and stays attached, printing the status as it changes, until the pendulum has
//! settled (`--wait`; then the drive follows the rig's link-loss policy: a soft stop a second
//! later) or until Ctrl-C (or SIGTERM, SIGHUP), which stops the drive.
//!
//! Exit statuses beyond 0/1/3: 4 `--wait` timed out; 5 another command replaced the target
//! before it settled ("superseded by …", naming its R and θd); a signal during `--wait` stops the
//! drive and exits 130 / 143 / 129 (3 when the rig did not confirm the stop). A signal ends a
//! plain `set`, which holds the drive until then, with 0 once the stop is confirmed.

use std::io::Write;
use std::time::{Duration, Instant};

use anyhow::{bail, Result};
use kapitza_core::link::convert::from_q16;
use kapitza_core::link::message::{Check, Mode};
use kapitza_core::link::Telemetry;
use kapitza_core::rig::config::RigConfig;

use super::progress::progress_writer;
use super::rig_args::RigArgs;
use crate::link::{Error, LineError};
use crate::rig::session::{line_failure, Session, StatusView};
use crate::rig::{self, Exit, Failure};
use crate::signals;

/// Set the drive strength R and the drive angle θd: starts the drive from idle, or changes it
/// (ramped and slewed at the rig's rate limits). R = 0 stops.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub rig: RigArgs,
    /// Drive strength R = A²ω²/(2gℓ), ≥ 0; the rig computes ω from its configured pendulum and
    /// stroke.
    #[arg(long, allow_hyphen_values = true)]
    pub r: f64,
    /// Drive angle θd in degrees: 0 shakes vertically, 90 horizontally, 180 vertically with
    /// the rod above the pivot.
    #[arg(long, allow_hyphen_values = true, value_name = "DEG")]
    pub angle: f64,
    /// Return once the pendulum has settled (exit 4 if it has not within --timeout).
    #[arg(long)]
    pub wait: bool,
    /// With --wait: seconds (wall time) to wait for it.
    #[arg(
        allow_hyphen_values = true,
        long,
        default_value_t = 120.0,
        value_name = "S",
        requires = "wait"
    )]
    pub timeout: f64,
    /// One JSON object at the end (the keys of `kapitza status --json`); progress goes to stderr.
    #[arg(long)]
    pub json: bool,
    /// Closed-loop R: `on` trims ω once settled so the R measured in situ is the R asked for
    /// (within the configuration's `closed_loop` band and rate); `off` returns to open loop.
    /// Stored in the rig's configuration.
    #[arg(long, value_name = "on|off", value_parser = ["on", "off"])]
    pub closed_loop: Option<String>,
}

/// The pre-run check takes 0.6 s of rig time; a verdict later than this means a lost rig.
const CHECK_TIMEOUT: Duration = Duration::from_secs(5);
/// How often the link is kept alive while waiting.
const KEEP_ALIVE: Duration = Duration::from_millis(250);
/// A progress line at least this often, and whenever the stage changes.
const PROGRESS_EVERY: Duration = Duration::from_secs(1);

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    if !(args.r.is_finite() && args.r >= 0.0) {
        bail!(
            "--r {} is out of range: expected a finite number >= 0",
            args.r
        );
    }
    if !args.angle.is_finite() {
        bail!(
            "--angle {} is out of range: expected a finite number of degrees",
            args.angle
        );
    }
    let timeout = crate::input::positive("--timeout", args.timeout)?;
    rig::catch_interrupt();
    let mut s = args.rig.connect_to_change("kapitza set")?;
    if let Some(on) = &args.closed_loop {
        let mut cfg = s.config;
        cfg.closed_loop.enabled = on == "on";
        if cfg != s.config {
            s.call(|c| c.set_config(&cfg))?;
            s.config = cfg;
        }
    }
    let starts = args.r > 0.0 && s.call(|c| c.status())?.mode == Mode::Idle;
    signals::check(|| "nothing was sent".into())?;
    s.call(|c| c.set_drive(args.r, args.angle))?;
    if starts {
        if let Err(why) = await_check(&mut s)? {
            if args.json {
                writeln!(out, "{}", serde_json::to_string_pretty(&s.snapshot()?)?)?;
            }
            return Err(Failure::new(
                Exit::Refused,
                format!(
                    "{}: the drive did not start: the pre-run check failed: {why}",
                    s.name
                ),
            )
            .into());
        }
    }
    let st = s.call(|c| c.status())?;
    let after = st.counters.commands;
    let ours = Target {
        r: args.r,
        theta_d_deg: args.angle,
    };
    let mut progress = progress_writer(args.json, &mut *out);
    writeln!(
        progress,
        "{}: R = {} at θd = {}° taken",
        s.name, args.r, args.angle
    )?;
    let done = if (s.via_owner && !args.wait) || args.r == 0.0 {
        true
    } else {
        let deadline = args
            .wait
            .then(|| Instant::now() + Duration::from_secs_f64(timeout));
        follow(&mut s, after, ours, deadline, &mut progress)?
    };
    drop(progress);
    if !done {
        writeln!(out, "{}: the rig confirmed the stop", s.name)?;
        return Ok(());
    }
    let view = s.snapshot()?;
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&view)?)?;
    } else {
        writeln!(out, "{}", view.text())?;
    }
    Ok(())
}

/// A start from idle runs the rig's pre-run check first: waits for its verdict (the status
/// polled, which also keeps the link alive). `Err` carries the reason it failed.
fn await_check(s: &mut Session) -> Result<Result<(), String>> {
    let deadline = Instant::now() + CHECK_TIMEOUT;
    loop {
        if let Some(sig) = signals::caught() {
            return Err(stopped(s, sig, true));
        }
        let st = s.call(|c| c.status())?;
        match st.check {
            Some(Check::Running) => {}
            Some(Check::Passed) => return Ok(Ok(())),
            Some(Check::Failed(v)) => return Ok(Err(v.to_string())),
            None => return Ok(Err("the rig did not run its pre-run check".into())),
        }
        if Instant::now() >= deadline {
            return Err(Failure::new(
                Exit::NoRig,
                format!("{}: no verdict from the pre-run check", s.name),
            )
            .into());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// The drive's target this command asked for; another command's `set` changes the status's.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Target {
    r: f64,
    theta_d_deg: f64,
}

/// How far the status's target may lie from the one asked for and still be it: the link's
/// I16F16 ω and θd round to 1.5e-5 (relative 1e-6 in R at ω ≈ 30 rad/s and above).
const SAME_R: f64 = 1e-4;
const SAME_DEG: f64 = 1e-3;

impl Target {
    /// Whether the status `st` carries another command's target rather than this one. With
    /// closed-loop R on, the rig trims ω itself within the configuration's band (in R).
    fn replaced_by(&self, st: &kapitza_core::link::Status, cfg: &RigConfig) -> bool {
        let r = cfg.r_for_omega(from_q16(st.omega_target));
        let deg = from_q16(st.theta_d_target_deg);
        let band = if cfg.closed_loop.enabled {
            cfg.closed_loop.band.max(SAME_R)
        } else {
            SAME_R
        };
        (deg - self.theta_d_deg).abs() > SAME_DEG || (r - self.r).abs() > band
    }
}

/// A signal while following: the drive stopped first. With `--wait` the signal's exit status
/// (the wait did not finish), else 0 once the rig confirmed the stop (a plain `set` ends so);
/// 3 when it did not confirm.
fn stopped(s: &mut Session, sig: signals::Signal, wait: bool) -> anyhow::Error {
    if s.client.stop().is_err() {
        return Failure::new(
            Exit::NoRig,
            format!(
                "{}: {}: the rig did not confirm the stop: it stops by itself once the line has \
                 been silent for its link timeout (link_timeout_ms, 1 s unless configured)",
                s.name,
                sig.name()
            ),
        )
        .into();
    }
    let what = format!(
        "{}: interrupted before the pendulum settled; the drive is stopping (the rig confirmed \
         the stop)",
        s.name
    );
    if wait {
        sig.failure(what)
    } else {
        Interrupted.into()
    }
}

/// A plain `set` ended by a signal, the stop confirmed: not a failure.
#[derive(Debug)]
struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted")
    }
}

impl std::error::Error for Interrupted {}

/// Follows the rig until the pendulum has settled after command number `after` (returns true),
/// a signal (the drive is stopped; returns false without `--wait`), the deadline (exit 4) or
/// another command's target (exit 5). Without a deadline only a signal ends it.
fn follow(
    s: &mut Session,
    after: u32,
    ours: Target,
    deadline: Option<Instant>,
    progress: &mut dyn Write,
) -> Result<bool> {
    s.call(|c| c.stream_telemetry(50))?;
    let mut next_alive = Instant::now();
    let mut last_stage = "";
    let mut next_line = Instant::now();
    loop {
        if let Some(sig) = signals::caught() {
            let e = stopped(s, sig, deadline.is_some());
            if e.is::<Interrupted>() {
                writeln!(progress, "{}: the drive is stopping", sig.name())?;
                return Ok(false);
            }
            return Err(e);
        }
        if deadline.is_some_and(|d| Instant::now() >= d) {
            return Err(Failure::new(
                Exit::WaitTimeout,
                format!("{}: the pendulum has not settled within --timeout", s.name),
            )
            .into());
        }
        if Instant::now() >= next_alive {
            next_alive = Instant::now() + KEEP_ALIVE;
            let st = s.call(|c| c.status())?;
            superseded(s, &st, ours)?;
            if let Mode::Faulted(_) | Mode::Idle = st.mode {
                let v = StatusView::new(&st, None, &s.config);
                let why = v.fault.or(v.last_stop).unwrap_or("stopped");
                return Err(Failure::new(
                    Exit::Refused,
                    format!("{}: the drive stopped ({}): {why}", s.name, v.mode),
                )
                .into());
            }
        }
        let t: Telemetry = match s.client.telemetry() {
            Ok(t) => t,
            Err(Error::Line(LineError::Timeout)) => continue,
            Err(e) => return Err(line_failure(&s.name, e)),
        };
        if t.commands < after {
            continue;
        }
        let stage = stage(&t);
        if stage != last_stage || Instant::now() >= next_line {
            writeln!(progress, "{}", progress_line(&t))?;
            last_stage = stage;
            next_line = Instant::now() + PROGRESS_EVERY;
        }
        if t.settled && deadline.is_some() {
            // Settled, but at whose target: the status says.
            let st = s.call(|c| c.status())?;
            superseded(s, &st, ours)?;
            return Ok(true);
        }
    }
}

/// Exit 5 when the status's target is another command's: a new drive, not a stop (a stop
/// from elsewhere ends the wait as a stopped drive).
fn superseded(s: &Session, st: &kapitza_core::link::Status, ours: Target) -> Result<()> {
    if st.omega_target != 0 && ours.replaced_by(st, &s.config) {
        let v = StatusView::new(st, None, &s.config);
        return Err(Failure::new(
            Exit::Superseded,
            format!(
                "{}: superseded by another command's R = {:.3} at θd = {:.1}° before the \
                 pendulum settled",
                s.name, v.r_target, v.drive_angle_target_deg
            ),
        )
        .into());
    }
    Ok(())
}

/// What the drive and the estimator are doing.
fn stage(t: &Telemetry) -> &'static str {
    if t.settled {
        "settled"
    } else if t.steady {
        "measuring"
    } else {
        "ramping"
    }
}

/// One line of what the rig does.
fn progress_line(t: &Telemetry) -> String {
    use crate::rig::live::Live;
    let live = Live::of(t.mode, t);
    let angle = match live.slow_angle_deg {
        Some(phi) => format!("φ = {phi:.1}°"),
        None => format!("θ = {:.1}°", live.theta_deg),
    };
    format!(
        "  ω = {:.0} rad/s, θd = {:.0}°, {angle}, {}",
        from_q16(t.omega),
        from_q16(t.theta_d_deg),
        stage(t)
    )
}
