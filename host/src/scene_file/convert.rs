//! The raw file converted to SI units, radians and the core's types, and checked: by hand where
//! two keys interact, by [`Scene::check`] for ranges, and by the fidelity decision, so that
//! nothing runs on a bad scene.

use anyhow::{anyhow, bail, Result};

use super::raw::*;
use super::{SceneFile, DEFAULT_RK4_STEPS};
use crate::outcome::{Expect, ExpectKind};
use kapitza_core::error::Range;
use kapitza_core::integrate::Symplectic;
use kapitza_core::math;
use kapitza_core::model::{DriveAngle, Geometry};
use kapitza_core::sim::scene::{
    DriveFrequency, DriveSpec, Effects, Fidelity, FidelityChoice, RunLength, Sensor, Viscous,
};
use kapitza_core::sim::{fidelity, Controller, Format, Method, Scene};
use kapitza_core::ParamError;

/// `key = value` is out of range.
pub(crate) fn out_of_range(
    key: &str,
    value: impl std::fmt::Display,
    allowed: &str,
) -> anyhow::Error {
    anyhow!("{key} = {value} is out of range: allowed {allowed}")
}

/// `v` if `range` admits it, else an error naming the scene key.
fn in_range(key: &str, v: f64, range: Range) -> Result<f64> {
    if range.admits(v) {
        Ok(v)
    } else {
        Err(out_of_range(key, v, range.allowed()))
    }
}

fn finite(key: &str, v: f64) -> Result<f64> {
    in_range(key, v, Range::Finite)
}

fn non_negative(key: &str, v: f64) -> Result<f64> {
    in_range(key, v, Range::NonNegative)
}

/// A core constructor's [`ParamError`] in terms of the scene key it came from.
fn param(key: &str, e: ParamError) -> anyhow::Error {
    out_of_range(key, e.value, e.allowed)
}

pub(super) fn convert(raw: RawScene, stem: &str) -> Result<SceneFile> {
    let pendulum = pendulum(&raw.pendulum)?;
    let d = &raw.drive;
    let frequency = match (d.omega, d.r) {
        (Some(w), None) => DriveFrequency::Omega(w),
        (None, Some(r)) => DriveFrequency::R(r),
        (Some(w), Some(r)) => bail!(
            "drive: both omega = {w} and r = {r} are given: allowed exactly one (omega in rad/s, or r, from which ω follows)"
        ),
        (None, None) => {
            bail!("drive: neither omega nor r is given: allowed exactly one (omega in rad/s, or r, from which ω follows)")
        }
    };
    let angle = DriveAngle::from_deg(d.angle_deg).map_err(|e| param("drive.angle_deg", e))?;
    let drive = DriveSpec {
        amplitude: d.amplitude,
        frequency,
        angle,
    };
    let run = &raw.run;
    let length = match (run.periods, run.duration) {
        (Some(p), None) => RunLength::Periods(p),
        (None, Some(s)) => RunLength::Duration(s),
        (Some(p), Some(s)) => bail!(
            "run: both periods = {p} and duration = {s} are given: allowed exactly one (periods: drive periods, or duration in s)"
        ),
        (None, None) => bail!(
            "run: neither periods nor duration is given: allowed exactly one (periods: drive periods, or duration in s)"
        ),
    };
    let fidelity = match run.fidelity {
        FidelityName::Full => FidelityChoice::Fixed(Fidelity::Full),
        FidelityName::Averaged => FidelityChoice::Fixed(Fidelity::Averaged),
        FidelityName::Linearised => FidelityChoice::Fixed(Fidelity::Linearised),
        FidelityName::Auto => FidelityChoice::Auto,
    };
    let effects = effects(&raw.effects)?;
    let scene = Scene {
        pendulum,
        drive,
        gravity: raw.environment.gravity,
        initial_angle: math::to_rad(finite("initial.angle_deg", raw.initial.angle_deg)?),
        initial_rate: finite("initial.rate", raw.initial.rate)?,
        length,
        fidelity,
        effects,
    };
    scene.check().map_err(|e| anyhow!("{e}"))?;
    let p = scene.physical().map_err(|e| anyhow!("{e}"))?;
    fidelity::decide(&scene, &p).map_err(|e| anyhow!("{e}"))?;
    let method = method(run)?;
    if !matches!(method, Method::Dop853 { .. }) && scene.effects.coulomb.is_some() {
        bail!("run.method: only dop853 can run effects.coulomb: allowed \"dop853\" or \"auto\" (stick–slip needs event location)");
    }
    if matches!(method, Method::Symplectic { .. }) && p.c > 0.0 {
        bail!("run.method: symplectic methods integrate undamped motion only: remove effects.viscous, or use \"dop853\" or \"rk4\"");
    }
    let controller = match run.controller {
        ControllerName::Standard => Controller::Standard,
        ControllerName::Pi => Controller::Pi,
    };
    let decided = fidelity::decide(&scene, &p).map_err(|e| anyhow!("{e}"))?;
    if controller == Controller::Pi && !method.has_step_controller(decided.fidelity) {
        bail!("run.controller = \"pi\" needs a method with an adaptive step: allowed with \"dop853\" (or \"auto\"), \"rkn1210\", or \"rkn86\" on the averaged model (fixed-step methods have no step controller; rkn86 on the full model chooses whole steps per drive period)");
    }
    Ok(SceneFile {
        title: raw.title.unwrap_or_else(|| stem.to_string()),
        scene,
        method,
        controller,
        format: match run.format {
            FormatName::F64 => Format::F64,
            FormatName::F32 => Format::F32,
        },
        seed: run.seed.unwrap_or(1),
        expect: raw.expect.map(expect).transpose()?,
    })
}

