//! What a run hands back between steps: the time series, strobes and sensor samples kept for the
//! output files, and the progress bar (drawn only when stderr is a terminal).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::VecDeque;
use std::io::IsTerminal;

use kapitza_core::sim::Recorder;

/// Most time-series points a run keeps; the output interval is widened to stay below it.
pub const SERIES_CAP: usize = 200_000;
/// Most strobes and sensor samples kept: the last ones, where the motion has settled.
pub const TAIL_CAP: usize = 200_000;

/// One stroboscopic sample: drive period k, time (s), θ (rad, unwrapped), θ' (rad/s), and the
/// period-mean θ (rad; NaN outside the classifier's analysis window).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrobeRow {
    pub k: u64,
    pub t: f64,
    pub theta: f64,
    pub rate: f64,
    pub mean: f64,
}

/// A [`Recorder`] that keeps what the output files need.
pub struct Collect {
    keep: bool,
    /// (t, θ unwrapped, θ') at the output interval.
    pub series: Vec<[f64; 3]>,
    /// The last [`TAIL_CAP`] strobes.
    pub strobes: VecDeque<StrobeRow>,
    /// The last [`TAIL_CAP`] sensor samples (t, reported angle in rad).
    pub sensed: VecDeque<(f64, f64)>,
    /// Sensor samples the run produced in all (more than kept on long runs).
    pub sensed_total: u64,
    bar: ProgressBar,
}

impl Collect {
    /// `keep`: whether to keep samples at all (only `--out` needs them).
    pub fn new(keep: bool) -> Self {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(Some(1000), target);
        if let Ok(style) = ProgressStyle::with_template(
            "simulating {wide_bar} {percent:>3}%  elapsed {elapsed}, about {eta} left",
        ) {
            bar.set_style(style);
        }
        Self {
            keep,
            series: Vec::new(),
            strobes: VecDeque::new(),
            sensed: VecDeque::new(),
            sensed_total: 0,
            bar,
        }
    }

    /// Removes the progress bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Recorder for Collect {
    fn sample(&mut self, t: f64, theta: f64, rate: f64) {
        // The interval keeps the series under the cap; the margin absorbs rounding at the end.
        if self.keep && self.series.len() < SERIES_CAP + 16 {
            self.series.push([t, theta, rate]);
        }
    }

    fn strobe(&mut self, k: u64, t: f64, theta: f64, rate: f64, mean: f64) {
        if self.keep {
            if self.strobes.len() == TAIL_CAP {
                self.strobes.pop_front();
            }
            self.strobes.push_back(StrobeRow {
                k,
                t,
                theta,
                rate,
                mean,
            });
        }
    }

    fn sensed(&mut self, t: f64, angle: f64) {
        self.sensed_total += 1;
        if self.keep {
            if self.sensed.len() == TAIL_CAP {
                self.sensed.pop_front();
            }
            self.sensed.push_back((t, angle));
        }
    }

    fn progress(&mut self, done: f64) {
        self.bar.set_position((done * 1000.0).round() as u64);
    }
}

/// The output interval (s): `samples_per_period` per drive period, widened so a run of
/// `duration` seconds yields at most [`SERIES_CAP`] points.
pub fn output_interval(period: f64, samples_per_period: u32, duration: f64) -> f64 {
    (period / f64::from(samples_per_period.max(1))).max(duration / (SERIES_CAP - 1) as f64)
}
