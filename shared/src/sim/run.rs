//! Running a scene: choose the equation, compose it from the listed effects, integrate, sample,
//! classify.
//!
//! The equation is built once, as a concrete type, before the loop starts: the drive signal
//! ([`Steady`] or [`Shaped`]), the extra forces ([`NoExtra`] or [`Viscous`]) and the number format
//! are type parameters, so the inner loop of a scene carries no test or evaluation for an effect
//! it does not list. Coulomb friction switches between sliding segments and sticking, so it has
//! its own loop ([`super::friction`]).

use super::adaptive::{self, Fast, Slow};
use super::classify::{self, Outcome, Strobes, Undecided};
use super::eom::{AveragedEom, FullEom, LinearisedEom, NoExtra, Viscous};
use super::fidelity::{self, Decision, FidelityError};
use super::friction;
use super::lyapunov;
use super::periodic;
use super::sampling::{Hermite, Interpolant, Recorder, Sampler, Sink};
use super::scene::{Fidelity, Physical, Scene, SceneError};
use super::sensor::Encoder;
use super::signal::{DriveSignal, Schedule, Shaped, Steady};
use super::turns::{Shifted, Turns};
use super::wobble::Wobble;
use crate::integrate::rkn::{RKN1210, RKN86};
use crate::integrate::{
    rk4_observe, symplectic_fixed, Control, Dop853, Force, IntegrateError, Phase, Stats, Step,
    StepControl, Symplectic, System,
};
use crate::{math, Real};
use core::fmt;

/// How to integrate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Classical RK4 with a fixed step of T/steps_per_period (T: the set-point drive period).
    Rk4 { steps_per_period: f64 },
    /// Adaptive Dormand–Prince 8(5,3) with dense output.
    Dop853 { rtol: f64, atol: f64 },
    /// Runge–Kutta–Nyström 8(6), viscous damping or none. On the full equation (drive periodic
    /// from t = 0): a whole number of steps per drive period, chosen per period from its error
    /// estimate ([`super::periodic`]); on the averaged equation: an adaptive step
    /// ([`super::slow`]).
    Rkn86 { rtol: f64, atol: f64 },
    /// Runge–Kutta–Nyström 12(10) with an adaptive step ([`super::adaptive`]), on the full or
    /// the averaged equation, viscous damping or none: for runs whose time scale is not the
    /// drive's (chaotic transients, a ramping drive).
    Rkn1210 { rtol: f64, atol: f64 },
    /// A symplectic method (Störmer–Verlet or a Yoshida composition) with a fixed step of
    /// T/steps_per_period: undamped scenes only.
    Symplectic {
        scheme: Symplectic,
        steps_per_period: f64,
    },
}

impl Method {
    /// Whether the method adapts its step to an error estimate step by step (what a step
    /// controller acts on) on the given fidelity.
    pub fn has_step_controller(&self, fidelity: Fidelity) -> bool {
        match self {
            Method::Dop853 { .. } | Method::Rkn1210 { .. } => true,
            Method::Rkn86 { .. } => fidelity == Fidelity::Averaged,
            Method::Rk4 { .. } | Method::Symplectic { .. } => false,
        }
    }

    /// The default: DOP853 at rtol = atol = 1e-9.
    pub const DEFAULT: Method = Method::Dop853 {
        rtol: 1e-9,
        atol: 1e-9,
    };
}

/// How an adaptive method picks its next step from its error estimates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Controller {
    /// From the last error alone (h ∝ err^(−1/(q+1))).
    #[default]
    Standard,
    /// Proportional–integral: the last two errors, β = [`Controller::PI_BETA`] (HNW I §IV.2).
    Pi,
}

impl Controller {
    /// The PI controller's β: the value HNW recommend for explicit Runge–Kutta pairs.
    pub const PI_BETA: f64 = 0.04;

    pub fn beta(self) -> f64 {
        match self {
            Controller::Standard => 0.0,
            Controller::Pi => Self::PI_BETA,
        }
    }
}

/// The number format of the state and its arithmetic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    F64,
    F32,
}

