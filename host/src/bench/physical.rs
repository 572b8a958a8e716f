//! Where accuracy stops mattering: for each scene, the cheapest method whose answer to the
//! physical question — the outcome kind and the resting (or centre) angle to 0.1° — is already
//! right; what `fidelity = "auto"` with the default method picks; and a sweep of ω/ω0 that
//! tests the averaged model's validity rule (`shared/src/sim/fidelity.rs`).
//!
//! ```text
//! right  ⇔  same kind as the reference, and |angle − reference angle| ≤ 0.1° where the kind has
//!           an angle (rest, flutter, subharmonic, oscillation: the period-mean angle), the same
//!           order (subharmonic), the same direction and turn period (rotation)
//! reference: the scene as shipped, full model, DOP853 at rtol = atol = 1e-12, classified
//! a ladder's answer: the cheapest setting that is right and whose next finer setting is right
//! cost: median wall time of the classified run, including the Lyapunov run when the
//!       classifier needs one (that is what answering the question costs)
//! ```

use anyhow::{anyhow, Result};
use serde::Serialize;
use std::time::Duration;

use super::measure::{options, Family, SettingName};
use super::scenes::BenchScene;
use crate::outcome::OutcomeOut;
use crate::timing::seconds_per_eval;
use kapitza_core::math;
use kapitza_core::sim::fidelity::{AVERAGED_MAX_A_OVER_L, AVERAGED_MIN_RATIO};
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::{DriveFrequency, Fidelity, FidelityChoice, RunLength};
use kapitza_core::sim::{simulate, Format, Method, Report, Scene};

/// Angle tolerance of the physical question (degrees).
pub const ANGLE_TOL_DEG: f64 = 0.1;
/// The reference's tolerance.
pub const REFERENCE_TOL: f64 = 1e-12;

/// Whether `a` answers the physical question as `reference` does.
pub fn right(a: &OutcomeOut, reference: &OutcomeOut) -> bool {
    use OutcomeOut as O;
    let close = |x: f64, y: f64| math::wrap_deg(x - y).abs() <= ANGLE_TOL_DEG;
    match (a, reference) {
        (O::Rest { angle_deg: x }, O::Rest { angle_deg: y })
        | (O::Flutter { angle_deg: x }, O::Flutter { angle_deg: y })
        | (O::Oscillation { angle_deg: x, .. }, O::Oscillation { angle_deg: y, .. }) => {
            close(*x, *y)
        }
        (
            O::Subharmonic {
                order: n,
                angle_deg: x,
            },
            O::Subharmonic {
                order: m,
                angle_deg: y,
            },
        ) => n == m && close(*x, *y),
        (
            O::Rotation {
                direction: d,
                turns: n,
                periods: p,
            },
            O::Rotation {
                direction: e,
                turns: m,
                periods: q,
            },
        ) => d == e && n == m && p == q,
        (O::Chaotic { .. }, O::Chaotic { .. }) => true,
        _ => false,
    }
}

/// One classified run.
fn classified(scene: &Scene, method: Method, format: Format) -> Result<Report> {
    simulate(scene, &options(method, format, true), &mut Discard).map_err(|e| anyhow!("{e}"))
}

/// A method's answer and what it cost.
#[derive(Debug, Clone, Serialize)]
pub struct Choice {
    /// e.g. "RK4 f32".
    pub method: String,
    pub family: Family,
    pub format: Format,
    /// Full or averaged.
    pub fidelity: Fidelity,
    pub setting_name: SettingName,
    pub setting: f64,
    pub answer: OutcomeOut,
    pub wall_s: f64,
    /// Evaluations of the run and of its Lyapunov run.
    pub rhs_evals: u64,
}

/// What `fidelity = "auto"` with the default method (DOP853 at 1e-9, f64) does.
#[derive(Debug, Clone, Serialize)]
pub struct AutoChoice {
    pub fidelity: Fidelity,
    pub reason: String,
    pub answer: OutcomeOut,
    pub right: bool,
    pub wall_s: f64,
    pub rhs_evals: u64,
}

/// The physical question on one scene.
#[derive(Debug, Clone, Serialize)]
pub struct PhysicalRow {
    pub scene: String,
    pub reference: OutcomeOut,
    /// Each ladder's cheapest right setting (ladders that never get it right are left out).
    pub ladders: Vec<Choice>,
    /// Ladders that never got it right, with their last answer.
    pub never_right: Vec<Choice>,
    /// The cheapest right one by time.
    pub cheapest: Option<Choice>,
    pub auto: AutoChoice,
}

fn with_fidelity(scene: &Scene, f: Fidelity) -> Scene {
    Scene {
        fidelity: FidelityChoice::Fixed(f),
        ..*scene
    }
}

/// The ladders of the physical question: (family, format, settings from cheapest).
pub type Ladder = (Family, Format, Vec<f64>);

