//! `kapitza bench`: what accuracy costs, measured — work-precision of the simulator against a
//! converged reference and against a peer (the `ode_solvers` crate), the stability-criteria
//! ladder, and the cheapest method that answers each scene's physical question.
//!
//! | module | concept |
//! |---|---|
//! | [`scenes`] | the four scenes (settling, flutter, chaotic, long undamped) from the shipped files |
//! | [`measure`] | one of our runs: error against the reference, work, median time |
//! | [`peer`] | the same for `ode_solvers`' Dopri5 and Dop853 on our right-hand side |
//! | [`ratio`] | cost at a matched error (log-log interpolation) and ours over the peer's |
//! | [`ladder`] | the stability criteria against Floquet, and Floquet's own convergence |
//! | [`physical`] | the cheapest right answer per scene, `auto`, and the averaged model's validity |
//! | [`realtime`] | real-time factors at a final error of 1e-6, full and averaged model |
//! | [`report`] | the results as JSON, CSV and Markdown |
//! | [`plots`] | log-log PNGs |

pub mod ladder;
pub mod measure;
pub mod peer;
pub mod physical;
pub mod plots;
pub mod ratio;
pub mod realtime;
pub mod report;
pub mod scenes;

use anyhow::Result;
use serde::Serialize;
use std::time::Duration;

use kapitza_core::sim::Format;
use ladder::LadderPlan;
use measure::{Family, Point, Reference};
use physical::{CalibrationCase, Ladder};
use scenes::{BenchScene, Horizons};

/// The target errors of the peer comparison.
pub const TARGETS: [f64; 2] = [1e-6, 1e-9];

/// What a run measures.
#[derive(Debug, Clone)]
pub struct Plan {
    pub quick: bool,
    pub horizons: Horizons,
    /// Each timing is the median of five batches of at least this long.
    pub batch: Duration,
    /// Settings per (family, format), cheapest first.
    pub ladders: Vec<Ladder>,
    /// Peer tolerances (rtol = atol).
    pub peer: Vec<f64>,
    /// Fixed-step runs predicted to take more evaluations than this are left out.
    pub max_evals: f64,
    pub ladder: LadderPlan,
    /// The ladders of the physical question.
    pub physical: Vec<Ladder>,
    pub calibration_ratios: Vec<f64>,
    pub calibration_seconds: f64,
    /// Tolerances at which the shipped chaotic scene is classified.
    pub fate_tolerances: Vec<f64>,
}

fn decades(from: i32, to: i32, step: usize) -> Vec<f64> {
    (to..=from)
        .rev()
        .step_by(step)
        .map(|e| 10f64.powi(e))
        .collect()
}

fn doubling(from: f64, to: f64) -> Vec<f64> {
    let mut v = vec![from];
    while v.last().is_some_and(|&x| x * 2.0 <= to) {
        v.push(v.last().copied().unwrap_or(from) * 2.0);
    }
    v
}

impl Plan {
    /// The full run of `docs/accuracy.md`.
    pub fn full() -> Plan {
        let tol = decades(-3, -12, 1);
        use Family::*;
        use Format::{F32, F64};
        Plan {
            quick: false,
            horizons: Horizons {
                settling: 4000,
                flutter: 3000,
                chaotic_s: 1.5,
                undamped: 500,
                undamped_physical: 4000,
                chaotic_physical: 1000,
            },
            batch: Duration::from_millis(20),
            ladders: vec![
                (Rk4, F64, doubling(8.0, 2048.0)),
                (Dop853, F64, tol.clone()),
                (Rkn86, F64, tol.clone()),
                (Dop853Pi, F64, tol.clone()),
                (Rkn1210, F64, tol.clone()),
                (Verlet, F64, doubling(16.0, 16384.0)),
                (Yoshida4, F64, doubling(8.0, 2048.0)),
                (Yoshida6, F64, doubling(4.0, 1024.0)),
                (AveragedDop853, F64, decades(-3, -12, 3)),
                (AveragedRkn86, F64, decades(-3, -12, 3)),
                (AveragedRkn86Pi, F64, decades(-3, -12, 3)),
                (Rk4, F32, doubling(8.0, 512.0)),
                (Dop853, F32, decades(-3, -7, 1)),
                (Rkn86, F32, decades(-3, -7, 1)),
                (Verlet, F32, doubling(16.0, 1024.0)),
                (Yoshida4, F32, doubling(8.0, 256.0)),
            ],
            peer: tol,
            max_evals: 2e8,
            ladder: LadderPlan {
                ks: vec![
                    -0.9, -0.7, -0.5, -0.3, -0.2, -0.1, -0.05, 0.05, 0.1, 0.15, 0.2, 0.35, 0.5,
                    0.7, 0.9,
                ],
                floquet_ks: vec![-0.3, 0.5],
                floquet_steps: vec![25, 50, 100, 200, 500, 1000, 2000, 4000],
                reference_steps: 16_000,
                batch: Duration::from_millis(20),
            },
            physical: physical_ladders(false),
            calibration_ratios: vec![5.0, 7.0, 10.0, 14.0, 20.0, 28.0, 40.0, 56.0, 80.0],
            calibration_seconds: 80.0,
            fate_tolerances: decades(-6, -13, 1),
        }
    }

