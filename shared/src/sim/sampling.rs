//! Everything the simulator samples between integrator steps, on one schedule each:
//! stroboscopic instants (drive phase 2πk), period means for the analysis window, output
//! samples, and sensor samples.
//!
//! Every integrator hands each step to [`Sampler::step`] with an [`Interpolant`]: DOP853's dense
//! output, or a cubic Hermite interpolant for the fixed-step methods. Points that fall on a step's
//! end use the step's own state exactly.

use super::classify::{Strobe, Strobes, WINDOW};
use super::sensor::Encoder;
use super::signal::Schedule;
use crate::math;
use crate::Real;

/// Sub-samples per drive period for the period mean. The mean of equally spaced samples over a
/// whole period is exact for every harmonic below the 16th (periodic trapezoid rule).
pub const MEAN_POINTS: u32 = 16;

/// The state anywhere inside one step.
pub trait Interpolant {
    /// (θ, θ') at t in [t0, t1] of the step.
    fn at(&mut self, t: f64) -> (f64, f64);
}

/// Receives what a run produces. Every method has a default that ignores it.
pub trait Recorder {
    /// An output sample of the true state.
    fn sample(&mut self, _t: f64, _theta: f64, _rate: f64) {}
    /// The k-th stroboscopic sample; `mean` is the period mean when it was computed (the
    /// analysis window), else NaN.
    fn strobe(&mut self, _k: u64, _t: f64, _theta: f64, _rate: f64, _mean: f64) {}
    /// What the sensor reports at t (only with the `sensor` effect).
    fn sensed(&mut self, _t: f64, _angle: f64) {}
    /// Fraction of the run done, about every 1 %.
    fn progress(&mut self, _done: f64) {}
    /// Whether this recorder wants the stroboscopic samples; if neither it nor the classifier
    /// does, they are not computed at all.
    fn wants_strobes(&self) -> bool {
        true
    }
}

/// A recorder that keeps nothing.
pub struct Discard;
impl Recorder for Discard {
    fn wants_strobes(&self) -> bool {
        false
    }
}

/// Where a run's samples go: the recorder, and the classifier's window of strobes when the run
/// classifies. The window (1024 strobes) is borrowed from the caller, so a run that does not
/// classify allocates none and its sampler stays small enough to move for free.
pub struct Sink<'a, Rec> {
    pub rec: &'a mut Rec,
    pub window: Option<&'a mut Strobes>,
}

/// The schedules of one run.
pub struct Sampler<'a, Rec: Recorder> {
    schedule: Schedule,
    /// Next strobe index and its time.
    next_k: u64,
    next_strobe: f64,
    last_strobe: f64,
    /// Strobes from this index on get a period mean.
    window_from: u64,
    /// Next period-mean sub-sample index j in 0..MEAN_POINTS (of period next_k), its time, sum.
    sub_j: u32,
    sub_t: f64,
    sub_sum: f64,
    out_dt: f64,
    out_i: u64,
    sensor: Option<Encoder>,
    sensor_i: u64,
    t_end: f64,
    next_progress: f64,
    /// The earliest of all the schedules: a step ending before it has nothing to do.
    next_event: f64,
    /// The classifier's window (when the run classifies).
    pub strobes: Option<&'a mut Strobes>,
    /// (k, t, θ, θ') at the strobe that opens the analysis window: where a Lyapunov run starts.
    pub window_start: Option<(u64, f64, f64, f64)>,
    pub rec: &'a mut Rec,
}

impl<'a, Rec: Recorder> Sampler<'a, Rec> {
    /// `strobes_total`: the number of strobes the run will see; `out_dt`: output interval (0 for
    /// none); a window in `sink`: keep the analysis window (strobes with period means) there for
    /// the classifier. A run that neither classifies nor records strobes computes none.
    pub fn new(
        schedule: Schedule,
        strobes_total: u64,
        out_dt: f64,
        sensor: Option<Encoder>,
        t_end: f64,
        sink: Sink<'a, Rec>,
    ) -> Self {
        let Sink { rec, window } = sink;
        let classify = window.is_some();
        let window_from = if classify {
            strobes_total.saturating_sub(WINDOW as u64 - 1).max(1)
        } else {
            u64::MAX
        };
        let first = if classify || rec.wants_strobes() {
            strobe_time(&schedule, 1)
        } else {
            f64::INFINITY
        };
        let mut s = Self {
            schedule,
            next_k: 1,
            next_strobe: first,
            last_strobe: 0.0,
            window_from,
            sub_j: 0,
            sub_t: f64::INFINITY,
            sub_sum: 0.0,
            out_dt,
            out_i: 0,
            sensor,
            sensor_i: 0,
            t_end,
            next_progress: 0.0,
            next_event: 0.0,
            strobes: window,
            window_start: None,
            rec,
        };
        s.plan_sub();
        s
    }

