//! Cost known up front: a long command estimates its CPU time before it starts and refuses work
//! past a generous budget unless `--no-budget`, saying the estimate.
//!
//! The budget, an hour of CPU, is far above the full `kapitza bench` (about 150 s): what it
//! refuses is a mistyped setting (`periods = 1e9`), not a long study.

use anyhow::{bail, Result};
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::{RunLength, Scene};
use kapitza_core::sim::{Options, PlannedRun};

/// Estimated CPU seconds past which a command refuses to start without `--no-budget`.
pub const BUDGET_S: f64 = 3600.0;

/// A duration in a person's units: "45 s", "12 min", "3.2 h", "41 days".
pub fn human(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "forever".into();
    }
    match seconds {
        s if s < 90.0 => format!("{s:.0} s"),
        s if s < 3600.0 => format!("{:.0} min", s / 60.0),
        s if s < 2.0 * 86_400.0 => format!("{:.1} h", s / 3600.0),
        s if s < 730.0 * 86_400.0 => format!("{:.0} days", s / 86_400.0),
        s => format!("{:.0} years", s / (365.25 * 86_400.0)),
    }
}

/// Refuses `what` (e.g. "this run") when its estimated CPU time passes [`BUDGET_S`], unless
/// `no_budget`.
pub fn check(what: &str, estimate_s: f64, no_budget: bool) -> Result<()> {
    // A NaN estimate is past any budget.
    let within = estimate_s.is_finite() && estimate_s <= BUDGET_S;
    if !no_budget && !within {
        bail!(
            "{what} would take about {} of CPU (estimated before starting), past the budget of \
             {}: nothing was run. Shorten it, or give --no-budget to run it anyway",
            human(estimate_s),
            human(BUDGET_S)
        );
    }
    Ok(())
}

/// Tells, on stderr, the estimate of a run long enough for a person to wonder (over 10 s).
pub fn announce(what: &str, estimate_s: f64) {
    if estimate_s > 10.0 {
        eprintln!("{what}: about {} of CPU estimated", human(estimate_s));
    }
}

/// Remaining time of a job `done` (0…1) through after `elapsed` seconds, extrapolating its
/// rate so far; `None` before anything is done.
pub fn remaining(elapsed: f64, done: f64) -> Option<f64> {
    (done > 0.0 && elapsed.is_finite()).then(|| elapsed * (1.0 - done.min(1.0)) / done)
}

/// Drive periods of the shortest pilot run; it grows fourfold until it takes [`PILOT_MIN_S`].
const PILOT_PERIODS: f64 = 16.0;
/// CPU time a pilot run must take for its rate to be measured (the clock's and the start's
/// cost made small).
const PILOT_MIN_S: f64 = 0.02;
/// The largest share of a run its pilots cover: they add at most 4/3 of it to the run's cost.
const PILOT_SHARE: f64 = 0.01;

/// The estimated CPU seconds of running `scene` with `options`: pilot runs of its first drive
/// periods, timed, scaled to its duration. `None` when a pilot fails (the run itself then says
/// why) or when the run is too short for a pilot (under 1600 drive periods).
pub fn simulation(scene: &Scene, options: &Options) -> Option<f64> {
    let full = PlannedRun::new(scene, options).ok()?;
    let total = full.duration();
    let period = kapitza_core::math::TAU / full.physical.omega;
    let mut pilot = *scene;
    let mut length = PILOT_PERIODS * period;
    let mut estimate = None;
    while length <= total * PILOT_SHARE {
        pilot.length = RunLength::Duration(length);
        let run = PlannedRun::new(&pilot, options).ok()?;
        let cpu0 = crate::timing::thread_cpu();
        run.run(&mut Discard).ok()?;
        let cpu = crate::timing::thread_cpu() - cpu0;
        estimate = Some(cpu * total / length);
        if cpu >= PILOT_MIN_S {
            break;
        }
        length *= 4.0;
    }
    estimate
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_refuses_past_an_hour_and_names_the_estimate() {
        check("this run", 3599.0, false).unwrap();
        let msg = format!("{:#}", check("this run", 5.0e4, false).unwrap_err());
        assert!(
            msg.contains("about 13.9 h")
                && msg.contains("budget of 1.0 h")
                && msg.contains("--no-budget"),
            "{msg}"
        );
        check("this run", 5.0e4, true).unwrap();
        // A cost that cannot be estimated as finite is past any budget.
        assert!(check("this run", f64::NAN, false).is_err());
    }

    #[test]
    fn remaining_time_extrapolates_the_rate() {
        // 10 s for 5 %: 190 s to go at the same rate.
        assert_eq!(remaining(10.0, 0.05), Some(190.0));
        assert_eq!(remaining(10.0, 0.0), None);
        assert_eq!(remaining(10.0, 1.0), Some(0.0));
    }

    #[test]
    fn durations_read_in_a_persons_units() {
        assert_eq!(human(42.0), "42 s");
        assert_eq!(human(600.0), "10 min");
        assert_eq!(human(3.0 * 3600.0), "3.0 h");
        assert_eq!(human(10.0 * 86_400.0), "10 days");
    }
}
