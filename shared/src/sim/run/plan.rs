//! The scene checked and derived once: a [`PlannedRun`] holds what every later stage reads (the
//! physical constants, the fidelity decision, the duration and strobe count, the drive schedule,
//! the start state, the averaged model's R and wobble), so nothing downstream derives it again.

use super::checks::{check_method, output_interval};
use super::compose::finish;
use super::{EndState, Format, Method, Options, Report, SimError};
use crate::math;
use crate::real::Real;
use crate::sim::fidelity::{self, Decision};
use crate::sim::sampling::{Recorder, Sampler, Sink};
use crate::sim::scene::{Fidelity, Physical, Scene};
use crate::sim::sensor::Encoder;
use crate::sim::signal::{Schedule, Shaped, Steady};
use crate::sim::wobble::Wobble;

/// Everything a generic run needs besides the equation.
pub(in crate::sim) struct Context {
    pub method: Method,
    pub y0: (f64, f64),
    pub t_end: f64,
    pub schedule: Schedule,
    pub strobes_total: u64,
    pub out_dt: f64,
    pub sensor: Option<Encoder>,
    /// Drive period at the set point (s).
    pub period: f64,
    pub omega: f64,
    pub undamped: bool,
    pub classify: bool,
    /// The equation is 2π-periodic in θ (full and averaged), so whole turns may be taken out.
    pub periodic: bool,
    /// Longest DOP853 step (s). The full and linearised equations, whose drive is inside the
    /// equation, are held to 16 drive periods so that a step never jumps the drive unseen; the
    /// averaged equation has no drive term to miss and its strobes and period means come from
    /// the dense output, so its step is limited by its error estimate alone.
    pub h_max: f64,
    /// β of the adaptive methods' step controller (0: standard).
    pub beta: f64,
}

impl Context {
    /// The run's sampler, started at t = 0 from the initial state.
    pub(in crate::sim) fn sampler<'r, Rec: Recorder>(
        &self,
        sink: Sink<'r, Rec>,
    ) -> Sampler<'r, Rec> {
        let mut sampler = Sampler::new(
            self.schedule,
            self.strobes_total,
            self.out_dt,
            self.sensor.clone(),
            self.t_end,
            sink,
        );
        sampler.start(self.y0.0, self.y0.1);
        sampler
    }
}

/// A scene checked once and derived once, ready to step.
pub struct PlannedRun {
    pub scene: Scene,
    pub physical: Physical,
    /// Which equation runs, and why.
    pub decision: Decision,
    pub format: Format,
    /// a1 = A/ℓ, the drive's first harmonic over the equivalent length.
    pub a1: f64,
    /// a2/ℓ of a slider-crank's second harmonic ([`second_harmonic`]); 0 without one.
    pub a2: f64,
    /// R of the averaged model: R (1 + A²/(4b²)) with a slider-crank of rod length b.
    pub r_effective: f64,
    /// Whether the drive signal is shaped (ramp, actuator lag, slider-crank) or the steady sinusoid.
    pub shaped: bool,
    /// The averaged model's fast part, to read the full state back from the slow one.
    pub wobble: Option<Wobble>,
    pub(in crate::sim) ctx: Context,
}