/// The physical question on one scene.
pub fn question(
    s: &BenchScene,
    ladders: &[Ladder],
    batch: Duration,
    mut tick: impl FnMut(),
) -> Result<PhysicalRow> {
    let full = with_fidelity(&s.physical, Fidelity::Full);
    let reference_run = classified(
        &full,
        Method::Dop853 {
            rtol: REFERENCE_TOL,
            atol: REFERENCE_TOL,
        },
        Format::F64,
    )?;
    let reference = OutcomeOut::from(reference_run.outcome);
    let mut found = Vec::new();
    let mut never_right = Vec::new();
    for (family, format, settings) in ladders {
        if !s.undamped && matches!(family, Family::Verlet | Family::Yoshida4 | Family::Yoshida6) {
            continue;
        }
        let scene = with_fidelity(&s.physical, family.fidelity());
        let mut answers: Vec<(f64, Report)> = Vec::new();
        for &setting in settings {
            let Some(method) = family.method(setting) else {
                continue;
            };
            if let Ok(r) = classified(&scene, method, *format) {
                answers.push((setting, r));
            }
        }
        tick();
        let ok: Vec<bool> = answers
            .iter()
            .map(|(_, r)| right(&OutcomeOut::from(r.outcome), &reference))
            .collect();
        let pick = (0..answers.len()).find(|&i| ok[i] && ok.get(i + 1).copied().unwrap_or(true));
        let choice = |i: usize, wall_s: f64| {
            let (setting, r) = &answers[i];
            Choice {
                method: super::ratio::curve_label(*family, *format),
                family: *family,
                format: *format,
                fidelity: family.fidelity(),
                setting_name: family.setting_name(),
                setting: *setting,
                answer: OutcomeOut::from(r.outcome),
                wall_s,
                rhs_evals: r.work.rhs_evals + r.lyapunov_work.rhs_evals,
            }
        };
        match pick {
            Some(i) => {
                let method = family.method(answers[i].0).expect("ours");
                let wall = seconds_per_eval(batch, || classified(&scene, method, *format));
                found.push(choice(i, wall));
            }
            None if !answers.is_empty() => never_right.push(choice(answers.len() - 1, f64::NAN)),
            None => {}
        }
    }
    let cheapest = found
        .iter()
        .min_by(|a, b| a.wall_s.total_cmp(&b.wall_s))
        .cloned();

    let auto_scene = Scene {
        fidelity: FidelityChoice::Auto,
        ..s.physical
    };
    let a = classified(&auto_scene, Method::DEFAULT, Format::F64)?;
    let answer = OutcomeOut::from(a.outcome);
    let auto = AutoChoice {
        fidelity: a.decision.fidelity,
        reason: a.decision.to_string(),
        right: right(&answer, &reference),
        answer,
        wall_s: seconds_per_eval(batch, || {
            classified(&auto_scene, Method::DEFAULT, Format::F64)
        }),
        rhs_evals: a.work.rhs_evals + a.lyapunov_work.rhs_evals,
    };
    tick();
    Ok(PhysicalRow {
        scene: s.name.to_string(),
        reference,
        ladders: found,
        never_right,
        cheapest,
        auto,
    })
}

/// One point of the averaged model's validity sweep.
#[derive(Debug, Clone, Serialize)]
pub struct CalibrationRow {
    /// The base scene, e.g. "scenes/tilted-135.toml".
    pub case: String,
    pub r: f64,
    pub drive_angle_deg: f64,
    /// ω/ω0.
    pub ratio: f64,
    /// A/ℓ = √(2R)/(ω/ω0) at fixed R.
    pub a_over_l: f64,
    pub full: OutcomeOut,
    pub averaged: OutcomeOut,
    /// Averaged minus full rest angle (degrees), when both rest.
    pub difference_deg: Option<f64>,
    /// The averaged model answers the physical question right.
    pub right: bool,
    /// The `auto` rule's verdict: ω/ω0 ≥ 10 and A/ℓ ≤ 0.1.
    pub auto_takes_averaged: bool,
}

/// The base scenes of the sweep: (label, scene).
pub struct CalibrationCase {
    pub case: String,
    pub scene: Scene,
}

