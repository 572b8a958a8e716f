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

use super::measure::{self, Family};
use crate::timing;
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::Fidelity;
use kapitza_core::sim::{simulate, Controller, Method, Options, Scene};

/// Simulated time (s).
pub const SIMULATED: f64 = 60.0;
/// The final error a setting must reach.
pub const TARGET: f64 = 1e-6;
const OMEGA: f64 = 330.0;

/// One method's real-time factor.
#[derive(Debug, Clone, Serialize)]
pub struct RealTimeFactor {
    /// Full or averaged.
    pub model: Fidelity,
    /// DOP853, RKN 8(6) or RKN 12(10).
    pub method: Family,
    pub controller: Controller,
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
fn scene(fidelity: Fidelity) -> Result<Scene> {
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
    Ok(r.end.angle_rate())
}

/// Tolerances tried, loosest first: 1, 1.5, 2, 3, 5 and 7 per decade, fine enough that the
/// cheapest setting reaching [`TARGET`] is found to within a step of about 1.5 in tolerance.
const LADDER: [f64; 43] = [
    1e-2, 7e-3, 5e-3, 3e-3, 2e-3, 1.5e-3, 1e-3, 7e-4, 5e-4, 3e-4, 2e-4, 1.5e-4, 1e-4, 7e-5, 5e-5,
    3e-5, 2e-5, 1.5e-5, 1e-5, 7e-6, 5e-6, 3e-6, 2e-6, 1.5e-6, 1e-6, 7e-7, 5e-7, 3e-7, 2e-7, 1.5e-7,
    1e-7, 7e-8, 5e-8, 3e-8, 2e-8, 1.5e-8, 1e-8, 7e-9, 5e-9, 3e-9, 2e-9, 1.5e-9, 1e-9,
];

/// What is measured: (model, method, controller).
pub const RECORDS: [(Fidelity, Family, Controller); 10] = {
    use Controller::{Pi, Standard};
    use Family::{Dop853, Rkn1210, Rkn86};
    use Fidelity::{Averaged, Full};
    [
        (Full, Dop853, Standard),
        (Full, Dop853, Pi),
        (Full, Rkn86, Standard),
        (Full, Rkn1210, Standard),
        (Averaged, Dop853, Standard),
        (Averaged, Dop853, Pi),
        (Averaged, Rkn86, Standard),
        (Averaged, Rkn86, Pi),
        (Averaged, Rkn1210, Standard),
        (Averaged, Rkn1210, Pi),
    ]
};

/// The factors of every [`RECORDS`] entry.
pub fn real_time_factors(batch: Duration, mut tick: impl FnMut()) -> Result<Vec<RealTimeFactor>> {
    let mut out = Vec::new();
    for (model, family, controller) in RECORDS {
        let s = scene(model)?;
        let reference = end(
            &s,
            Method::Dop853 {
                rtol: 1e-13,
                atol: 1e-13,
            },
            Controller::Standard,
        )?;
        let method = |tol: f64| {
            family
                .method(tol)
                .ok_or_else(|| anyhow!("{family} is not one of ours"))
        };
        let mut found = None;
        for tol in LADDER {
            let got = end(&s, method(tol)?, controller)?;
            let error = measure::error(got, reference, OMEGA);
            if error <= TARGET {
                found = Some((tol, error));
                break;
            }
        }
        let (tol, error) = found.ok_or_else(|| {
            anyhow!("{model} {family} {controller}: no tolerance down to 1e-9 reaches 1e-6")
        })?;
        let method = method(tol)?;
        let cost = timing::cost(batch, || end(&s, method, controller));
        out.push(RealTimeFactor {
            model,
            method: family,
            controller,
            setting: tol,
            error,
            cpu_s: cost.cpu_s,
            factor: SIMULATED / cost.cpu_s,
        });
        tick();
    }
    Ok(out)
}