    /// The quick run for CI: short horizons and reduced ladders.
    pub fn quick() -> Plan {
        use Family::*;
        use Format::{F32, F64};
        let tol = decades(-3, -11, 2);
        Plan {
            quick: true,
            horizons: Horizons {
                settling: 200,
                flutter: 200,
                chaotic_s: 1.5,
                undamped: 300,
                undamped_physical: 1000,
                chaotic_physical: 1000,
            },
            batch: Duration::from_millis(2),
            ladders: vec![
                (Rk4, F64, vec![16.0, 64.0, 256.0]),
                (Dop853, F64, tol.clone()),
                (Rkn86, F64, tol.clone()),
                (Dop853Pi, F64, tol.clone()),
                (Rkn1210, F64, tol.clone()),
                (Verlet, F64, vec![64.0, 256.0, 1024.0]),
                (Yoshida4, F64, vec![16.0, 64.0, 256.0]),
                (Yoshida6, F64, vec![8.0, 32.0, 128.0]),
                (AveragedDop853, F64, vec![1e-3, 1e-9]),
                (AveragedRkn86, F64, vec![1e-3, 1e-9]),
                (Rk4, F32, vec![16.0, 64.0]),
                (Dop853, F32, vec![1e-3, 1e-5]),
            ],
            peer: tol,
            max_evals: 5e6,
            ladder: LadderPlan {
                ks: vec![-0.5, -0.3, 0.1, 0.5],
                floquet_ks: vec![-0.3],
                floquet_steps: vec![50, 200, 1000],
                reference_steps: 4000,
                batch: Duration::from_millis(2),
            },
            physical: physical_ladders(true),
            calibration_ratios: vec![7.0, 14.0, 28.0],
            calibration_seconds: 80.0,
            fate_tolerances: vec![1e-9, 1e-12],
        }
    }
}

fn physical_ladders(quick: bool) -> Vec<Ladder> {
    use Family::*;
    use Format::{F32, F64};
    if quick {
        vec![
            (Rk4, F64, vec![8.0, 16.0, 32.0]),
            (Dop853, F64, vec![1e-3, 1e-5]),
            (Rkn86, F64, vec![1e-3, 1e-5]),
            (Rkn1210, F64, vec![1e-3, 1e-5]),
            (AveragedDop853, F64, vec![1e-3, 1e-5]),
            (AveragedRkn86, F64, vec![1e-3, 1e-5]),
        ]
    } else {
        vec![
            (Rk4, F64, doubling(4.0, 256.0)),
            (Dop853, F64, decades(-2, -10, 1)),
            (Rkn86, F64, decades(-2, -10, 1)),
            (Rkn1210, F64, decades(-2, -10, 1)),
            (Verlet, F64, doubling(8.0, 512.0)),
            (Yoshida4, F64, doubling(4.0, 256.0)),
            (AveragedDop853, F64, decades(-2, -10, 1)),
            (AveragedRkn86, F64, decades(-2, -10, 1)),
            (Rk4, F32, doubling(4.0, 256.0)),
            (Dop853, F32, decades(-2, -6, 1)),
            (AveragedDop853, F32, decades(-2, -6, 1)),
        ]
    }
}

