//! `kapitza simulate`: run a scene file, say what the pendulum ended up doing and what it cost.

use anyhow::{anyhow, bail, Context, Result};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::cmd::predict::EquilibriumOut;
use crate::outcome::{self, Judged, OutcomeOut};
use crate::record::{Collect, Plan};
use crate::scene_file::{self, SceneFile};
use crate::{csv_out, plot};
use kapitza_core::integrate::Symplectic;
use kapitza_core::math;
use kapitza_core::model::equilibria;
use kapitza_core::sim::scene::{Fidelity, FidelityChoice};
use kapitza_core::sim::{Format, Method, Options, PlannedRun, Report};

/// Simulate a scene file (TOML; keys in docs/scenes.md) and report the outcome: rest (at which
/// angle), flutter, subharmonic, rotation, chaotic tumbling or oscillation.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// The scene file.
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Override a scene key, e.g. --set drive.angle_deg=120. VALUE is TOML (numbers, true/false,
    /// "quoted strings", { inline = tables }); a bare word is a string (--set run.fidelity=full);
    /// an empty VALUE removes the key. Repeatable; may add an effect (--set effects.viscous.q=50).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Write series.csv, strobes.csv, sensed.csv (with a sensor), summary.json, angle.png and
    /// phase.png into DIR (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print JSON instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Exit with status 1 unless the scene's [expect] table is met (a scene without one fails).
    #[arg(long)]
    pub check: bool,
    /// Time-series samples per drive period for series.csv (at most 200 000 samples in all:
    /// long runs keep every n-th). The plots sample at least 64 a period.
    #[arg(long, value_name = "N", default_value_t = 20, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(1..))]
    pub samples_per_period: u32,
    /// The end of the run the plots draw at full resolution: drive periods (`--window 20`) or
    /// seconds (`--window 1.5s`).
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "PERIODS|SECONDSs",
        default_value = "20"
    )]
    pub window: WindowLength,
    /// Run even when the estimated CPU time passes the budget (an hour).
    #[arg(long)]
    pub no_budget: bool,
}

/// The length of the end window: drive periods, or seconds with an `s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WindowLength {
    Periods(u64),
    Seconds(f64),
}

impl WindowLength {
    /// Whole drive periods (at least one) of `period` seconds.
    pub fn periods(self, period: f64) -> u64 {
        match self {
            Self::Periods(n) => n,
            Self::Seconds(s) => (s / period - 1e-9).ceil().max(1.0) as u64,
        }
    }
}

