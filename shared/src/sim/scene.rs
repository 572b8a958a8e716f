//! A scene: one experiment, in SI units and radians, checked once before anything runs.
//!
//! The host reads scene files (TOML) into this type; the core never parses text. Every check
//! names the scene key it concerns, so a loading error can point at the line to fix.

use crate::model::{DriveAngle, Geometry};
use core::fmt;
use serde::Serialize;

/// How the drive frequency is given: ω itself, or R (then ω = ωc √R with the effective gravity).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DriveFrequency {
    Omega(f64),
    R(f64),
}

/// The drive as the scene states it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveSpec {
    /// A: half the peak-to-peak stroke (m). With `slider_crank` it is the crank radius.
    pub amplitude: f64,
    pub frequency: DriveFrequency,
    pub angle: DriveAngle,
}

/// Viscous damping, as a quality factor Q = ω0/c or as γ = c/2 (physics §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Viscous {
    Q(f64),
    Gamma(f64),
}

/// The sensor: what the pivot encoder reports, not what the pendulum does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensor {
    /// Resolution: 2^bits counts per turn.
    pub bits: u32,
    /// Standard deviation of additive noise (rad).
    pub noise: f64,
    /// Samples per second.
    pub rate_hz: f64,
}

/// The effects a scene asks for. An absent effect is `None` and costs nothing.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Effects {
    pub viscous: Option<Viscous>,
    /// Coulomb friction torque per unit inertia (rad/s²).
    pub coulomb: Option<f64>,
    /// Tilt β of the plane of swing (rad): g → g cos β.
    pub tilt: Option<f64>,
    /// Slider-crank connecting-rod length b (m): adds the second harmonic (r²/4b) cos 2ϕ.
    pub slider_crank: Option<f64>,
    /// Drive ramp duration (s): ω rises linearly from 0 to its set point.
    pub ramp: Option<f64>,
    pub sensor: Option<Sensor>,
    /// Motor speed-loop time constant (s): delivered ω lags the commanded ω (first order).
    pub actuator: Option<f64>,
}

/// Which equation to integrate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Fidelity {
    Full,
    Averaged,
    Linearised,
}

impl Fidelity {
    /// As scene files spell it: `full`, `averaged`, `linearised`.
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Full => "full",
            Fidelity::Averaged => "averaged",
            Fidelity::Linearised => "linearised",
        }
    }
}

impl fmt::Display for Fidelity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The fidelity a scene asks for; `Auto` picks the cheapest valid one and says why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FidelityChoice {
    Fixed(Fidelity),
    Auto,
}

/// How long to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RunLength {
    /// Drive periods (of the set-point frequency).
    Periods(f64),
    /// Seconds.
    Duration(f64),
}

/// One experiment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scene {
    pub pendulum: Geometry,
    pub drive: DriveSpec,
    /// g before any tilt (m/s²).
    pub gravity: f64,
    /// Initial angle (rad) and rate (rad/s), at t = 0, which is drive phase zero (pivot at +A).
    pub initial_angle: f64,
    pub initial_rate: f64,
    pub length: RunLength,
    pub fidelity: FidelityChoice,
    pub effects: Effects,
}

/// A scene value out of range: the key, the value and what is allowed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneError {
    pub key: &'static str,
    pub value: f64,
    pub allowed: &'static str,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {} is out of range: allowed {}",
            self.key,
            crate::error::Compact(self.value),
            self.allowed
        )
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SceneError {}

fn check(key: &'static str, value: f64, ok: bool, allowed: &'static str) -> Result<(), SceneError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(SceneError {
            key,
            value,
            allowed,
        })
    }
}

/// Longest run accepted, in drive periods: 10⁹ keeps every step index exact in f64. A run given
/// in seconds is held to the same count, and so is the count of its fastest time scale — the
/// drive, the pendulum's own swing (ω0), the damping (c) or the initial rate of turning — which
/// sets the number of steps.
pub const MAX_PERIODS: f64 = 1e9;

/// Fastest drive accepted (rad/s), and fastest initial rate of turning. The sampler takes instants within 1e-12 s of a step's end as
/// that end, so a drive period must stay far above it; 1e6 rad/s (6.3 µs) is 6e6 times it, and
/// 2400 times the rig's limit.
pub const MAX_OMEGA: f64 = 1e6;

/// The scene key of a body's parameter, for a [`ParamError`] from [`Geometry::validate`].
fn pendulum_key(name: &str) -> &'static str {
    match name {
        "length" => "pendulum.length",
        "inertia" => "pendulum.inertia",
        "mass" => "pendulum.mass",
        "com" => "pendulum.com",
        _ => "pendulum",
    }
}

