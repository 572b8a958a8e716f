//! What a run hands back between steps: the time series, strobes and sensor samples kept for the
//! output files, the drive periods and the end window the plots draw, and the progress bar
//! (drawn only when stderr is a terminal).

mod periods;
mod window;

pub use periods::{Bucket, PeriodSum, Periods};
pub use window::Window;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::VecDeque;
use std::io::IsTerminal;
use std::time::Duration;

use kapitza_core::sim::Recorder;

/// Most time-series points a run keeps for `series.csv`: long runs keep every n-th sample.
pub const SERIES_CAP: usize = 200_000;
/// Most strobes and sensor samples kept: the last ones, where the motion has settled.
pub const TAIL_CAP: usize = 200_000;
/// Samples per drive period the plots need to draw a smooth curve (`--samples-per-period` is
/// raised to a multiple of itself at least this large for them).
pub const PLOT_SAMPLES_PER_PERIOD: u32 = 64;
/// Drive periods kept one by one from the start (the transient).
pub const FIRST_PERIODS: usize = 8192;
/// Buckets of the whole run's period means.
pub const WHOLE_BUCKETS: usize = 4096;
/// Most samples the end window may hold.
pub const WINDOW_CAP: u64 = 2_000_000;
/// Output samples a run may ask the simulator for (it allows 1e9).
const MAX_SAMPLES: f64 = 5e8;

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

/// How densely a run is sampled for the output files and the plots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plan {
    /// Samples per drive period, a multiple of `--samples-per-period` unless the run is too
    /// long for that.
    pub per_period: u32,
    /// The output interval (s): a drive period over `per_period`.
    pub dt: f64,
    /// `series.csv` keeps every n-th sample.
    pub series_every: u64,
    /// Drive periods in the end window.
    pub window_periods: u64,
}

impl Plan {
    /// `period`: the drive period (s); `periods`: the run's length in periods; `smooth`: raise
    /// the density to [`PLOT_SAMPLES_PER_PERIOD`] (not needed for the averaged model's slow
    /// angle, which has no motion within a period).
    pub fn new(
        period: f64,
        periods: f64,
        samples_per_period: u32,
        window_periods: u64,
        smooth: bool,
    ) -> Result<Self, String> {
        let spp = samples_per_period.max(1);
        let wanted = if smooth {
            spp * PLOT_SAMPLES_PER_PERIOD.div_ceil(spp)
        } else {
            spp
        };
        let afford = (MAX_SAMPLES / periods.max(1.0)).floor().max(1.0);
        let per_period = f64::from(wanted).min(afford) as u32;
        let total = periods.max(1.0) * f64::from(per_period) + 1.0;
        let every = (per_period / spp).max(1);
        let series_every = u64::from(every).max((total / SERIES_CAP as f64).ceil() as u64);
        let window_periods = window_periods.clamp(1, periods.ceil().max(1.0) as u64);
        if window_periods * u64::from(per_period) > WINDOW_CAP {
            return Err(format!(
                "--window {window_periods} periods at {per_period} samples a period is more than {WINDOW_CAP} samples: ask for a shorter window"
            ));
        }
        Ok(Self {
            per_period,
            dt: period / f64::from(per_period),
            series_every,
            window_periods,
        })
    }
}

/// What the plots and files need, sampled on a [`Plan`].
pub struct Kept {
    pub plan: Plan,
    /// (t, θ unwrapped, θ') for `series.csv`.
    pub series: Vec<[f64; 3]>,
    /// The first [`FIRST_PERIODS`] drive periods.
    pub first: Periods,
    /// The whole run in at most [`WHOLE_BUCKETS`] buckets.
    pub whole: Periods,
    /// The last `window_periods` drive periods at full resolution.
    pub window: Window,
    sum: PeriodSum,
    index: u64,
}

impl Kept {
    pub fn new(plan: Plan) -> Self {
        Self {
            plan,
            series: Vec::new(),
            first: Periods::first(FIRST_PERIODS),
            whole: Periods::growing(WHOLE_BUCKETS),
            window: Window::new((plan.window_periods * u64::from(plan.per_period)) as usize + 1),
            sum: PeriodSum::default(),
            index: 0,
        }
    }

    fn sample(&mut self, t: f64, theta: f64, rate: f64) {
        // The margin absorbs rounding at the end.
        if self.index.is_multiple_of(self.plan.series_every) && self.series.len() < SERIES_CAP + 16
        {
            self.series.push([t, theta, rate]);
        }
        self.index += 1;
        self.window.push([t, theta, rate]);
        if let Some(b) = self
            .sum
            .add(self.plan.per_period, self.plan.dt, t, theta, rate)
        {
            self.first.push(b);
            self.whole.push(b);
        }
    }
}