impl PlannedRun {
    /// Checks the scene and the options against it, and derives everything a run needs.
    pub fn new(scene: &Scene, options: &Options) -> Result<PlannedRun, SimError> {
        scene.check()?;
        let p = scene.physical()?;
        let decision = fidelity::decide(scene, &p)?;
        let t_end = scene.duration(p.omega);
        check_method(scene, &p, decision.fidelity, options, t_end)?;
        let sched = schedule(scene, &p);
        // `periods = 4000` must give 4000 strobes, not 3999 through rounding of ω·t_end/2π.
        let strobes_total = libm::floor(sched.state(t_end).phase / math::TAU + 1e-9) as u64;
        let a2 = second_harmonic(scene, &p);
        let wobble = (decision.fidelity == Fidelity::Averaged).then(|| Wobble {
            a1: p.amplitude / p.ell,
            a2,
            omega: p.omega,
            c: p.c,
            angle: scene.drive.angle,
        });
        let given = (scene.initial_angle, scene.initial_rate);
        // The averaged model starts from the slow state under the given full one. A ramped or
        // lagging drive starts at rest, with no wobble to take out.
        let y0 = match wobble {
            Some(w) if scene.effects.ramp.is_none() && scene.effects.actuator.is_none() => {
                w.slow(given, 0.0)
            }
            _ => given,
        };
        let ctx = Context {
            method: options.method,
            y0,
            t_end,
            schedule: sched,
            strobes_total,
            out_dt: options.out_dt,
            sensor: scene.effects.sensor.map(|s| Encoder::new(s, options.seed)),
            period: math::TAU / p.omega,
            omega: p.omega,
            undamped: p.c == 0.0 && scene.effects.coulomb.is_none(),
            classify: options.classify,
            periodic: decision.fidelity != Fidelity::Linearised,
            h_max: if decision.fidelity == Fidelity::Averaged {
                f64::INFINITY
            } else {
                16.0 * math::TAU / p.omega
            },
            beta: options.controller.beta(),
        };
        Ok(PlannedRun {
            scene: *scene,
            physical: p,
            decision,
            format: options.format,
            a1: p.amplitude / p.ell,
            a2,
            r_effective: averaged_r(scene, &p),
            shaped: shaped(scene),
            wobble,
            ctx,
        })
    }

    /// The run's duration (s).
    pub fn duration(&self) -> f64 {
        self.ctx.t_end
    }

    /// Samples the time series every `dt` seconds (0: none). For a caller that sizes its output
    /// from the plan's duration and fidelity, which are only known once the scene is planned.
    pub fn sample_every(&mut self, dt: f64) -> Result<(), SimError> {
        output_interval(dt, self.ctx.t_end)?;
        self.ctx.out_dt = dt;
        Ok(())
    }

    /// Steps the planned run, sampling into `rec`, and classifies the outcome.
    pub fn run<Rec: Recorder>(&self, rec: &mut Rec) -> Result<Report, SimError> {
        match self.format {
            Format::F64 => self.run_in::<f64, Rec>(rec),
            Format::F32 => self.run_in::<f32, Rec>(rec),
        }
    }

    fn run_in<R: Real, Rec: Recorder>(&self, rec: &mut Rec) -> Result<Report, SimError> {
        let mut report = if self.shaped {
            let sig = Shaped::<R>::new(self.a1, self.a2, self.ctx.schedule);
            finish(self, sig, rec)
        } else {
            finish(self, Steady::<R>::new(self.a1, self.physical.omega), rec)
        }?;
        // The end state is reported as the full one: the slow state with its wobble put back, at
        // the drive's phase and frequency there.
        if let Some(w) = self.wobble {
            let EndState {
                t,
                theta: phi,
                rate: phi_rate,
            } = report.end;
            let drive = self.ctx.schedule.state(t);
            if drive.omega <= 0.0 {
                return Ok(report);
            }
            let w = Wobble {
                omega: drive.omega,
                ..w
            };
            let (theta, rate) = w.full((phi, phi_rate), drive.phase);
            report.end = EndState { t, theta, rate };
        }
        Ok(report)
    }
}

/// The drive signal a scene needs: the steady sinusoid unless something shapes it.
fn shaped(scene: &Scene) -> bool {
    let e = &scene.effects;
    e.ramp.is_some() || e.actuator.is_some() || e.slider_crank.is_some()
}

fn schedule(scene: &Scene, p: &Physical) -> Schedule {
    Schedule {
        omega: p.omega,
        ramp: scene.effects.ramp,
        lag: scene.effects.actuator,
    }
}

/// a2/ℓ of the slider-crank's second harmonic, A²/(4b)/ℓ.
fn second_harmonic(scene: &Scene, p: &Physical) -> f64 {
    scene
        .effects
        .slider_crank
        .map_or(0.0, |b| p.amplitude * p.amplitude / (4.0 * b) / p.ell)
}

/// R of the averaged model: R (1 + 4 (a2/a1)²) = R (1 + A²/(4b²)) with a slider-crank of rod
/// length b (see [`crate::sim::eom`]); R itself otherwise.
fn averaged_r(scene: &Scene, p: &Physical) -> f64 {
    let ratio = second_harmonic(scene, p) / (p.amplitude / p.ell);
    p.r * (1.0 + 4.0 * ratio * ratio)
}