/// How to run a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    pub method: Method,
    /// The step controller of an adaptive method; [`Controller::Pi`] is refused for methods
    /// without one ([`Method::has_step_controller`]).
    pub controller: Controller,
    pub format: Format,
    /// Output sample interval (s); 0 for none.
    pub out_dt: f64,
    /// Seed of the sensor's noise.
    pub seed: u64,
    /// Classify the outcome. Off, a run only integrates and samples (the outcome is
    /// `Undecided`), which is what benchmarks and error measurements want: classifying can cost
    /// a second run for the Lyapunov exponent.
    pub classify: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            method: Method::DEFAULT,
            controller: Controller::Standard,
            format: Format::F64,
            out_dt: 0.0,
            seed: 1,
            classify: true,
        }
    }
}

/// What a run found and what it cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Report {
    pub outcome: Outcome,
    pub decision: Decision,
    pub physical: Physical,
    pub duration: f64,
    /// Stroboscopic samples taken (drive periods completed).
    pub strobes: u64,
    /// Work of the run itself (including dense-output and interpolation evaluations).
    pub work: Stats,
    /// Work of the Lyapunov run, when the classifier needed one.
    pub lyapunov_work: Stats,
    /// Final time, angle (rad, unwrapped) and rate (rad/s). From the averaged model: the full
    /// state read back from the slow one ([`super::wobble`]).
    pub end: (f64, f64, f64),
    /// With Coulomb friction: how many times the pendulum stuck.
    pub sticks: Option<u64>,
}

/// Why a run did not happen or did not finish.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SimError {
    Scene(SceneError),
    Fidelity(FidelityError),
    Integrate(IntegrateError),
    /// A method or option that cannot run this scene, with the reason.
    Unsupported(&'static str),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Scene(e) => e.fmt(f),
            SimError::Fidelity(e) => e.fmt(f),
            SimError::Integrate(e) => write!(f, "integration failed: {e}"),
            SimError::Unsupported(why) => f.write_str(why),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SimError {}

impl From<SceneError> for SimError {
    fn from(e: SceneError) -> Self {
        SimError::Scene(e)
    }
}
impl From<FidelityError> for SimError {
    fn from(e: FidelityError) -> Self {
        SimError::Fidelity(e)
    }
}
impl From<IntegrateError> for SimError {
    fn from(e: IntegrateError) -> Self {
        SimError::Integrate(e)
    }
}

const NOT_LINEARISED: &str = "methods rkn86 and rkn1210 integrate the full or the averaged equation: set run.fidelity = \"full\" or \"averaged\", or use dop853";

/// Everything a generic run needs besides the equation.
pub(super) struct Context {
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
    pub(super) fn sampler<'r, Rec: Recorder>(&self, sink: Sink<'r, Rec>) -> Sampler<'r, Rec> {
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

/// The raw result of a generic run, before classification.
pub(super) struct RunOut<'a, Rec: Recorder> {
    pub sampler: Sampler<'a, Rec>,
    pub work: Stats,
    pub end: (f64, f64, f64),
    pub sticks: Option<u64>,
}

/// Runs a scene and classifies the outcome.
pub fn simulate<Rec: Recorder>(
    scene: &Scene,
    options: &Options,
    rec: &mut Rec,
) -> Result<Report, SimError> {
    scene.check()?;
    let p = scene.physical()?;
    let decision = fidelity::decide(scene, &p)?;
    check_method(scene, &p, decision.fidelity, options)?;
    match options.format {
        Format::F64 => run_format::<f64, Rec>(scene, &p, decision, options, rec),
        Format::F32 => run_format::<f32, Rec>(scene, &p, decision, options, rec),
    }
}