/// One scene's facts for the report.
#[derive(Debug, Clone, Serialize)]
pub struct SceneOut {
    pub name: &'static str,
    pub file: &'static str,
    pub what: &'static str,
    /// The `--set` overrides of the measurement scene (as `kapitza simulate` takes them).
    pub sets: Vec<String>,
    /// The same for the physical question.
    pub physical_sets: Vec<String>,
    pub horizon_s: f64,
    pub periods: f64,
    pub omega: f64,
    pub omega0: f64,
    pub undamped: bool,
    /// The averaged model's validity (`auto`'s rule) on this scene.
    pub averaged_valid: bool,
    pub reference: Reference,
    /// The chaotic scene's finite-time Lyapunov exponent (1/s) from the physical reference run.
    pub lyapunov: Option<f64>,
    /// ln(1/ε)/λ with ε = 2.2e-16: the time for a rounding-size error to grow to order one.
    pub predictability_s: Option<f64>,
    /// Median CPU time of one evaluation of the right-hand side alone (s).
    pub rhs_seconds: f64,
}

/// Everything a run measured.
#[derive(Debug, Clone, Serialize)]
pub struct Results {
    pub quick: bool,
    pub machine: Machine,
    pub scenes: Vec<SceneOut>,
    /// Ours over the peer's best, its Dop853 in autonomous form included (the strict
    /// comparison).
    pub peer_ratios: Vec<ratio::PeerRatio>,
    /// The same against the peer as published (its Dop853 fails on our time-dependent
    /// equation, so its best is Dopri5).
    pub peer_as_published_ratios: Vec<ratio::PeerRatio>,
    pub measurements: Vec<Point>,
    pub stability_criteria: Vec<ladder::CriterionRow>,
    pub floquet_convergence: Vec<ladder::FloquetRow>,
    pub physical: Vec<physical::PhysicalRow>,
    pub averaged_validity: Vec<physical::CalibrationRow>,
    /// The sweep fitted: |averaged − full| ≈ C (A/ℓ)², and where it reaches 0.1°.
    pub averaged_thresholds: Vec<physical::Threshold>,
    /// The shipped chaotic scene's verdict at each tolerance.
    pub chaotic_fate: Vec<physical::FateRow>,
    /// Simulated seconds per CPU second at a final error of 1e-6 (see [`realtime`]).
    pub real_time_factors: Vec<realtime::RealTimeFactor>,
    /// Settings left out (over the evaluation budget) or that failed, with why.
    pub skipped: Vec<String>,
    pub notes: Vec<String>,
    pub wall_s: f64,
}

/// Where it ran.
#[derive(Debug, Clone, Serialize)]
pub struct Machine {
    pub cpu: String,
    pub cores: usize,
    /// 1-minute load average at the start and at the end (Linux), for judging the timings.
    pub load_start: Option<f64>,
    pub load_end: Option<f64>,
}

pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

fn machine() -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".to_string());
    Machine {
        cpu,
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        load_start: load_average(),
        load_end: None,
    }
}

/// Progress: one tick per measured item.
pub trait Progress {
    fn set_total(&mut self, total: u64);
    fn tick(&mut self, what: &str);
}

/// Fixed-step evaluations per step.
fn evals_per_step(f: Family) -> f64 {
    match f {
        Family::Rk4 => 4.0,
        Family::Verlet => 1.0,
        Family::Yoshida4 => 3.0,
        Family::Yoshida6 => 7.0,
        _ => 0.0,
    }
}

/// Whether a family applies to a scene: symplectic methods need an undamped scene, the averaged
/// model is measured where its validity (the `auto` rule) holds.
fn applies(f: Family, s: &BenchScene, averaged_valid: bool) -> bool {
    match f {
        Family::Verlet | Family::Yoshida4 | Family::Yoshida6 => s.undamped,
        Family::AveragedDop853 | Family::AveragedRkn86 | Family::AveragedRkn86Pi => averaged_valid,
        _ => true,
    }
}

fn averaged_valid(s: &BenchScene) -> bool {
    let auto = kapitza_core::sim::Scene {
        fidelity: kapitza_core::sim::scene::FidelityChoice::Auto,
        ..s.scene
    };
    auto.physical()
        .ok()
        .and_then(|p| kapitza_core::sim::fidelity::decide(&auto, &p).ok())
        .is_some_and(|d| d.fidelity == kapitza_core::sim::scene::Fidelity::Averaged)
}

/// One measurement to make: a family at one setting on one scene.
struct Measurement {
    scene: usize,
    family: Family,
    format: Format,
    setting: f64,
}