pub(crate) fn pendulum(p: &RawPendulum) -> Result<Geometry> {
    let name = match p.geometry {
        GeometryName::Rod => "rod",
        GeometryName::Point => "point",
        GeometryName::General => "general",
    };
    match p.geometry {
        GeometryName::Rod | GeometryName::Point => {
            for (key, v) in [("inertia", p.inertia), ("mass", p.mass), ("com", p.com)] {
                if let Some(v) = v {
                    bail!("pendulum.{key} = {v} is not allowed with geometry = \"{name}\": allowed only length (m)");
                }
            }
            let Some(length) = p.length else {
                bail!("pendulum: missing field `length` (m), needed by geometry = \"{name}\"");
            };
            let g = match p.geometry {
                GeometryName::Rod => Geometry::rod(length),
                _ => Geometry::point_mass(length),
            };
            g.map_err(|e| param("pendulum.length", e))
        }
        GeometryName::General => {
            if let Some(v) = p.length {
                bail!("pendulum.length = {v} is not allowed with geometry = \"general\": allowed inertia (kg m²), mass (kg) and com (m)");
            }
            let need = |key: &str, v: Option<f64>| {
                v.ok_or_else(|| {
                    anyhow!("pendulum: missing field `{key}`, needed by geometry = \"general\" (inertia in kg m², mass in kg, com in m)")
                })
            };
            let (i, m, z) = (
                need("inertia", p.inertia)?,
                need("mass", p.mass)?,
                need("com", p.com)?,
            );
            Geometry::general(i, m, z).map_err(|e| param(&format!("pendulum.{}", e.name), e))
        }
    }
}

fn effects(e: &RawEffects) -> Result<Effects> {
    let viscous = match &e.viscous {
        None => None,
        Some(RawViscous {
            q: Some(q),
            gamma: None,
        }) => Some(Viscous::Q(*q)),
        Some(RawViscous {
            q: None,
            gamma: Some(g),
        }) => Some(Viscous::Gamma(*g)),
        Some(RawViscous {
            q: Some(q),
            gamma: Some(g),
        }) => bail!(
            "effects.viscous: both q = {q} and gamma = {g} are given: allowed exactly one (q = ω0/(2γ), or gamma in 1/s)"
        ),
        Some(RawViscous {
            q: None,
            gamma: None,
        }) => bail!("effects.viscous: neither q nor gamma is given: allowed exactly one (q = ω0/(2γ), or gamma in 1/s)"),
    };
    let sensor = match &e.sensor {
        None => None,
        Some(s) => Some(Sensor {
            bits: s.bits,
            noise: math::to_rad(non_negative("effects.sensor.noise_deg", s.noise_deg)?),
            rate_hz: s.rate_hz,
        }),
    };
    let tilt = match &e.tilt {
        None => None,
        // Checked here in degrees, so the message repeats the value as written.
        Some(t) if t.angle_deg.is_finite() && t.angle_deg.abs() < 90.0 => {
            Some(math::to_rad(t.angle_deg))
        }
        Some(t) => {
            return Err(out_of_range(
                "effects.tilt.angle_deg",
                t.angle_deg,
                "a number in (-90, 90) degrees",
            ))
        }
    };
    Ok(Effects {
        viscous,
        coulomb: e.coulomb.as_ref().map(|c| c.torque),
        tilt,
        slider_crank: e.slider_crank.as_ref().map(|s| s.rod_length),
        ramp: e.ramp.as_ref().map(|r| r.seconds),
        sensor,
        actuator: e.actuator.as_ref().map(|a| a.lag_s),
    })
}