fn check_method(
    scene: &Scene,
    p: &Physical,
    fidelity: Fidelity,
    options: &Options,
) -> Result<(), SimError> {
    if options.controller != Controller::Standard && !options.method.has_step_controller(fidelity) {
        return Err(SimError::Unsupported(
            "run.controller = \"pi\" needs a method with an adaptive step: dop853, rkn1210, or rkn86 on the averaged model (rk4 and the symplectic methods take fixed steps; rkn86 on the full model chooses whole steps per drive period)",
        ));
    }
    let steps_ok = |spp: f64| spp > 0.0 && spp <= MAX_STEPS_PER_PERIOD;
    match options.method {
        Method::Symplectic {
            steps_per_period, ..
        } => {
            if !steps_ok(steps_per_period) {
                return Err(SimError::Unsupported(STEPS_PER_PERIOD_RANGE));
            }
            if p.c > 0.0 || scene.effects.coulomb.is_some() {
                return Err(SimError::Unsupported(
                    "symplectic methods integrate undamped motion only: drop effects.viscous and effects.coulomb, or use dop853 or rk4",
                ));
            }
        }
        Method::Rk4 { steps_per_period } => {
            if !steps_ok(steps_per_period) {
                return Err(SimError::Unsupported(STEPS_PER_PERIOD_RANGE));
            }
            if scene.effects.coulomb.is_some() {
                return Err(SimError::Unsupported(
                    "Coulomb friction needs event location: use method = \"dop853\"",
                ));
            }
        }
        Method::Rkn86 { rtol, atol } => {
            tolerances(rtol, atol)?;
            let e = &scene.effects;
            if fidelity == Fidelity::Full && (e.ramp.is_some() || e.actuator.is_some()) {
                return Err(SimError::Unsupported(
                    "method rkn86 on the full model needs a drive periodic from t = 0: it cannot run effects.ramp or effects.actuator (use dop853)",
                ));
            }
            if e.coulomb.is_some() {
                return Err(SimError::Unsupported(
                    "method rkn86 cannot run effects.coulomb: stick–slip needs event location (use dop853)",
                ));
            }
        }
        Method::Rkn1210 { rtol, atol } => {
            tolerances(rtol, atol)?;
            if scene.effects.coulomb.is_some() {
                return Err(SimError::Unsupported(
                    "method rkn1210 cannot run effects.coulomb: stick–slip needs event location (use dop853)",
                ));
            }
        }
        Method::Dop853 { rtol, atol } => tolerances(rtol, atol)?,
    }
    let out_dt = options.out_dt;
    let t_end = scene.duration(p.omega);
    if !(out_dt == 0.0 || (out_dt > 0.0 && t_end / out_dt <= MAX_OUTPUT_SAMPLES)) {
        return Err(SimError::Unsupported(
            "the output interval must be 0 (none) or a finite number > 0 giving at most 1e9 samples",
        ));
    }
    Ok(())
}

/// Tolerances of an adaptive method: finite, ≥ 0, not both 0.
fn tolerances(rtol: f64, atol: f64) -> Result<(), SimError> {
    if rtol.is_finite() && atol.is_finite() && rtol >= 0.0 && atol >= 0.0 && rtol + atol > 0.0 {
        Ok(())
    } else {
        Err(SimError::Unsupported(
            "run.rtol and run.atol must be finite, >= 0, not both 0",
        ))
    }
}

/// More steps per drive period than any accuracy needs (RK4's error is at rounding by 10⁴);
/// beyond it a run is a mistake that would take forever.
const MAX_STEPS_PER_PERIOD: f64 = 1e6;
const STEPS_PER_PERIOD_RANGE: &str = "run.steps_per_period must be a number > 0 and <= 1e6";
/// Output samples a run may write.
const MAX_OUTPUT_SAMPLES: f64 = 1e9;

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