/// Runs everything in `plan`.
pub fn run(plan: &Plan, progress: &mut dyn Progress) -> Result<Results> {
    let started = std::time::Instant::now();
    let mut machine = machine();
    let scenes = scenes::scenes(plan.horizons)?;
    let mut skipped = Vec::new();
    let mut notes = Vec::new();

    // Plan the measurements first, so the progress bar knows its length.
    let jobs = measurements(plan, &scenes, &mut skipped);
    progress.set_total(ticks(plan, &scenes, jobs.len()));

    let references = references(&scenes, progress)?;
    let points = measure(
        plan,
        &scenes,
        &references,
        jobs,
        progress,
        &mut skipped,
        &mut notes,
    );
    let ratios = |workaround: bool| {
        scenes
            .iter()
            .flat_map(|s| TARGETS.map(|t| ratio::peer_ratio(&points, s.name, t, workaround)))
            .collect::<Vec<_>>()
    };
    let peer_ratios = ratios(true);
    let peer_as_published_ratios = ratios(false);

    let stability_criteria =
        ladder::criteria(&plan.ladder, || progress.tick("stability criteria"))?;
    let floquet_convergence =
        ladder::floquet_convergence(&plan.ladder, || progress.tick("Floquet convergence"))?;

    let mut physical_rows = Vec::new();
    for s in &scenes {
        physical_rows.push(physical::question(s, &plan.physical, plan.batch, || {
            progress.tick(&format!("physical question: {}", s.name))
        })?);
    }

    let cases = calibration_cases()?;
    let averaged_validity = physical::calibration(
        &cases,
        &plan.calibration_ratios,
        plan.calibration_seconds,
        || progress.tick("averaged model validity"),
    )?;

    let chaotic_fate = match scenes.iter().find(|s| s.name == "chaotic") {
        Some(s) => physical::chaotic_fate(&s.shipped, &plan.fate_tolerances, || {
            progress.tick("chaotic scene over 4000 periods")
        })?,
        None => Vec::new(),
    };

    let scene_out = scene_facts(&scenes, references, &physical_rows, plan.batch)?;
    let real_time_factors =
        realtime::real_time_factors(plan.batch, || progress.tick("real-time factors"))?;
    machine.load_end = load_average();
    Ok(Results {
        quick: plan.quick,
        machine,
        scenes: scene_out,
        peer_ratios,
        peer_as_published_ratios,
        measurements: points,
        stability_criteria,
        floquet_convergence,
        physical: physical_rows,
        averaged_thresholds: physical::thresholds(&averaged_validity),
        averaged_validity,
        chaotic_fate,
        real_time_factors,
        skipped,
        notes,
        wall_s: started.elapsed().as_secs_f64(),
    })
}

/// Every (scene, family, setting) of the ladders that applies and fits the evaluation budget,
/// then the peer's; what is over the budget goes to `skipped`.
fn measurements(plan: &Plan, scenes: &[BenchScene], skipped: &mut Vec<String>) -> Vec<Measurement> {
    let mut jobs = Vec::new();
    for (i, s) in scenes.iter().enumerate() {
        let valid = averaged_valid(s);
        for (family, format, settings) in &plan.ladders {
            if !applies(*family, s, valid) {
                continue;
            }
            for &setting in settings {
                let predicted = s.periods() * setting * evals_per_step(*family);
                if predicted > plan.max_evals {
                    skipped.push(format!(
                        "{}: {} {} at {} steps per period (≈ {predicted:.1e} evaluations, over the budget of {:.0e})",
                        s.name,
                        family.label(),
                        format,
                        setting,
                        plan.max_evals
                    ));
                    continue;
                }
                jobs.push(Measurement {
                    scene: i,
                    family: *family,
                    format: *format,
                    setting,
                });
            }
        }
        for family in [
            Family::PeerDopri5,
            Family::PeerDop853,
            Family::PeerDop853Autonomous,
        ] {
            for &tol in &plan.peer {
                jobs.push(Measurement {
                    scene: i,
                    family,
                    format: Format::F64,
                    setting: tol,
                });
            }
        }
    }
    jobs
}

/// How many progress ticks the whole run makes.
fn ticks(plan: &Plan, scenes: &[BenchScene], measurements: usize) -> u64 {
    let physical_ticks: usize = scenes
        .iter()
        .map(|s| {
            plan.physical
                .iter()
                .filter(|(f, _, _)| {
                    s.undamped || !matches!(f, Family::Verlet | Family::Yoshida4 | Family::Yoshida6)
                })
                .count()
                + 1
        })
        .sum();
    let total = scenes.len()
        + measurements
        + plan.ladder.ks.len()
        + plan.ladder.floquet_ks.len() * plan.ladder.floquet_steps.len()
        + physical_ticks
        + 2 * plan.calibration_ratios.len()
        + plan.fate_tolerances.len()
        + realtime::RECORDS.len();
    total as u64
}

