//! Which equation a scene runs, and why (physics §5).
//!
//! ```text
//! averaged    valid when ω/ω0 ≥ 10 and A/ℓ ≤ 0.1, no Coulomb friction (its average needs its own
//!             derivation), and no ramp or motor lag (the drive starts from rest, where ω/ω0 is small)
//! linearised  exists only about an exact fixed point of the full equation: θd = 0° or 180° and
//!             θ* = 0 or π; valid for a start within 0.05 rad of θ* and |θ'|/ω0 ≤ 0.05
//! full        always
//! ```
//! `auto` takes the cheapest valid one: averaged (no fast drive to resolve), then linearised, then
//! full. The thresholds are the conservative defaults of the literature's "ω ≫ ω0, A ≪ ℓ".

use super::scene::{Fidelity, FidelityChoice, Physical, Scene};
use crate::math;
use core::fmt;

/// ω/ω0 at and above which the averaged model is taken as valid.
pub const AVERAGED_MIN_RATIO: f64 = 10.0;
/// A/ℓ at and below which the averaged model is taken as valid.
pub const AVERAGED_MAX_A_OVER_L: f64 = 0.1;
/// Largest start distance from θ* (rad) and |θ'|/ω0 for the linearised model.
pub const LINEARISED_MAX_AMPLITUDE: f64 = 0.05;

/// Why a fidelity is or is not valid for a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Why {
    AveragedValid { ratio: f64, a_over_l: f64 },
    DriveTooSlow { ratio: f64 },
    AmplitudeTooLarge { a_over_l: f64 },
    Coulomb,
    StartsFromRest,
    LinearisedValid { inverted: bool, start: f64 },
    NotVertical { drive_deg: f64 },
    StartTooFar { start: f64 },
    FullAlwaysValid,
    Requested,
}

impl fmt::Display for Why {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Why::AveragedValid { ratio, a_over_l } => write!(
                f,
                "averaged: ω/ω0 = {ratio:.1} >= {AVERAGED_MIN_RATIO} and A/l = {a_over_l:.3} <= {AVERAGED_MAX_A_OVER_L}"
            ),
            Why::DriveTooSlow { ratio } => {
                write!(f, "averaged invalid: ω/ω0 = {ratio:.2} < {AVERAGED_MIN_RATIO}")
            }
            Why::AmplitudeTooLarge { a_over_l } => {
                write!(f, "averaged invalid: A/l = {a_over_l:.3} > {AVERAGED_MAX_A_OVER_L}")
            }
            Why::Coulomb => f.write_str("averaged and linearised models do not describe Coulomb friction (physics §5)"),
            Why::StartsFromRest => {
                f.write_str("averaged invalid: ramp/actuator start the drive from rest, where ω/ω0 is small")
            }
            Why::LinearisedValid { inverted, start } => write!(
                f,
                "linearised about θ* = {}: vertical drive, start {start:.3} rad <= {LINEARISED_MAX_AMPLITUDE} from it",
                if inverted { "180°" } else { "0°" }
            ),
            Why::NotVertical { drive_deg } => write!(
                f,
                "linearised invalid: at θd = {drive_deg}° the motion near equilibrium is a periodic orbit, not a fixed point (needs θd = 0° or 180°)"
            ),
            Why::StartTooFar { start } => write!(
                f,
                "linearised invalid: start {start:.3} rad (angle or |rate|/ω0) from θ* > {LINEARISED_MAX_AMPLITUDE}"
            ),
            Why::FullAlwaysValid => f.write_str("full: always valid"),
            Why::Requested => f.write_str("requested by the scene"),
        }
    }
}

/// The chosen fidelity, the reason, and (for `auto`) why the cheaper ones were passed over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    pub fidelity: Fidelity,
    pub why: Why,
    /// For `auto` choosing linearised or full: why averaged was passed over.
    pub not_averaged: Option<Why>,
    /// For `auto` choosing full: why linearised was passed over.
    pub not_linearised: Option<Why>,
}