fn run_format<R: Real, Rec: Recorder>(
    scene: &Scene,
    p: &Physical,
    decision: Decision,
    options: &Options,
    rec: &mut Rec,
) -> Result<Report, SimError> {
    let sched = schedule(scene, p);
    let t_end = scene.duration(p.omega);
    // `periods = 4000` must give 4000 strobes, not 3999 through rounding of ω·t_end/2π.
    let strobes_total = libm::floor(sched.state(t_end).phase / math::TAU + 1e-9) as u64;
    let wobble = (decision.fidelity == Fidelity::Averaged).then(|| Wobble {
        a1: p.amplitude / p.ell,
        a2: second_harmonic(scene, p),
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
    let a1 = p.amplitude / p.ell;
    let mut report = if shaped(scene) {
        let sig = Shaped::<R>::new(a1, second_harmonic(scene, p), sched);
        finish(scene, p, decision, sig, &ctx, rec)
    } else {
        finish(scene, p, decision, Steady::<R>::new(a1, p.omega), &ctx, rec)
    }?;
    // The end state is reported as the full one: the slow state with its wobble put back, at
    // the drive's phase and frequency there.
    if let Some(w) = wobble {
        let (t, phi, phi_rate) = report.end;
        let drive = sched.state(t);
        if drive.omega <= 0.0 {
            return Ok(report);
        }
        let w = Wobble {
            omega: drive.omega,
            ..w
        };
        let (theta, rate) = w.full((phi, phi_rate), drive.phase);
        report.end = (t, theta, rate);
    }
    Ok(report)
}

/// Runs the composed equation, then classifies (running the Lyapunov pair only if asked).
fn finish<R: Real, D: DriveSignal<R>, Rec: Recorder>(
    scene: &Scene,
    p: &Physical,
    decision: Decision,
    sig: D,
    ctx: &Context,
    rec: &mut Rec,
) -> Result<Report, SimError> {
    let mut window = None;
    let rec = Sink {
        rec,
        window: ctx.classify.then(|| window.insert(Strobes::default())),
    };
    let full =
        || FullEom::<R, D, NoExtra>::new(p.omega0 * p.omega0, scene.drive.angle, sig, NoExtra);
    let averaged = || {
        let r_eff = averaged_r(scene, p);
        AveragedEom::<R, D, _>::new(p.omega0 * p.omega0, r_eff, scene.drive.angle, sig, NoExtra)
    };
    let out = match (scene.effects.coulomb, ctx.method) {
        (Some(mu), _) => friction::run(full(), R::from_f64(p.c), mu, ctx, rec)?,
        (None, Method::Rkn86 { rtol, atol }) => match decision.fidelity {
            Fidelity::Full => periodic::run(full(), p.c, (rtol, atol), ctx, rec)?,
            Fidelity::Averaged => {
                let eom = averaged();
                adaptive::run(Slow(&eom), &RKN86, p.c, (rtol, atol), ctx, rec)?
            }
            Fidelity::Linearised => return Err(SimError::Unsupported(NOT_LINEARISED)),
        },
        (None, Method::Rkn1210 { rtol, atol }) => match decision.fidelity {
            Fidelity::Full => {
                let eom = full();
                adaptive::run(Fast(&eom), &RKN1210, p.c, (rtol, atol), ctx, rec)?
            }
            Fidelity::Averaged => {
                let eom = averaged();
                adaptive::run(Slow(&eom), &RKN1210, p.c, (rtol, atol), ctx, rec)?
            }
            Fidelity::Linearised => return Err(SimError::Unsupported(NOT_LINEARISED)),
        },
        (None, _) => with_equation(scene, p, decision, sig, Integrate { ctx, rec })?,
    };
    let RunOut {
        sampler,
        work,
        end,
        sticks,
    } = out;
    let mut lyapunov_work = Stats::default();
    if !ctx.classify {
        let outcome = Outcome::Undecided {
            reason: Undecided::NotClassified,
        };
        return Ok(Report {
            outcome,
            decision,
            physical: *p,
            duration: ctx.t_end,
            strobes: ctx.strobes_total,
            work,
            lyapunov_work,
            end,
            sticks,
        });
    }
    let Some(strobes) = sampler.strobes.as_deref() else {
        return Err(SimError::Unsupported(
            "a classifying run keeps its window of strobes",
        ));
    };
    let outcome = classify::classify(strobes, p.omega, ctx.undamped, || {
        match (sampler.window_start, scene.effects.coulomb) {
            (Some(start), None) => {
                let (lambda, w) =
                    with_equation(scene, p, decision, sig, lyapunov::Exponent { ctx, start });
                lyapunov_work = w;
                lambda
            }
            // The pair-of-trajectories estimate is not defined across stick–slip switches.
            _ => 0.0,
        }
    });
    Ok(Report {
        outcome,
        decision,
        physical: *p,
        duration: ctx.t_end,
        strobes: ctx.strobes_total,
        work,
        lyapunov_work,
        end,
        sticks,
    })
}

/// Something to do with a composed smooth equation.
pub(super) trait Job<R: Real> {
    type Out;
    fn run<S: System<2, R> + Copy>(self, sys: S) -> Self::Out;
}

/// Builds the equation for the decided fidelity with exactly the listed forces, and hands it to
/// `job`. Each arm is its own concrete type.
pub(super) fn with_equation<R: Real, D: DriveSignal<R>, J: Job<R>>(
    scene: &Scene,
    p: &Physical,
    decision: Decision,
    sig: D,
    job: J,
) -> J::Out {
    let w0sq = p.omega0 * p.omega0;
    let angle = scene.drive.angle;
    let viscous = (p.c > 0.0).then_some(Viscous {
        c: R::from_f64(p.c),
    });
    macro_rules! with_extras {
        ($build:expr) => {
            match viscous {
                None => job.run(($build)(NoExtra)),
                Some(v) => job.run(($build)(v)),
            }
        };
    }
    match decision.fidelity {
        Fidelity::Full => with_extras!(|x| FullEom::<R, D, _>::new(w0sq, angle, sig, x)),
        Fidelity::Averaged => {
            let r_eff = averaged_r(scene, p);
            with_extras!(|x| AveragedEom::<R, D, _>::new(w0sq, r_eff, angle, sig, x))
        }
        Fidelity::Linearised => {
            let inverted = fidelity::linearised_centre(scene);
            let up = angle.cos() < 0.0;
            with_extras!(|x| LinearisedEom::<R, D, _>::new(w0sq, inverted, up, sig, x))
        }
    }
}

/// The main run as a [`Job`].
struct Integrate<'c, 'r, Rec: Recorder> {
    ctx: &'c Context,
    rec: Sink<'r, Rec>,
}

impl<'c, 'r, R: Real, Rec: Recorder> Job<R> for Integrate<'c, 'r, Rec> {
    type Out = Result<RunOut<'r, Rec>, SimError>;
    fn run<S: System<2, R> + Copy>(self, sys: S) -> Self::Out {
        integrate(sys, self.ctx, self.rec)
    }
}

/// R of the averaged model: R (1 + 4 (a2/a1)²) = R (1 + A²/(4b²)) with a slider-crank of rod
/// length b (see [`super::eom`]); R itself otherwise.
pub fn averaged_r(scene: &Scene, p: &Physical) -> f64 {
    let ratio = second_harmonic(scene, p) / (p.amplitude / p.ell);
    p.r * (1.0 + 4.0 * ratio * ratio)
}

/// Dense output of an accepted DOP853 step as an [`Interpolant`].
pub(super) struct Dense<'s, 'a, R: Real>(pub &'s Step<'a, 2, R>);

impl<R: Real> Interpolant for Dense<'_, '_, R> {
    fn at(&mut self, t: f64) -> (f64, f64) {
        let y = self.0.eval(t);
        (y[0].to_f64(), y[1].to_f64())
    }
}

fn pair<R: Real>(y: &[R; 2]) -> (f64, f64) {
    (y[0].to_f64(), y[1].to_f64())
}

/// Integrates a smooth equation with the chosen method, feeding the sampler.
///
/// The integrators see the angle reduced by whole turns ([`Turns`]): a run stops when the angle
/// is due for reduction and restarts from the reduced state, at the same step size and, for the
/// fixed-step methods, at the same step times t_i = i·h.
pub(super) fn integrate<'r, R: Real, S: System<2, R>, Rec: Recorder>(
    sys: S,
    ctx: &Context,
    rec: Sink<'r, Rec>,
) -> Result<RunOut<'r, Rec>, SimError> {
    let mut sampler = ctx.sampler(rec);
    let mut turns = Turns::new(ctx.periodic);
    let mut y = [turns.reduce(R::from_f64(ctx.y0.0)), R::from_f64(ctx.y0.1)];
    let mut t = 0.0;
    let mut work = Stats::default();
    match ctx.method {
        Method::Dop853 { rtol, atol } => {
            let mut solver = Dop853::new(rtol, atol);
            solver.h_max = ctx.h_max;
            solver.beta = ctx.beta;
            solver.max_steps = u64::MAX;
            loop {
                let offset = turns.offset();
                let mut last_h = None;
                let sol = solver.solve(&sys, t, y, ctx.t_end, |step| {
                    let (theta, rate) = pair(&step.y1);
                    sampler.step(
                        step.t1,
                        (theta + offset, rate),
                        &mut Shifted(Dense(step), offset),
                    );
                    last_h = Some(step.t1 - step.t0);
                    if turns.due(step.y1[0]) {
                        StepControl::Stop
                    } else {
                        StepControl::Continue
                    }
                })?;
                work.add(sol.stats);
                (t, y) = (sol.t, sol.y);
                if t >= ctx.t_end {
                    break;
                }
                y[0] = turns.reduce(y[0]);
                solver.h_init = last_h;
            }
        }
        Method::Symplectic {
            scheme,
            steps_per_period,
        } => {
            let driver = SymplecticDriver {
                scheme,
                force: AtRest(&sys),
            };
            let n_h = fixed_steps(ctx, steps_per_period);
            (t, y) = in_stretches(&driver, &sys, n_h, y, &mut turns, &mut sampler, &mut work);
        }
        Method::Rkn86 { .. } | Method::Rkn1210 { .. } => {
            return Err(SimError::Unsupported(
                "the RKN methods run through their own loops",
            ))
        }
        Method::Rk4 { steps_per_period } => {
            let n_h = fixed_steps(ctx, steps_per_period);
            (t, y) = in_stretches(
                &Rk4Driver(&sys),
                &sys,
                n_h,
                y,
                &mut turns,
                &mut sampler,
                &mut work,
            );
        }
    }
    for v in y {
        if !v.is_finite() {
            return Err(SimError::Integrate(IntegrateError::NonFinite { t }));
        }
    }
    let end = (t, y[0].to_f64() + turns.offset(), y[1].to_f64());
    Ok(RunOut {
        sampler,
        work,
        end,
        sticks: None,
    })
}

