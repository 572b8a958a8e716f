//! Whether the options can run a scene: the method against the scene's effects and fidelity,
//! tolerances, step counts and the output interval. Checked once, when the run is planned.

use super::{Controller, Method, Options, SimError};
use crate::sim::scene::{Fidelity, Physical, Scene};

/// Refuses options that cannot run the scene, with the reason; `t_end` is the run's duration.
pub(super) fn check_method(
    scene: &Scene,
    p: &Physical,
    fidelity: Fidelity,
    options: &Options,
    t_end: f64,
) -> Result<(), SimError> {
    if options.controller != Controller::Standard && !options.method.has_step_controller(fidelity) {
        return Err(SimError::Unsupported(
            "run.controller = \"pi\" needs a method with an adaptive step: dop853, rkn1210, or rkn86 on the averaged model (rk4 and the symplectic methods take fixed steps; rkn86 on the full model chooses whole steps per drive period)",
        ));
    }
    let steps_ok = |spp: f64| spp > 0.0 && spp <= MAX_STEPS_PER_PERIOD;
    // A fixed step longer than a drive period steps over the drive the full model integrates:
    // its "outcome" describes no pendulum. The averaged model has no motion within a period.
    let spans_periods = |spp: f64| fidelity != Fidelity::Averaged && spp < 1.0;
    match options.method {
        Method::Symplectic {
            steps_per_period, ..
        } => {
            if !steps_ok(steps_per_period) {
                return Err(SimError::Unsupported(STEPS_PER_PERIOD_RANGE));
            }
            if spans_periods(steps_per_period) {
                return Err(SimError::Unsupported(STEPS_SPAN_PERIODS));
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
            if spans_periods(steps_per_period) {
                return Err(SimError::Unsupported(STEPS_SPAN_PERIODS));
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
    output_interval(options.out_dt, t_end)
}

/// The time series' sampling interval: 0 (none) or at most [`MAX_OUTPUT_SAMPLES`] samples.
pub(super) fn output_interval(out_dt: f64, t_end: f64) -> Result<(), SimError> {
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
const STEPS_SPAN_PERIODS: &str = "run.steps_per_period must be at least 1 on the full (or linearised) model: a fixed step spanning drive periods cannot follow the drive (fractions are allowed with fidelity = \"averaged\")";
/// Output samples a run may write.
const MAX_OUTPUT_SAMPLES: f64 = 1e9;