fn method(run: &RawRun) -> Result<Method> {
    let positive = |key: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(out_of_range(key, v, "a finite number > 0"))
        }
    };
    let fixed_step = |name: &str| -> Result<f64> {
        for (key, v) in [("rtol", run.rtol), ("atol", run.atol)] {
            if let Some(v) = v {
                bail!("run.{key} = {v} is not allowed with method = \"{name}\": allowed steps_per_period (rtol and atol are for \"dop853\", \"rkn86\" and \"rkn1210\")");
            }
        }
        run.steps_per_period.map_or(Ok(DEFAULT_RK4_STEPS), |s| {
            positive("run.steps_per_period", s)
        })
    };
    let symplectic = |scheme, name| {
        Ok(Method::Symplectic {
            scheme,
            steps_per_period: fixed_step(name)?,
        })
    };
    match run.method {
        MethodName::Rk4 => Ok(Method::Rk4 {
            steps_per_period: fixed_step("rk4")?,
        }),
        MethodName::Verlet => symplectic(Symplectic::Verlet, "verlet"),
        MethodName::Yoshida4 => symplectic(Symplectic::Yoshida4, "yoshida4"),
        MethodName::Yoshida6 => symplectic(Symplectic::Yoshida6, "yoshida6"),
        MethodName::Auto | MethodName::Dop853 | MethodName::Rkn86 | MethodName::Rkn1210 => {
            if let Some(s) = run.steps_per_period {
                bail!("run.steps_per_period = {s} is not allowed with an adaptive method: allowed only with a fixed-step method (rk4, verlet, yoshida4, yoshida6)");
            }
            let Method::Dop853 { rtol, atol } = Method::DEFAULT else {
                unreachable!("the default method is DOP853")
            };
            let rtol = run.rtol.map_or(Ok(rtol), |v| positive("run.rtol", v))?;
            let atol = run.atol.map_or(Ok(atol), |v| positive("run.atol", v))?;
            Ok(match run.method {
                MethodName::Rkn86 => Method::Rkn86 { rtol, atol },
                MethodName::Rkn1210 => Method::Rkn1210 { rtol, atol },
                _ => Method::Dop853 { rtol, atol },
            })
        }
    }
}

fn expect(e: RawExpect) -> Result<Expect> {
    let tolerance_deg = e.tolerance_deg.unwrap_or(0.5);
    if !(tolerance_deg.is_finite() && tolerance_deg > 0.0) {
        return Err(out_of_range(
            "expect.tolerance_deg",
            tolerance_deg,
            "a finite number > 0 (degrees)",
        ));
    }
    let angle_deg = e
        .angle_deg
        .map(|a| finite("expect.angle_deg", a))
        .transpose()?;
    if let Some(a) = angle_deg {
        if !e.kind.has_angle() {
            bail!(
                "expect.angle_deg = {a} is not allowed with kind = \"{}\": allowed only with rest, flutter, subharmonic or oscillation",
                e.kind.name()
            );
        }
    }
    if let Some(n) = e.order {
        if e.kind != ExpectKind::Subharmonic {
            bail!(
                "expect.order = {n} is not allowed with kind = \"{}\": allowed only with subharmonic",
                e.kind.name()
            );
        }
        if !(3..=16).contains(&n) {
            return Err(out_of_range(
                "expect.order",
                n,
                "an integer in [3, 16] (2 is flutter)",
            ));
        }
    }
    let direction = match e.direction {
        None => None,
        Some(d) if e.kind != ExpectKind::Rotation => bail!(
            "expect.direction = {d} is not allowed with kind = \"{}\": allowed only with rotation",
            e.kind.name()
        ),
        Some(d @ (1 | -1)) => Some(d as i8),
        Some(d) => {
            return Err(out_of_range(
                "expect.direction",
                d,
                "1 (θ increasing, counter-clockwise) or -1",
            ))
        }
    };
    Ok(Expect {
        kind: e.kind,
        angle_deg,
        tolerance_deg,
        order: e.order,
        direction,
    })
}