/// The step count and size of a fixed-step run: whole steps, the last landing on t_end.
fn fixed_steps(ctx: &Context, steps_per_period: f64) -> (u64, f64) {
    let n = libm::round(ctx.t_end / ctx.period * steps_per_period).max(1.0) as u64;
    (n, ctx.t_end / n as f64)
}

/// A fixed-step method run from (t, y) for up to n steps, observed after each.
trait FixedDriver<R: Real> {
    fn run<O: FnMut(f64, [R; 2]) -> Control>(
        &self,
        t: f64,
        y: [R; 2],
        h: f64,
        n: u64,
        observer: O,
    ) -> (Stats, [R; 2]);
}

struct Rk4Driver<'s, S>(&'s S);

impl<R: Real, S: System<2, R>> FixedDriver<R> for Rk4Driver<'_, S> {
    #[inline(always)]
    fn run<O: FnMut(f64, [R; 2]) -> Control>(
        &self,
        t: f64,
        y: [R; 2],
        h: f64,
        n: u64,
        mut observer: O,
    ) -> (Stats, [R; 2]) {
        let sol = rk4_observe(self.0, t, y, h, n, |t, y| observer(t, *y));
        (sol.stats, sol.y)
    }
}

struct SymplecticDriver<F> {
    scheme: Symplectic,
    force: F,
}