/// A [`Recorder`] that keeps what the output files need.
pub struct Collect {
    /// `None` when nothing is written.
    pub kept: Option<Kept>,
    /// The last [`TAIL_CAP`] strobes.
    pub strobes: VecDeque<StrobeRow>,
    /// The last [`TAIL_CAP`] sensor samples (t, reported angle in rad).
    pub sensed: VecDeque<(f64, f64)>,
    /// Sensor samples the run produced in all (more than kept on long runs).
    pub sensed_total: u64,
    bar: Progress,
}

impl Collect {
    /// `plan`: what to keep (only `--out` needs anything).
    pub fn new(plan: Option<Plan>) -> Self {
        Self {
            kept: plan.map(Kept::new),
            strobes: VecDeque::new(),
            sensed: VecDeque::new(),
            sensed_total: 0,
            bar: Progress::new("simulating"),
        }
    }

    /// Removes the progress bar.
    pub fn finish(&self) {
        self.bar.bar.finish_and_clear();
    }
}

impl Recorder for Collect {
    fn sample(&mut self, t: f64, theta: f64, rate: f64) {
        if let Some(k) = &mut self.kept {
            k.sample(t, theta, rate);
        }
    }

    fn strobe(&mut self, k: u64, t: f64, theta: f64, rate: f64, mean: f64) {
        if self.kept.is_some() {
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
        if self.kept.is_some() {
            if self.sensed.len() == TAIL_CAP {
                self.sensed.pop_front();
            }
            self.sensed.push_back((t, angle));
        }
    }

    fn progress(&mut self, done: f64) {
        self.bar.set(done);
    }
}

/// Steps of a progress bar over one run.
pub const PROGRESS_STEPS: u64 = 1000;

/// A progress bar on stderr (hidden when stderr is not a terminal) that redraws itself several
/// times a second, so its clock and spinner move between the run's progress reports.
pub struct Progress {
    pub bar: ProgressBar,
}

impl Progress {
    /// A bar over one run, `what` its label.
    pub fn new(what: &str) -> Self {
        let bar = bar(
            PROGRESS_STEPS,
            &format!("{{spinner}} {what} {{wide_bar}} {{percent:>3}}%  elapsed {{elapsed}}, about {{eta}} left"),
        );
        Self { bar }
    }

    /// The run is `done` (0…1) through.
    pub fn set(&self, done: f64) {
        self.bar
            .set_position((done.clamp(0.0, 1.0) * PROGRESS_STEPS as f64).round() as u64);
    }
}

/// `template` with its `{eta}` the remaining time at the rate so far ([`crate::budget::remaining`]),
/// `?` before anything is done: indicatif's own estimate reads "0 s" until its first steps.
pub fn style(template: &str) -> Option<ProgressStyle> {
    let eta = |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
        let text = crate::budget::remaining(s.elapsed().as_secs_f64(), f64::from(s.fraction()))
            .map_or_else(|| "?".to_string(), crate::budget::human);
        let _ = w.write_str(&text);
    };
    ProgressStyle::with_template(template)
        .ok()
        .map(|st| st.with_key("eta", eta))
}

/// A bar of `len` steps drawn with `template`, ticking on its own when drawn.
pub fn bar(len: u64, template: &str) -> ProgressBar {
    let target = if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(len), target);
    if let Some(style) = style(template) {
        bar.set_style(style);
    }
    if !bar.is_hidden() {
        bar.enable_steady_tick(Duration::from_millis(120));
    }
    bar
}

/// A [`Recorder`] that keeps nothing and moves a shared bar by its run's share: one run of
/// many (a map's cell) adds [`PROGRESS_STEPS`] to the bar over its course.
pub struct Share<'a> {
    bar: &'a ProgressBar,
    done: u64,
}

impl<'a> Share<'a> {
    pub fn new(bar: &'a ProgressBar) -> Self {
        Self { bar, done: 0 }
    }

    /// Adds what the run has not reported (all of it when it reported nothing).
    pub fn finish(self) {
        self.bar.inc(PROGRESS_STEPS - self.done);
    }
}

