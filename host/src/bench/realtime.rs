//! Real-time factors: simulated seconds per CPU second on the `realtime` benchmark's scene
//! (scenes/tilted-135.toml's pendulum and drive, R ≈ 3.3 at 135°, with Q = 50, for 60 s), each
//! method at the cheapest setting of its ladder that reaches a final error of 1e-6.
//!
//! ```text
//! error  = max(|Δθ|, |Δθ'|/ω) at t = 60 s, Δθ wrapped
//! full model:      against DOP853 at rtol = atol = 1e-13 on the full equation
//! averaged model:  against DOP853 at 1e-13 on the averaged equation (its own converged answer)
//! factor = 60 s / (CPU seconds of one run: median of five batches, classification off)
//! ```
//! CPU time of the measuring thread is used because other processes on a shared machine do not
//! inflate it; it still varies by some per cent from run to run.

use anyhow::{anyhow, Result};
use serde::Serialize;
use std::time::Duration;

use super::clock;
use kapitza_core::math;
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::{simulate, Controller, Method, Options, Scene};

/// Simulated time (s).
pub const SIMULATED: f64 = 60.0;
/// The final error a setting must reach.
pub const TARGET: f64 = 1e-6;
const OMEGA: f64 = 330.0;

/// One method's real-time factor.
#[derive(Debug, Clone, Serialize)]
pub struct RealTimeFactor {
    /// `"full"` or `"averaged"`.
    pub model: &'static str,
    /// `"dop853"`, `"rkn86"` or `"rkn1210"`.
    pub method: &'static str,
    /// The step controller: `"standard"` or `"pi"`.
    pub controller: &'static str,
    /// rtol = atol of the cheapest setting that reaches [`TARGET`].
    pub setting: f64,
    /// Its final error against the model's reference.
    pub error: f64,
    /// CPU seconds of one 60 s run.
    pub cpu_s: f64,
    /// Simulated seconds per CPU second.
    pub factor: f64,
}

/// The shipped tilted scene with Q = 50 for 60 s: the `realtime` benchmark's scene.
fn scene(fidelity: &str) -> Result<Scene> {
    let sets = [
        "effects.viscous.q=50",
        "run.periods=",
        &format!("run.duration={SIMULATED}"),
        &format!("run.fidelity={fidelity}"),
        "expect=",
    ]
    .map(String::from);
    let file = crate::scene_file::parse(TILTED, "scenes/tilted-135.toml", "tilted-135", &sets)?;
    Ok(file.scene)
}

const TILTED: &str = include_str!("../../../scenes/tilted-135.toml");

fn end(s: &Scene, method: Method, controller: Controller) -> Result<(f64, f64)> {
    let options = Options {
        method,
        controller,
        classify: false,
        ..Options::default()
    };
    let r = simulate(s, &options, &mut Discard).map_err(|e| anyhow!("{e}"))?;
    Ok((r.end.1, r.end.2))
}

/// Tolerances tried, loosest first.
const LADDER: [f64; 22] = [
    1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6, 5e-7, 2e-7, 1e-7,
    5e-8, 2e-8, 1e-8, 5e-9, 2e-9, 1e-9,
];

/// What is measured: (model, method, controller).
pub const RECORDS: [(&str, &str, &str); 10] = [
    ("full", "dop853", "standard"),
    ("full", "dop853", "pi"),
    ("full", "rkn86", "standard"),
    ("full", "rkn1210", "standard"),
    ("averaged", "dop853", "standard"),
    ("averaged", "dop853", "pi"),
    ("averaged", "rkn86", "standard"),
    ("averaged", "rkn86", "pi"),
    ("averaged", "rkn1210", "standard"),
    ("averaged", "rkn1210", "pi"),
];

/// The factors of every [`RECORDS`] entry.
pub fn real_time_factors(batch: Duration, mut tick: impl FnMut()) -> Result<Vec<RealTimeFactor>> {
    let mut out = Vec::new();
    for (model, name, controller_name) in RECORDS {
        let s = scene(model)?;
        let reference = end(
            &s,
            Method::Dop853 {
                rtol: 1e-13,
                atol: 1e-13,
            },
            Controller::Standard,
        )?;
        let method = |tol: f64| match name {
            "rkn86" => Method::Rkn86 {
                rtol: tol,
                atol: tol,
            },
            "rkn1210" => Method::Rkn1210 {
                rtol: tol,
                atol: tol,
            },
            _ => Method::Dop853 {
                rtol: tol,
                atol: tol,
            },
        };
        let controller = if controller_name == "pi" {
            Controller::Pi
        } else {
            Controller::Standard
        };
        let mut found = None;
        for tol in LADDER {
            let got = end(&s, method(tol), controller)?;
            let error = math::wrap_pi(got.0 - reference.0)
                .abs()
                .max((got.1 - reference.1).abs() / OMEGA);
            if error <= TARGET {
                found = Some((tol, error));
                break;
            }
        }
        let (tol, error) = found.ok_or_else(|| {
            anyhow!("{model} {name} {controller_name}: no tolerance down to 1e-9 reaches 1e-6")
        })?;
        let cost = clock::cost(batch, || end(&s, method(tol), controller));
        out.push(RealTimeFactor {
            model,
            method: name,
            controller: controller_name,
            setting: tol,
            error,
            cpu_s: cost.cpu_s,
            factor: SIMULATED / cost.cpu_s,
        });
        tick();
    }
    Ok(out)
}