impl<R: Real, F: Force<1, R>> FixedDriver<R> for SymplecticDriver<F> {
    #[inline(always)]
    fn run<O: FnMut(f64, [R; 2]) -> Control>(
        &self,
        t: f64,
        y: [R; 2],
        h: f64,
        n: u64,
        mut observer: O,
    ) -> (Stats, [R; 2]) {
        let x0 = Phase {
            q: [y[0]],
            v: [y[1]],
        };
        let sol = symplectic_fixed(self.scheme, &self.force, t, x0, h, n, |t, x| {
            observer(t, [x.q[0], x.v[0]])
        });
        (sol.stats, [sol.y.q[0], sol.y.v[0]])
    }
}

/// Runs n fixed steps of size h from t = 0 in stretches, each ending when the angle is due for
/// reduction; the next starts from the reduced state at t = done·h (step times stay t0 + i·h,
/// computed afresh). Returns where the run ended.
fn in_stretches<R: Real, S: System<2, R>, D: FixedDriver<R>, Rec: Recorder>(
    driver: &D,
    sys: &S,
    (n, h): (u64, f64),
    mut y: [R; 2],
    turns: &mut Turns,
    sampler: &mut Sampler<'_, Rec>,
    work: &mut Stats,
) -> (f64, [R; 2]) {
    let (mut t, mut done) = (0.0, 0u64);
    while done < n {
        let offset = turns.offset();
        let mut prev = (t, y);
        let mut extra = 0u64;
        let (stats, y_end) = driver.run(t, y, h, n - done, |t, y| {
            observe(sampler, sys, prev, (t, y), offset, &mut extra);
            prev = (t, y);
            if turns.due(y[0]) {
                Control::Stop
            } else {
                Control::Continue
            }
        });
        work.add(stats);
        work.rhs_evals += extra;
        done += stats.steps;
        (t, y) = (done as f64 * h, [turns.reduce(y_end[0]), y_end[1]]);
    }
    (t, y)
}