impl fmt::Display for Decision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.why)?;
        for w in [self.not_averaged, self.not_linearised]
            .into_iter()
            .flatten()
        {
            write!(f, "; {w}")?;
        }
        Ok(())
    }
}

/// A fidelity the scene asked for that cannot describe it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FidelityError(pub Why);

impl fmt::Display for FidelityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "run.fidelity: {}", self.0)
    }
}

fn averaged(scene: &Scene, p: &Physical) -> Result<Why, Why> {
    let e = &scene.effects;
    if e.coulomb.is_some() {
        return Err(Why::Coulomb);
    }
    if e.ramp.is_some() || e.actuator.is_some() {
        return Err(Why::StartsFromRest);
    }
    let ratio = p.omega / p.omega0;
    if ratio < AVERAGED_MIN_RATIO {
        return Err(Why::DriveTooSlow { ratio });
    }
    let a_over_l = p.amplitude / p.ell;
    if a_over_l > AVERAGED_MAX_A_OVER_L {
        return Err(Why::AmplitudeTooLarge { a_over_l });
    }
    Ok(Why::AveragedValid { ratio, a_over_l })
}

/// Whether θ* = π (else 0) is the centre the linearised model uses: the nearer one to the start.
pub fn linearised_centre(scene: &Scene) -> bool {
    math::cos(scene.initial_angle) < 0.0
}

fn linearised_exists(scene: &Scene) -> Result<(), Why> {
    if scene.effects.coulomb.is_some() {
        return Err(Why::Coulomb);
    }
    if scene.drive.angle.sin() != 0.0 {
        return Err(Why::NotVertical {
            drive_deg: scene.drive.angle.deg(),
        });
    }
    Ok(())
}

fn linearised(scene: &Scene, p: &Physical) -> Result<Why, Why> {
    linearised_exists(scene)?;
    let inverted = linearised_centre(scene);
    let centre = if inverted { math::PI } else { 0.0 };
    let start = math::wrap_pi(scene.initial_angle - centre)
        .abs()
        .max(scene.initial_rate.abs() / p.omega0);
    if start > LINEARISED_MAX_AMPLITUDE {
        return Err(Why::StartTooFar { start });
    }
    Ok(Why::LinearisedValid { inverted, start })
}

/// Decides the fidelity. An explicit averaged or linearised choice is refused only where the
/// model does not exist for the scene (Coulomb friction, a drive off the vertical for
/// linearised); outside its validity range it runs as asked.
pub fn decide(scene: &Scene, p: &Physical) -> Result<Decision, FidelityError> {
    let plain = |fidelity, why| Decision {
        fidelity,
        why,
        not_averaged: None,
        not_linearised: None,
    };
    match scene.fidelity {
        FidelityChoice::Fixed(Fidelity::Full) => Ok(plain(Fidelity::Full, Why::Requested)),
        FidelityChoice::Fixed(Fidelity::Averaged) => {
            if scene.effects.coulomb.is_some() {
                return Err(FidelityError(Why::Coulomb));
            }
            Ok(plain(Fidelity::Averaged, Why::Requested))
        }
        FidelityChoice::Fixed(Fidelity::Linearised) => {
            linearised_exists(scene).map_err(FidelityError)?;
            Ok(plain(Fidelity::Linearised, Why::Requested))
        }
        FidelityChoice::Auto => {
            let not_averaged = match averaged(scene, p) {
                Ok(why) => return Ok(plain(Fidelity::Averaged, why)),
                Err(w) => w,
            };
            let not_linearised = match linearised(scene, p) {
                Ok(why) => {
                    return Ok(Decision {
                        fidelity: Fidelity::Linearised,
                        why,
                        not_averaged: Some(not_averaged),
                        not_linearised: None,
                    })
                }
                Err(w) => w,
            };
            Ok(Decision {
                fidelity: Fidelity::Full,
                why: Why::FullAlwaysValid,
                not_averaged: Some(not_averaged),
                not_linearised: Some(not_linearised),
            })
        }
    }
}