/// The converged reference of each scene.
fn references(scenes: &[BenchScene], progress: &mut dyn Progress) -> Result<Vec<Reference>> {
    let mut references = Vec::new();
    for s in scenes {
        references.push(measure::reference(s)?);
        progress.tick(&format!("reference: {}", s.name));
    }
    Ok(references)
}

/// Makes every measurement; a method that fails is listed once per scene in `skipped`, with
/// the settings it failed at and the first error.
fn measure(
    plan: &Plan,
    scenes: &[BenchScene],
    references: &[Reference],
    jobs: Vec<Measurement>,
    progress: &mut dyn Progress,
    skipped: &mut Vec<String>,
    notes: &mut Vec<String>,
) -> Vec<Point> {
    let mut points = Vec::new();
    let mut failed: Vec<(String, String, Vec<f64>, String)> = Vec::new();
    for Measurement {
        scene: i,
        family,
        format,
        setting,
    } in jobs
    {
        let s = &scenes[i];
        let what = format!("{}: {} {format} at {setting}", s.name, family.label());
        let got = if family.is_peer() {
            peer::peer(s, &references[i], family, setting, plan.batch, notes)
        } else {
            measure::ours(
                &measure::Job {
                    scene: s,
                    reference: &references[i],
                    family,
                    format,
                    setting,
                },
                plan.batch,
            )
        };
        match got {
            Ok(p) => points.push(p),
            Err(e) => {
                let method = ratio::curve_label(family, format);
                match failed.iter_mut().find(|f| f.0 == s.name && f.1 == method) {
                    Some(f) => f.2.push(setting),
                    None => {
                        failed.push((s.name.to_string(), method, vec![setting], format!("{e:#}")))
                    }
                }
            }
        }
        progress.tick(&what);
    }
    for (scene, method, settings, first) in failed {
        let list: Vec<String> = settings.iter().map(|x| format!("{x:e}")).collect();
        skipped.push(format!(
            "{scene}: {method} failed at {} (first: {first})",
            list.join(", ")
        ));
    }
    points
}

/// Each scene's facts for the report, with the chaotic scene's Lyapunov exponent from the
/// physical question's reference run.
fn scene_facts(
    scenes: &[BenchScene],
    references: Vec<Reference>,
    physical_rows: &[physical::PhysicalRow],
    batch: Duration,
) -> Result<Vec<SceneOut>> {
    let mut scene_out = Vec::new();
    for (s, reference) in scenes.iter().zip(references) {
        let p = s.scene.physical()?;
        let lyapunov = physical_rows
            .iter()
            .find(|r| r.scene == s.name)
            .and_then(|r| match r.reference {
                crate::outcome::OutcomeOut::Chaotic { lyapunov } => Some(lyapunov),
                _ => None,
            });
        scene_out.push(SceneOut {
            name: s.name,
            file: s.file,
            what: s.what,
            sets: s.sets.clone(),
            physical_sets: s.physical_sets.clone(),
            horizon_s: s.horizon(),
            periods: s.periods(),
            omega: p.omega,
            omega0: p.omega0,
            undamped: s.undamped,
            averaged_valid: averaged_valid(s),
            reference,
            predictability_s: lyapunov.map(|l| (1.0 / f64::EPSILON).ln() / l),
            rhs_seconds: peer::rhs_cost(&s.scene, batch)?,
            lyapunov,
        });
    }
    Ok(scene_out)
}

const HORIZONTAL: &str = include_str!("../../../scenes/horizontal-r1.75.toml");
const TILTED: &str = include_str!("../../../scenes/tilted-135.toml");

fn calibration_cases() -> Result<Vec<CalibrationCase>> {
    let load = |text: &str, file: &str, stem: &str| {
        crate::scene_file::parse(text, file, stem, &[]).map(|f| CalibrationCase {
            case: file.to_string(),
            scene: f.scene,
        })
    };
    Ok(vec![
        load(TILTED, "scenes/tilted-135.toml", "tilted-135")?,
        load(
            HORIZONTAL,
            "scenes/horizontal-r1.75.toml",
            "horizontal-r1.75",
        )?,
    ])
}