/// Hands a fixed step from `prev` to `next` to the sampler, with its turns added back.
fn observe<R: Real, S: System<2, R>, Rec: Recorder>(
    sampler: &mut Sampler<'_, Rec>,
    sys: &S,
    prev: (f64, [R; 2]),
    next: (f64, [R; 2]),
    offset: f64,
    extra: &mut u64,
) {
    let (theta, rate) = pair(&next.1);
    let interp = LazyHermite {
        sys,
        t0: prev.0,
        t1: next.0,
        y0: prev.1,
        y1: next.1,
        ready: None,
        evals: extra,
    };
    sampler.step(next.0, (theta + offset, rate), &mut Shifted(interp, offset));
}

/// An undamped equation seen as a force: θ'' = a(t, θ), evaluated at θ' = 0 (the extras of an
/// undamped scene ignore θ', which [`check_method`] ensures before a symplectic method runs).
struct AtRest<'s, S>(&'s S);

impl<R: Real, S: System<2, R>> Force<1, R> for AtRest<'_, S> {
    #[inline(always)]
    fn accel(&self, t: f64, q: &[R; 1], a: &mut [R; 1]) {
        let mut dy = [R::ZERO; 2];
        self.0.rhs(t, &[q[0], R::ZERO], &mut dy);
        a[0] = dy[1];
    }
}

/// Hermite interpolation whose end derivatives are evaluated only if a sample falls inside the
/// step (two right-hand-side evaluations, counted as work).
struct LazyHermite<'s, R: Real, S: System<2, R>> {
    sys: &'s S,
    t0: f64,
    t1: f64,
    y0: [R; 2],
    y1: [R; 2],
    ready: Option<Hermite<R>>,
    evals: &'s mut u64,
}

impl<R: Real, S: System<2, R>> Interpolant for LazyHermite<'_, R, S> {
    fn at(&mut self, t: f64) -> (f64, f64) {
        if self.ready.is_none() {
            let (mut f0, mut f1) = ([R::ZERO; 2], [R::ZERO; 2]);
            self.sys.rhs(self.t0, &self.y0, &mut f0);
            self.sys.rhs(self.t1, &self.y1, &mut f1);
            *self.evals += 2;
            self.ready = Some(Hermite {
                t0: self.t0,
                t1: self.t1,
                y0: self.y0,
                y1: self.y1,
                f0,
                f1,
            });
        }
        self.ready
            .as_mut()
            .map_or((f64::NAN, f64::NAN), |h| h.at(t))
    }
}