impl Recorder for Share<'_> {
    fn progress(&mut self, done: f64) {
        let now = (done.clamp(0.0, 1.0) * PROGRESS_STEPS as f64).round() as u64;
        if now > self.done {
            self.bar.inc(now - self.done);
            self.done = now;
        }
    }

    fn wants_strobes(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plan_keeps_series_csv_on_its_grid_and_plots_smooth() {
        // 10 samples a period asked: the plots get 70 (the first multiple of 10 ≥ 64), and
        // series.csv every 7th of them, so its rows stay 10 a period.
        let p = Plan::new(0.1, 600.0, 10, 20, true).unwrap();
        assert_eq!(
            (p.per_period, p.series_every, p.window_periods),
            (70, 7, 20)
        );
        assert!((p.dt - 0.1 / 70.0).abs() < 1e-18);
        // The averaged model's slow angle: as asked.
        assert_eq!(Plan::new(0.1, 600.0, 10, 20, false).unwrap().per_period, 10);
        // A million periods: series.csv stays under its cap.
        let p = Plan::new(0.1, 1e6, 20, 20, true).unwrap();
        assert!((1e6 * f64::from(p.per_period) / p.series_every as f64) < SERIES_CAP as f64);
        // A window longer than the run is the run; one too long to hold is refused.
        assert_eq!(
            Plan::new(0.1, 30.0, 20, 100, true).unwrap().window_periods,
            30
        );
        assert!(Plan::new(0.1, 1e6, 20, 100_000, true).is_err());
    }

    #[test]
    fn memory_stays_bounded_over_a_million_periods() {
        // 4 samples a period, a million periods, a 20-period window.
        let plan = Plan::new(1.0, 1e6, 4, 20, false).unwrap();
        let mut c = Collect::new(Some(plan));
        let n = 1_000_000 * 4;
        for i in 0..=n {
            let t = i as f64 * plan.dt;
            c.sample(t, (std::f64::consts::TAU * t).sin(), 0.0);
        }
        let k = c.kept.as_ref().unwrap();
        assert!(k.series.len() <= SERIES_CAP + 16);
        assert!(k.first.buckets().len() == FIRST_PERIODS);
        assert!(k.whole.buckets().len() <= WHOLE_BUCKETS);
        // The window: the last 20 periods at full resolution, equally spaced, ending at the end.
        assert_eq!(k.window.len(), 20 * 4 + 1);
        let ts: Vec<f64> = k.window.samples().map(|s| s[0]).collect();
        assert_eq!(*ts.last().unwrap(), n as f64 * plan.dt);
        for w in ts.windows(2) {
            assert!((w[1] - w[0] - plan.dt).abs() < 1e-9);
        }
    }

    #[test]
    fn a_long_run_reports_its_progress_many_times() {
        // 2000 periods of a flutter scene: the simulator reports about every 1 %, so the
        // shared bar moves in about a hundred steps, not once at the end.
        let text = r#"
            title = "flutter"
            [pendulum]
            geometry = "rod"
            length = 0.03
            [drive]
            amplitude = 0.0095
            omega = 300.0
            angle_deg = 180.0
            [initial]
            angle_deg = 175.0
            [run]
            periods = 2000
            fidelity = "full"
            [effects]
            viscous = { q = 20.0 }
        "#;
        let scene = crate::scene_file::parse(text, "test.toml", "test", &[])
            .unwrap()
            .scene;
        struct Count<'a>(Share<'a>, Vec<u64>);
        impl Recorder for Count<'_> {
            fn progress(&mut self, done: f64) {
                self.0.progress(done);
                self.1.push(self.0.bar.position());
            }
            fn wants_strobes(&self) -> bool {
                false
            }
        }
        let bar = ProgressBar::hidden();
        bar.set_length(PROGRESS_STEPS);
        let mut rec = Count(Share::new(&bar), Vec::new());
        kapitza_core::sim::simulate(&scene, &kapitza_core::sim::Options::default(), &mut rec)
            .unwrap();
        let seen = rec.1;
        assert!(seen.len() >= 90, "{} progress reports", seen.len());
        assert!(seen.windows(2).all(|w| w[0] <= w[1]));
        let distinct = seen.windows(2).filter(|w| w[0] < w[1]).count();
        assert!(distinct >= 90, "the bar moved {distinct} times");
        rec.0.finish();
        assert_eq!(bar.position(), PROGRESS_STEPS);
    }

    #[test]
    fn progress_reports_move_the_bar() {
        let p = Progress::new("test");
        p.set(0.25);
        assert_eq!(p.bar.position(), PROGRESS_STEPS / 4);
        p.set(2.0);
        assert_eq!(p.bar.position(), PROGRESS_STEPS);
    }
}