    fn plan_sub(&mut self) {
        self.sub_j = 0;
        self.sub_sum = 0.0;
        self.sub_t = if self.next_k >= self.window_from {
            self.last_strobe
        } else {
            f64::INFINITY
        };
    }

    fn next_out(&self) -> f64 {
        if self.out_dt > 0.0 {
            self.out_i as f64 * self.out_dt
        } else {
            f64::INFINITY
        }
    }

    fn next_sensor(&self) -> f64 {
        self.sensor
            .as_ref()
            .map_or(f64::INFINITY, |e| self.sensor_i as f64 * e.interval())
    }

    /// Handles the start of the run (t = 0 output and sensor samples).
    pub fn start(&mut self, theta: f64, rate: f64) {
        if self.window_from == 1 {
            self.window_start = Some((0, 0.0, theta, rate));
        }
        self.handle_until(0.0, &mut |_| (theta, rate), theta, rate);
    }

    /// Handles every scheduled point in (t0, t1] of an accepted step ending in state (θ1, θ'1).
    #[inline]
    pub fn step(&mut self, t1: f64, end: (f64, f64), interp: &mut dyn Interpolant) {
        // The common step has nothing to sample: one comparison (with the rounding allowance
        // that handle_until uses for points on the step's end).
        if t1 + 1e-12 * t1.abs().max(1.0) < self.next_event {
            return;
        }
        self.handle_until(t1, &mut |t| interp.at(t), end.0, end.1);
        if t1 >= self.next_progress {
            self.rec.progress((t1 / self.t_end).min(1.0));
            self.next_progress = t1 + 0.01 * self.t_end;
        }
        self.next_event = self
            .next_strobe
            .min(self.sub_t)
            .min(self.next_out())
            .min(self.next_sensor())
            .min(self.next_progress);
    }

    fn handle_until(&mut self, t1: f64, at: &mut dyn FnMut(f64) -> (f64, f64), th1: f64, v1: f64) {
        // A point within rounding of the step's end is the step's end.
        let tol = 1e-12 * t1.abs().max(1.0);
        let mut state = |t: f64| {
            if (t - t1).abs() <= tol {
                (th1, v1)
            } else {
                at(t)
            }
        };
        loop {
            let t = self
                .next_strobe
                .min(self.sub_t)
                .min(self.next_out())
                .min(self.next_sensor());
            if t > t1 + tol || t > self.t_end + tol {
                return;
            }
            let (th, v) = state(t);
            if t == self.sub_t {
                self.sub_sum += th;
                self.sub_j += 1;
                let span = self.next_strobe - self.last_strobe;
                self.sub_t = if self.sub_j < MEAN_POINTS {
                    self.last_strobe + span * f64::from(self.sub_j) / f64::from(MEAN_POINTS)
                } else {
                    f64::INFINITY
                };
            } else if t == self.next_strobe {
                let in_window = self.next_k >= self.window_from;
                let mean = if in_window {
                    self.sub_sum / f64::from(MEAN_POINTS)
                } else {
                    f64::NAN
                };
                if let (true, Some(window)) = (in_window, self.strobes.as_deref_mut()) {
                    window.push(Strobe {
                        theta: th,
                        rate: v,
                        mean,
                    });
                }
                if self.next_k + 1 == self.window_from {
                    self.window_start = Some((self.next_k, t, th, v));
                }
                self.rec.strobe(self.next_k, t, th, v, mean);
                self.last_strobe = t;
                self.next_k += 1;
                self.next_strobe = strobe_time(&self.schedule, self.next_k);
                self.plan_sub();
            } else if t == self.next_out() {
                self.rec.sample(t, th, v);
                self.out_i += 1;
            } else {
                let e = self
                    .sensor
                    .as_mut()
                    .expect("sensor schedule without a sensor");
                let m = e.measure(th);
                self.rec.sensed(t, m);
                self.sensor_i += 1;
            }
        }
    }
}

/// The k-th stroboscopic instant: drive phase 2πk.
pub fn strobe_time(schedule: &Schedule, k: u64) -> f64 {
    schedule.time_of_phase(k as f64 * math::TAU)
}

/// Cubic Hermite interpolation over a fixed step from (y0, f0) to (y1, f1): third-order
/// accurate, enough for sampling a fourth-order method's output.
pub struct Hermite<R> {
    pub t0: f64,
    pub t1: f64,
    pub y0: [R; 2],
    pub y1: [R; 2],
    pub f0: [R; 2],
    pub f1: [R; 2],
}

impl<R: Real> Interpolant for Hermite<R> {
    fn at(&mut self, t: f64) -> (f64, f64) {
        let h = self.t1 - self.t0;
        let s = (t - self.t0) / h;
        let (s2, s3) = (s * s, s * s * s);
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        let y = |i: usize| {
            h00 * self.y0[i].to_f64()
                + h10 * h * self.f0[i].to_f64()
                + h01 * self.y1[i].to_f64()
                + h11 * h * self.f1[i].to_f64()
        };
        (y(0), y(1))
    }
}