impl Scene {
    /// A canonical scene from its numbers, run for `length` on the given equation.
    pub fn from_case(
        c: &crate::cases::SceneCase,
        length: RunLength,
        fidelity: Fidelity,
    ) -> Result<Scene, crate::error::ParamError> {
        Ok(Scene {
            pendulum: Geometry::rod(c.rod_length)?,
            drive: DriveSpec {
                amplitude: c.amplitude,
                frequency: DriveFrequency::Omega(c.omega),
                angle: DriveAngle::from_deg(c.drive_angle_deg)?,
            },
            gravity: c.gravity,
            initial_angle: crate::math::to_rad(c.initial_angle_deg),
            initial_rate: c.initial_rate,
            length,
            fidelity: FidelityChoice::Fixed(fidelity),
            effects: Effects {
                viscous: Some(Viscous::Q(c.q)),
                ..Effects::default()
            },
        })
    }

    /// Checks every number once; nothing runs on a scene that fails.
    pub fn check(&self) -> Result<(), SceneError> {
        let d = &self.drive;
        self.check_pendulum()?;
        check(
            "drive.amplitude",
            d.amplitude,
            d.amplitude > 0.0,
            "a finite number > 0 (m)",
        )?;
        match d.frequency {
            DriveFrequency::Omega(w) => check(
                "drive.omega",
                w,
                w > 0.0 && w <= MAX_OMEGA,
                "a number in (0, 1e6] (rad/s)",
            )?,
            DriveFrequency::R(r) => check("drive.r", r, r > 0.0, "a finite number > 0")?,
        }
        check(
            "environment.gravity",
            self.gravity,
            self.gravity > 0.0,
            "a finite number > 0 (m/s²)",
        )?;
        let angle_deg = crate::math::to_deg(self.initial_angle);
        check(
            "initial.angle_deg",
            angle_deg,
            angle_deg.abs() <= crate::model::drive::MAX_ANGLE_DEG,
            crate::model::drive::ANGLE_RANGE,
        )?;
        check(
            "initial.rate",
            self.initial_rate,
            self.initial_rate.abs() <= MAX_OMEGA,
            "a number in [-1e6, 1e6] (rad/s), no faster than the fastest drive",
        )?;
        match self.length {
            RunLength::Periods(p) => check(
                "run.periods",
                p,
                p > 0.0 && p <= MAX_PERIODS,
                "a number in (0, 1e9]",
            )?,
            RunLength::Duration(s) => check("run.duration", s, s > 0.0, "a finite number > 0 (s)")?,
        }
        let e = &self.effects;
        match e.viscous {
            Some(Viscous::Q(q)) => check("effects.viscous.q", q, q > 0.0, "a finite number > 0")?,
            Some(Viscous::Gamma(g)) => check(
                "effects.viscous.gamma",
                g,
                g >= 0.0,
                "a finite number >= 0 (1/s)",
            )?,
            None => {}
        }
        if let Some(t) = e.coulomb {
            check(
                "effects.coulomb.torque",
                t,
                t >= 0.0,
                "a finite number >= 0 (rad/s²)",
            )?;
        }
        if let Some(b) = e.tilt {
            let ok = b.abs() < crate::math::FRAC_PI_2;
            check(
                "effects.tilt.angle_deg",
                crate::math::to_deg(b),
                ok,
                "a number in (-90, 90) degrees",
            )?;
        }
        if let Some(b) = e.slider_crank {
            check(
                "effects.slider_crank.rod_length",
                b,
                b > 2.0 * d.amplitude,
                "a finite number > 2 x drive.amplitude (m)",
            )?;
        }
        if let Some(s) = e.ramp {
            check(
                "effects.ramp.seconds",
                s,
                s > 0.0,
                "a finite number > 0 (s)",
            )?;
        }
        if let Some(s) = e.sensor {
            check(
                "effects.sensor.bits",
                f64::from(s.bits),
                (4..=24).contains(&s.bits),
                "an integer in [4, 24]",
            )?;
            // Noise beyond a turn means nothing, and far beyond it (σ·|n| > 6.7e301 rad with a
            // 24-bit encoder) the quantiser's count overflows and the sample is NaN.
            check(
                "effects.sensor.noise_deg",
                crate::math::to_deg(s.noise),
                s.noise >= 0.0 && s.noise <= crate::math::TAU,
                "a number in [0, 360] degrees",
            )?;
            check(
                "effects.sensor.rate_hz",
                s.rate_hz,
                s.rate_hz > 0.0 && s.rate_hz <= 1e6,
                "a number in (0, 1e6] (Hz)",
            )?;
        }
        if let Some(t) = e.actuator {
            check(
                "effects.actuator.lag_s",
                t,
                t > 0.0,
                "a finite number > 0 (s)",
            )?;
        }
        // The full equation is exact for any stroke; only averaging needs A << l (see fidelity).
        // Ten pendulum lengths is far past any rig and guards against unit slips (mm for m).
        // Checked before the derived constants, so that a tiny pendulum is reported here rather
        // than as an overflow of g/ℓ.
        check(
            "drive.amplitude",
            d.amplitude,
            d.amplitude < 10.0 * self.pendulum.equivalent_length(),
            "less than 10 equivalent lengths (m)",
        )?;
        let p = self.physical()?;
        let (key, given) = self.frequency();
        check(
            key,
            given,
            p.omega <= MAX_OMEGA,
            "a drive of at most 1e6 rad/s",
        )?;
        // The drive's angular acceleration ω/T during a ramp or motor lag must be finite.
        if let Some(t) = e.ramp {
            check(
                "effects.ramp.seconds",
                t,
                (p.omega / t).is_finite(),
                "long enough that omega / ramp is finite (s)",
            )?;
        }
        if let Some(t) = e.actuator {
            check(
                "effects.actuator.lag_s",
                t,
                (p.omega / t).is_finite(),
                "long enough that omega / lag is finite (s)",
            )?;
        }
        let fastest = p.omega.max(p.omega0).max(p.c).max(self.initial_rate.abs());
        let seconds = self.duration(p.omega);
        let (key, value) = match self.length {
            RunLength::Periods(n) => ("run.periods", n),
            RunLength::Duration(s) => ("run.duration", s),
        };
        check(
            key,
            value,
            seconds > 0.0 && seconds * fastest / crate::math::TAU <= MAX_PERIODS,
            "longer than 0 s and at most 1e9 periods of the fastest of the drive, omega0, the damping c and the initial rate",
        )?;
        Ok(())
    }