impl std::str::FromStr for WindowLength {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}` is not a window: give drive periods (20) or seconds (1.5s)");
        match s.trim().strip_suffix('s') {
            Some(secs) => match secs.trim().parse::<f64>() {
                Ok(x) if x.is_finite() && x > 0.0 => Ok(Self::Seconds(x)),
                _ => Err(bad()),
            },
            None => match s.trim().parse::<u64>() {
                Ok(n) if n > 0 => Ok(Self::Periods(n)),
                _ => Err(bad()),
            },
        }
    }
}

/// The `--json` output, also written to `summary.json`.
#[derive(Debug, Serialize)]
pub struct Summary {
    /// The scene file as given.
    pub scene: String,
    pub title: String,
    /// The `--set` overrides: the title and `[expect]` are the file's, written for the scene
    /// without them.
    pub sets: Vec<String>,
    pub outcome: OutcomeOut,
    /// The scene's `[expect]` with `met`; `null` when the scene has none.
    pub expect: Option<Judged>,
    pub fidelity: FidelityOut,
    /// `"dop853"`, `"rkn86"` or `"rkn1210"` (with `rtol`, `atol`); `"rk4"`, `"verlet"`,
    /// `"yoshida4"` or `"yoshida6"` (with `steps_per_period`).
    pub method: &'static str,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub steps_per_period: Option<f64>,
    /// `"f64"` or `"f32"`.
    pub format: Format,
    /// R = A²ω²/(2 g_eff ℓ) at the set point.
    pub r: f64,
    /// R of the averaged theory: R (1 + A²/(4b²)) with a slider-crank of rod length b, else R.
    /// The predicted equilibria use it.
    pub r_effective: f64,
    /// Set-point drive frequency (rad/s).
    pub omega: f64,
    /// √(g_eff/ℓ) (rad/s).
    pub omega0: f64,
    pub drive_angle_deg: f64,
    /// A (m).
    pub amplitude: f64,
    /// ℓ (m).
    pub equivalent_length: f64,
    /// g cos β (m/s²).
    pub gravity_effective: f64,
    /// Viscous c = 2γ (1/s); 0 without the effect.
    pub damping_c: f64,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Drive periods completed (stroboscopic samples).
    pub periods: u64,
    pub wall_s: f64,
    /// Simulated seconds per wall-clock second.
    pub real_time_factor: f64,
    pub work: WorkOut,
    pub end: EndOut,
    /// With Coulomb friction: how many times the pendulum stuck; else `null`.
    pub sticks: Option<u64>,
    /// Equilibria of the averaged theory at `r_effective` and θd, as `kapitza predict` lists them.
    pub predicted: Vec<EquilibriumOut>,
}

#[derive(Debug, Serialize)]
pub struct FidelityOut {
    /// What the scene asked for: `"auto"`, `"full"`, `"averaged"` or `"linearised"`.
    pub requested: &'static str,
    /// What ran.
    pub used: Fidelity,
    pub reason: String,
}

#[derive(Debug, Serialize)]
pub struct WorkOut {
    pub steps: u64,
    pub rhs_evals: u64,
    pub rejected: u64,
    pub lyapunov_steps: u64,
    pub lyapunov_rhs_evals: u64,
    pub lyapunov_rejected: u64,
}

#[derive(Debug, Serialize)]
pub struct EndOut {
    pub t: f64,
    /// In (−180°, 180°].
    pub angle_deg: f64,
    /// Turns completed, from the unwrapped angle (rounded towards zero).
    pub turns: i64,
    pub rate: f64,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    let file = scene_file::load(&args.scene, &args.set)?;
    let name = args.scene.display().to_string();
    // An unwritable --out must not throw away a whole run: checked before it.
    if let Some(dir) = &args.out {
        crate::chart::draw::prepare_dir(dir)?;
    }
    let options = Options {
        method: file.method,
        controller: file.controller,
        format: file.format,
        seed: file.seed,
        ..Options::default()
    };
    let mut planned = PlannedRun::new(&file.scene, &options).map_err(|e| anyhow!("{name}: {e}"))?;
    if let Some(cpu) = crate::budget::simulation(&file.scene, &options) {
        crate::budget::check(&format!("{name}: this run"), cpu, args.no_budget)?;
        crate::budget::announce(&name, cpu);
    }
    // The output is sized from the plan: its duration, and whether the averaged model runs
    // (its slow state has no fast wobble to resolve).
    let period = math::TAU / planned.physical.omega;
    let plan = match &args.out {
        Some(_) => {
            let averaged = planned.decision.fidelity == Fidelity::Averaged;
            let plan = Plan::new(
                period,
                planned.duration() / period,
                args.samples_per_period,
                args.window.periods(period),
                !averaged,
            )
            .map_err(|e| anyhow!("{e}"))?;
            planned
                .sample_every(plan.dt)
                .map_err(|e| anyhow!("{name}: {e}"))?;
            Some(plan)
        }
        None => None,
    };
    let mut rec = Collect::new(plan);
    let start = Instant::now();
    let result = planned.run(&mut rec);
    let wall = start.elapsed().as_secs_f64();
    rec.finish();
    let report = result.map_err(|e| anyhow!("{name}: {e}"))?;
    let summary = summarise(&name, &file, &args.set, &report, planned.r_effective, wall)?;
    let mut written = Vec::new();
    if let Some(dir) = &args.out {
        written = write_out(dir, &file, &summary, &rec)?;
    }
    if args.json {
        serde_json::to_writer_pretty(&mut *out, &summary)?;
        writeln!(out)?;
    } else {
        print_summary(&summary, &report, out)?;
        for f in &written {
            writeln!(out, "wrote {}", f.display())?;
        }
    }
    if args.check {
        match &summary.expect {
            None => bail!("{name}: --check needs an [expect] table, and the scene has none"),
            Some(j) if !j.met => bail!(
                "{name}: expectation not met: {}",
                j.why_not.as_deref().unwrap_or("")
            ),
            Some(_) => {}
        }
    }
    Ok(())
}

fn summarise(
    name: &str,
    file: &SceneFile,
    sets: &[String],
    report: &Report,
    r_effective: f64,
    wall: f64,
) -> Result<Summary> {
    let p = &report.physical;
    let scene = &file.scene;
    let outcome = OutcomeOut::from(report.outcome);
    let eqs = equilibria(r_effective, scene.drive.angle).context("predicted equilibria")?;
    let predicted = eqs
        .as_slice()
        .map(|e| EquilibriumOut::new(e, Some(p.omega0)))
        .collect();
    let (method, rtol, atol, steps_per_period) = match file.method {
        Method::Dop853 { rtol, atol } => ("dop853", Some(rtol), Some(atol), None),
        Method::Rkn86 { rtol, atol } => ("rkn86", Some(rtol), Some(atol), None),
        Method::Rkn1210 { rtol, atol } => ("rkn1210", Some(rtol), Some(atol), None),
        Method::Rk4 { steps_per_period } => ("rk4", None, None, Some(steps_per_period)),
        Method::Symplectic {
            scheme,
            steps_per_period,
        } => {
            let name = match scheme {
                Symplectic::Verlet => "verlet",
                Symplectic::Yoshida4 => "yoshida4",
                Symplectic::Yoshida6 => "yoshida6",
            };
            (name, None, None, Some(steps_per_period))
        }
    };
    let kapitza_core::sim::EndState {
        t: t_end,
        theta: theta_end,
        rate: rate_end,
    } = report.end;
    Ok(Summary {
        scene: name.to_string(),
        title: file.title.clone(),
        sets: sets.to_vec(),
        expect: file.expect.as_ref().map(|e| e.judge(&outcome)),
        outcome,
        fidelity: FidelityOut {
            requested: match scene.fidelity {
                FidelityChoice::Auto => "auto",
                FidelityChoice::Fixed(f) => f.name(),
            },
            used: report.decision.fidelity,
            reason: report.decision.to_string(),
        },
        method,
        rtol,
        atol,
        steps_per_period,
        format: file.format,
        r: p.r,
        r_effective,
        omega: p.omega,
        omega0: p.omega0,
        drive_angle_deg: scene.drive.angle.deg(),
        amplitude: p.amplitude,
        equivalent_length: p.ell,
        gravity_effective: p.g_eff,
        damping_c: p.c,
        duration_s: report.duration,
        periods: report.strobes,
        wall_s: wall,
        real_time_factor: report.duration / wall.max(1e-9),
        work: WorkOut {
            steps: report.work.steps,
            rhs_evals: report.work.rhs_evals,
            rejected: report.work.rejected,
            lyapunov_steps: report.lyapunov_work.steps,
            lyapunov_rhs_evals: report.lyapunov_work.rhs_evals,
            lyapunov_rejected: report.lyapunov_work.rejected,
        },
        end: EndOut {
            t: t_end,
            angle_deg: outcome::deg(theta_end),
            turns: (theta_end / math::TAU).trunc() as i64,
            rate: rate_end,
        },
        sticks: report.sticks,
        predicted,
    })
}

fn print_summary(s: &Summary, report: &Report, out: &mut dyn Write) -> Result<()> {
    writeln!(out, "{}  ({})", s.title, s.scene)?;
    if !s.sets.is_empty() {
        writeln!(
            out,
            "with --set {}: the title and [expect] are the file's, written for the scene without it",
            s.sets.join(", ")
        )?;
    }
    writeln!(
        out,
        "drive: R = {:.4}, ω = {:.2} rad/s, θd = {}°, A = {} m; ℓ = {:.4} m, ω0 = {:.3} rad/s (ω/ω0 = {:.1})",
        s.r,
        s.omega,
        s.drive_angle_deg,
        s.amplitude,
        s.equivalent_length,
        s.omega0,
        s.omega / s.omega0
    )?;
    writeln!(
        out,
        "fidelity: {} ({} requested): {}",
        s.fidelity.used, s.fidelity.requested, s.fidelity.reason
    )?;
    let name = match s.method {
        "dop853" => "DOP853",
        "rkn86" => "RKN 8(6)",
        "rkn1210" => "RKN 12(10)",
        "rk4" => "RK4",
        other => other,
    };
    let method = match (s.rtol, s.atol, s.steps_per_period) {
        (Some(r), Some(a), _) => format!("{name}, rtol {r:e}, atol {a:e}"),
        (_, _, Some(n)) => format!("{name}, {n} steps per drive period"),
        _ => s.method.to_string(),
    };
    writeln!(out, "method: {method}; numbers: {}", s.format)?;
    writeln!(out, "outcome: {}", s.outcome)?;
    if let Some(j) = &s.expect {
        if j.met {
            writeln!(out, "expected: {} — met", j.expect)?;
        } else {
            writeln!(
                out,
                "expected: {} — NOT MET: {}",
                j.expect,
                j.why_not.as_deref().unwrap_or("")
            )?;
        }
    }
    let eqs: Vec<String> = s
        .predicted
        .iter()
        .map(|e| {
            let reach = if e.within_90_of_drive {
                ""
            } else {
                ", beyond 90° of the drive"
            };
            format!("{} {}{reach}", outcome::show_deg(e.angle_deg), e.stability)
        })
        .collect();
    writeln!(
        out,
        "predicted equilibria (averaged theory): {}",
        eqs.join("; ")
    )?;
    if let Some(n) = s.sticks {
        writeln!(out, "stick–slip: stuck {n} times")?;
    }
    let w = &s.work;
    write!(
        out,
        "work: {} steps, {} rhs evaluations, {} rejected",
        w.steps, w.rhs_evals, w.rejected
    )?;
    if report.lyapunov_work.rhs_evals > 0 {
        write!(
            out,
            "; Lyapunov run {} rhs evaluations",
            w.lyapunov_rhs_evals
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "time: {} drive periods = {:.3} s simulated in {:.3} s wall (real-time factor {:.3e})",
        s.periods, s.duration_s, s.wall_s, s.real_time_factor
    )?;
    Ok(())
}

/// Writes the CSV files, `summary.json` and the plots; returns the paths written.
fn write_out(dir: &Path, file: &SceneFile, s: &Summary, rec: &Collect) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut written = Vec::new();
    let mut path = |name: &str| {
        let p = dir.join(name);
        written.push(p.clone());
        p
    };
    let kept = rec.kept.as_ref().context("the run kept no samples")?;
    csv_out::series(&path("series.csv"), &kept.series)?;
    csv_out::strobes(&path("strobes.csv"), &rec.strobes)?;
    if file.scene.effects.sensor.is_some() {
        csv_out::sensed(&path("sensed.csv"), &rec.sensed)?;
    }
    let json = path("summary.json");
    let mut text = serde_json::to_string_pretty(s)?;
    text.push('\n');
    std::fs::write(&json, text).with_context(|| format!("cannot write {}", json.display()))?;
    let title = if s.sets.is_empty() {
        s.title.clone()
    } else {
        format!("{} — changed by --set {}", s.title, s.sets.join(", "))
    };
    let input = plot::PlotInput {
        title: &title,
        subtitle: format!(
            "R = {:.3}, θd = {}°, ω = {:.1} rad/s, {} model, {}  —  outcome: {}",
            s.r, s.drive_angle_deg, s.omega, s.fidelity.used, s.method, s.outcome
        ),
        first: kept.first.buckets(),
        first_is_whole: kept.first.is_complete(),
        whole: kept.whole.buckets(),
        window: kept.window.samples().copied().collect(),
        strobes: rec.strobes.iter().map(|r| (r.t, r.theta, r.rate)).collect(),
        equilibria: equilibria(s.r_effective, file.scene.drive.angle)
            .context("predicted equilibria")?
            .as_slice()
            .map(|e| (outcome::deg(e.angle), e.stability))
            .collect(),
        averaged: s.fidelity.used == Fidelity::Averaged,
    };
    plot::angle_png(&path("angle.png"), &input)?;
    plot::phase_png(&path("phase.png"), &input)?;
    Ok(written)
}