/// Rest angle of the averaged and the full model at fixed R and θd as ω/ω0 varies
/// (A = ℓ √(2R)/(ω/ω0), so ω = ω0 · ratio); `seconds` of simulated time each.
pub fn calibration(
    cases: &[CalibrationCase],
    ratios: &[f64],
    seconds: f64,
    mut tick: impl FnMut(),
) -> Result<Vec<CalibrationRow>> {
    let mut rows = Vec::new();
    for c in cases {
        let p = c.scene.physical()?;
        for &ratio in ratios {
            let a_over_l = (2.0 * p.r).sqrt() / ratio;
            let mut scene = c.scene;
            scene.drive.amplitude = a_over_l * p.ell;
            scene.drive.frequency = DriveFrequency::R(p.r);
            scene.length = RunLength::Duration(seconds);
            let m = Method::Dop853 {
                rtol: 1e-10,
                atol: 1e-10,
            };
            let full = OutcomeOut::from(
                classified(&with_fidelity(&scene, Fidelity::Full), m, Format::F64)?.outcome,
            );
            let averaged = OutcomeOut::from(
                classified(&with_fidelity(&scene, Fidelity::Averaged), m, Format::F64)?.outcome,
            );
            let difference_deg = match (&full, &averaged) {
                (OutcomeOut::Rest { angle_deg: f }, OutcomeOut::Rest { angle_deg: a }) => {
                    Some(math::wrap_deg(a - f))
                }
                _ => None,
            };
            rows.push(CalibrationRow {
                case: c.case.clone(),
                r: p.r,
                drive_angle_deg: scene.drive.angle.deg(),
                ratio,
                a_over_l,
                right: right(&averaged, &full),
                auto_takes_averaged: ratio >= AVERAGED_MIN_RATIO
                    && a_over_l <= AVERAGED_MAX_A_OVER_L,
                full,
                averaged,
                difference_deg,
            });
            tick();
        }
    }
    Ok(rows)
}

/// The shipped chaotic scene's verdict at one tolerance.
#[derive(Debug, Clone, Serialize)]
pub struct FateRow {
    /// DOP853 rtol = atol (f64).
    pub tolerance: f64,
    pub outcome: OutcomeOut,
}

/// Drive periods of the fate runs: four times the classifier's window (1024 strobes), so that
/// the window, and the Lyapunov run that starts at its first strobe, begin on a trajectory that
/// has had 3000 periods to depend on the tolerance. With the shipped 1000 periods the window
/// covers the whole run: the Lyapunov pair then starts from the initial state at its own fixed
/// tolerance, and every run tolerance reports the same λ to the last digit.
pub const FATE_PERIODS: f64 = 4000.0;

/// The shipped chaotic scene over [`FATE_PERIODS`] drive periods classified at each tolerance:
/// the tumbling is a chaotic transient that may lock into rotation, and whether and when it
/// does depends on the rounding and truncation errors, so no tolerance makes this long-run
/// answer converge.
pub fn chaotic_fate(
    scene: &Scene,
    tolerances: &[f64],
    mut tick: impl FnMut(),
) -> Result<Vec<FateRow>> {
    let scene = Scene {
        length: RunLength::Periods(FATE_PERIODS),
        ..*scene
    };
    let mut rows = Vec::new();
    for &tol in tolerances {
        let m = Method::Dop853 {
            rtol: tol,
            atol: tol,
        };
        let r = classified(&with_fidelity(&scene, Fidelity::Full), m, Format::F64)?;
        rows.push(FateRow {
            tolerance: tol,
            outcome: OutcomeOut::from(r.outcome),
        });
        tick();
    }
    Ok(rows)
}

/// The averaged model's rest-angle error against A/ℓ, fitted per base scene.
#[derive(Debug, Clone, Serialize)]
pub struct Threshold {
    pub case: String,
    pub r: f64,
    pub drive_angle_deg: f64,
    /// C in |averaged − full| ≈ C (A/ℓ)² degrees: the median of |Δ|/(A/ℓ)² over the sweep.
    pub c_deg: f64,
    /// Where the fit reaches [`ANGLE_TOL_DEG`]: A/ℓ = √(0.1°/C).
    pub a_over_l_at_tol: f64,
    /// The same as ω/ω0 = √(2R)/(A/ℓ).
    pub ratio_at_tol: f64,
}

/// Fits |Δ| = C (A/ℓ)² to each case of the sweep.
pub fn thresholds(rows: &[CalibrationRow]) -> Vec<Threshold> {
    let mut cases: Vec<&str> = rows.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    cases
        .into_iter()
        .filter_map(|case| {
            let these: Vec<&CalibrationRow> = rows.iter().filter(|r| r.case == case).collect();
            let mut c: Vec<f64> = these
                .iter()
                .filter_map(|r| {
                    r.difference_deg
                        .map(|d| d.abs() / (r.a_over_l * r.a_over_l))
                })
                .filter(|c| c.is_finite() && *c > 0.0)
                .collect();
            if c.is_empty() {
                return None;
            }
            c.sort_by(f64::total_cmp);
            let c_deg = c[c.len() / 2];
            let first = these[0];
            let a = (ANGLE_TOL_DEG / c_deg).sqrt();
            Some(Threshold {
                case: case.to_string(),
                r: first.r,
                drive_angle_deg: first.drive_angle_deg,
                c_deg,
                a_over_l_at_tol: a,
                ratio_at_tol: (2.0 * first.r).sqrt() / a,
            })
        })
        .collect()
}