    /// The drive frequency as given: its key and value.
    fn frequency(&self) -> (&'static str, f64) {
        match self.drive.frequency {
            DriveFrequency::Omega(w) => ("drive.omega", w),
            DriveFrequency::R(r) => ("drive.r", r),
        }
    }

    /// The body, checked as its constructor would (a literal may hold any numbers).
    fn check_pendulum(&self) -> Result<(), SceneError> {
        match self.pendulum.validate() {
            Ok(_) => Ok(()),
            Err(e) => Err(SceneError {
                key: pendulum_key(e.name),
                value: e.value,
                allowed: e.allowed,
            }),
        }
    }

    /// The derived physical constants every model needs. Each is checked: numbers that pass
    /// [`Scene::check`] one by one can still overflow together (g/ℓ, A²ω², ω0/Q).
    pub fn physical(&self) -> Result<Physical, SceneError> {
        self.check_pendulum()?;
        let ell = self.pendulum.equivalent_length();
        let g_eff = self.gravity * self.effects.tilt.map_or(1.0, crate::math::cos);
        let omega0 = crate::math::sqrt(g_eff / ell);
        let a = self.drive.amplitude;
        let omega = match self.drive.frequency {
            DriveFrequency::Omega(w) => w,
            // R = A²ω²/(2 g ℓ) with the effective gravity (physics §5: under tilt R uses g cos β).
            DriveFrequency::R(r) => crate::math::sqrt(2.0 * g_eff * ell * r) / a,
        };
        let c = match self.effects.viscous {
            None => 0.0,
            Some(Viscous::Q(q)) => omega0 / q,
            Some(Viscous::Gamma(g)) => 2.0 * g,
        };
        let r = a * a * omega * omega / (2.0 * g_eff * ell);
        let positive = "a finite number > 0 (the scene's numbers overflow or underflow together)";
        check(
            "environment.gravity",
            self.gravity,
            g_eff > 0.0 && omega0.is_finite() && omega0 > 0.0,
            "a finite number > 0 with g/l finite and > 0 (m/s², pendulum length in m)",
        )?;
        let (key, given) = self.frequency();
        check(key, given, omega.is_finite() && omega > 0.0, positive)?;
        // R overflows through the drive, (Aω)², or through a vanishing 2gℓ: name the one at fault.
        check(key, given, (a * omega * a * omega).is_finite(), positive)?;
        check(
            "environment.gravity",
            self.gravity,
            r.is_finite(),
            "large enough that R = A²ω²/(2gℓ) is finite (m/s²)",
        )?;
        let (key, given) = match self.effects.viscous {
            Some(Viscous::Gamma(g)) => ("effects.viscous.gamma", g),
            Some(Viscous::Q(q)) => ("effects.viscous.q", q),
            None => ("effects.viscous", 0.0),
        };
        check(key, given, c.is_finite(), positive)?;
        Ok(Physical {
            ell,
            g_eff,
            omega0,
            omega,
            r,
            c,
            amplitude: a,
        })
    }

    /// Run length in seconds.
    pub fn duration(&self, omega: f64) -> f64 {
        match self.length {
            RunLength::Periods(p) => p * crate::math::TAU / omega,
            RunLength::Duration(s) => s,
        }
    }
}

/// Derived constants of a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Physical {
    /// Equivalent length ℓ (m).
    pub ell: f64,
    /// g cos β (m/s²).
    pub g_eff: f64,
    /// √(g_eff/ℓ) (rad/s).
    pub omega0: f64,
    /// Set-point drive frequency (rad/s).
    pub omega: f64,
    /// R at the set point, with g_eff.
    pub r: f64,
    /// Viscous damping coefficient c (1/s); 0 without the effect.
    pub c: f64,
    pub amplitude: f64,
}
