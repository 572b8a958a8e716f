//! `kapitza boundary`: the stability window in m = A/ℓ from every criterion of physics §4, each
//! with its difference from Floquet and its measured cost.

mod omega;

use anyhow::{bail, Result};
use serde::Serialize;
use std::io::Write;
use std::time::Duration;

use crate::input::{self, GeometryArgs};
use crate::timing::seconds_per_eval;
use kapitza_core::model::Groups;
use kapitza_core::stability::{
    averaging, harmonic_balance, hill, mathieu, End, Window, DELTA_MAX, K_MAX,
};

/// Subharmonic orders reported (n = 2 is the flutter boundary).
const ORDERS: std::ops::RangeInclusive<u32> = 2..=8;
/// Length of one timing batch.
const BATCH: Duration = Duration::from_millis(20);

/// Stability window in m = A/ℓ of the hanging or inverted position, from every criterion.
///
/// Give the signed k of the linearised equation x'' + c x' + ω²(k − m cos ωt) x = 0 (negative
/// about the inverted position, positive about the hanging one), or a pendulum and drive
/// frequency (--rod/--point with --omega; the inverted position unless --hanging), which also
/// gives the window as amplitudes A in metres. Only Floquet includes damping; the other
/// criteria report their undamped value and say so.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Signed k = ±(ω0/ω)²: < 0 about the inverted position, > 0 about the hanging one.
    #[arg(long, value_name = "K", allow_hyphen_values = true,
          required_unless_present_any = ["rod", "point"],
          conflicts_with_all = ["rod", "point", "omega", "damping", "hanging", "amplitude"])]
    pub k: Option<f64>,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    /// Drive angular frequency ω (rad/s). With --rod or --point.
    #[arg(long, value_name = "W", allow_hyphen_values = true)]
    pub omega: Option<f64>,
    /// Pivot amplitude A (m), half the stroke. With --rod or --point instead of --omega: the
    /// window of ω (rad/s, Hz, rpm) in which that stroke holds the inverted position (exact,
    /// undamped), with ωc explained.
    #[arg(long, value_name = "A", allow_hyphen_values = true, conflicts_with_all = ["omega", "hanging", "damping", "quality"])]
    pub amplitude: Option<f64>,
    /// Gravity g (m/s²). With --rod or --point.
    #[arg(
        long,
        value_name = "G",
        default_value_t = 9.81,
        allow_hyphen_values = true
    )]
    pub gravity: f64,
    /// Study the hanging position (k > 0) instead of the inverted one. With --rod or --point.
    #[arg(long)]
    pub hanging: bool,
    /// Damping coefficient c (1/s) of the term c θ'. With --rod or --point.
    #[arg(
        long,
        value_name = "C",
        conflicts_with = "quality",
        allow_hyphen_values = true
    )]
    pub damping: Option<f64>,
    /// Quality factor Q = ω0/c of the damping (δ = c/ω = √|k|/Q).
    #[arg(
        long = "q",
        id = "quality",
        value_name = "Q",
        allow_hyphen_values = true
    )]
    pub quality: Option<f64>,
    /// Floquet: tolerance on each boundary in m.
    #[arg(
        allow_hyphen_values = true,
        long,
        value_name = "TOL",
        default_value_t = 1e-7
    )]
    pub tol: f64,
    /// Floquet with damping: RK4 steps per drive period of tr M (default 1000; integrated over
    /// half a period). Undamped ends come from Hill's determinant and need no steps. Refused
    /// when doubling it moves an end by more than --tol: such a setting cannot be converged.
    #[arg(allow_hyphen_values = true, long, value_name = "N")]
    pub steps: Option<u32>,
    /// Run even when the estimated CPU time passes the budget (an hour).
    #[arg(long)]
    pub no_budget: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct Report {
    pub k: f64,
    pub position: &'static str,
    /// δ = c/ω: damping per radian of drive phase.
    pub delta: f64,
    pub physical: Option<Physical>,
    pub criteria: Vec<Criterion>,
    pub subharmonics: Vec<Subharmonic>,
}

#[derive(Debug, Serialize)]
pub struct Physical {
    pub equivalent_length: f64,
    pub omega: f64,
    pub omega0: f64,
    pub gravity: f64,
    pub damping_c: f64,
}

#[derive(Debug, Serialize)]
pub struct Criterion {
    pub name: &'static str,
    pub lower_m: Option<f64>,
    pub upper_m: Option<f64>,
    /// Why an end is null.
    pub lower_reason: Option<&'static str>,
    pub upper_reason: Option<&'static str>,
    /// The ends as pivot amplitudes A = m ℓ in metres (with a pendulum).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lower_amplitude: Option<Option<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub upper_amplitude: Option<Option<f64>>,
    /// This criterion's end minus Floquet's (null where either is missing).
    pub lower_diff_from_floquet: Option<f64>,
    pub upper_diff_from_floquet: Option<f64>,
    /// Measured wall time of one evaluation of this criterion's window (both ends), median of 5.
    pub seconds_per_eval: f64,
    pub includes_damping: bool,
    /// How far to trust the values (e.g. the Mathieu series used outside its range, or an
    /// undamped value beside a damped reference).
    pub notes: Vec<&'static str>,
    /// Harmonic balance only: the truncated (A5 dropped) flutter formula.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub upper_m_truncated: Option<f64>,
    /// Floquet only: integrations of tr M (half a period each; none undamped) and their
    /// right-hand-side evaluations one window took.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub monodromies: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rhs_evals: Option<u64>,
    /// Floquet only: LDLᵀ passes over Hill's tridiagonal blocks (Sturm counts and Newton
    /// steps) one window took.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sturm_counts: Option<u64>,
}

#[derive(Debug, Serialize)]
pub struct Subharmonic {
    pub order: u32,
    /// Harmonic balance (5×5 determinant; n = 2: the 3×3 flutter boundary).
    pub m: Option<f64>,
    /// Floquet: where tr M = 2 cos(2π/n), undamped.
    pub m_floquet: Option<f64>,
    pub reason: Option<&'static str>,
    pub reason_floquet: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<Option<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amplitude_floquet: Option<Option<f64>>,
}

/// The linearised problem to study.
struct Problem {
    k: f64,
    delta: f64,
    physical: Option<Physical>,
}

pub fn run(args: &Args, out: &mut dyn Write) -> Result<()> {
    if let (Some(a), Some(geometry)) = (args.amplitude, args.geometry.geometry()?) {
        let w = omega::compute(
            geometry.equivalent_length(),
            input::positive("--amplitude", a)?,
            input::positive("--gravity", args.gravity)?,
        )?;
        if args.json {
            serde_json::to_writer_pretty(&mut *out, &w)?;
            writeln!(out)?;
        } else {
            omega::print(&w, out)?;
        }
        return Ok(());
    }
    let report = compute(args)?;
    if args.json {
        serde_json::to_writer_pretty(&mut *out, &report)?;
        writeln!(out)?;
    } else {
        print_table(&report, out)?;
    }
    Ok(())
}

fn problem(args: &Args) -> Result<Problem> {
    let quality = args
        .quality
        .map(|q| input::positive("--q", q))
        .transpose()?;
    if let Some(k) = args.k {
        let k = input::finite("--k", k)?;
        if k.abs() > K_MAX {
            bail!("--k {k} is out of range: expected |k| <= {K_MAX}");
        }
        // δ = c/ω and Q = ω0/c with ω0/ω = √|k|: δ = √|k|/Q.
        let quality = quality
            .map(|q| input::quality_for("--q", q, k.abs()))
            .transpose()?;
        let delta = quality.map_or(0.0, |q| k.abs().sqrt() / q);
        return Ok(Problem {
            k,
            delta,
            physical: None,
        });
    }
    let Some(geometry) = args.geometry.geometry()? else {
        bail!("give --k K, or a pendulum (--rod L or --point l) with --omega W");
    };
    let Some(omega) = args.omega else {
        bail!("--rod/--point need --omega W (rad/s), or --amplitude A (m) for the window in ω");
    };
    let omega = input::positive("--omega", omega)?;
    let gravity = input::positive("--gravity", args.gravity)?;
    let ell = geometry.equivalent_length();
    let omega0 = (gravity / ell).sqrt();
    let c = match (args.damping, quality) {
        (Some(c), _) => input::non_negative("--damping", c)?,
        (None, Some(q)) => omega0 / input::quality_for("--q", q, (omega0 / omega).powi(2))?,
        (None, None) => 0.0,
    };
    if c / omega > DELTA_MAX {
        bail!(
            "--damping {c} is out of range for --omega {omega}: expected at most {} (δ = c/ω \
             past {DELTA_MAX} per radian of drive is beyond what the criteria compute)",
            DELTA_MAX * omega
        );
    }
    // The amplitude only scales m; any positive value gives the same k and δ.
    let g = Groups::new(ell, gravity, ell, omega, c)?;
    let k = g.k(!args.hanging);
    if k.abs() > K_MAX {
        bail!(
            "(ω0/ω)² = {} is out of range: expected <= {K_MAX} (raise --omega)",
            k.abs()
        );
    }
    Ok(Problem {
        k,
        delta: g.delta(),
        physical: Some(Physical {
            equivalent_length: ell,
            omega,
            omega0,
            gravity,
            damping_c: c,
        }),
    })
}

/// Largest m searched for the Floquet window (the rig's m is well below 1).
const M_SEARCH: f64 = 10.0;

/// The Floquet window with its work: (window, tr M integrations, rhs evaluations, Sturm counts).
fn floquet_window(
    k: f64,
    delta: f64,
    tol: f64,
    half_steps: u32,
) -> Result<(Window, u64, u64, u64)> {
    if delta == 0.0 {
        let (w, _, counts) = hill::first_window(k, M_SEARCH, tol)?;
        return Ok((w, 0, 0, counts));
    }
    let d = hill::damped_window(k, delta, tol, half_steps)?;
    let evals = d.traces * 4 * u64::from(half_steps);
    Ok((d.window, d.traces, evals, d.counts))
}

/// Most RK4 steps per drive period: 1e8 already takes minutes for one window.
const MAX_STEPS: u32 = 100_000_000;

/// Estimated CPU seconds of the damped Floquet work at `half_steps`: one window at the default
/// steps, timed and scaled by the steps, for the reference, the check at twice the steps (2×)
/// and the timing batches (at least 5 windows).
fn estimate(k: f64, delta: f64, tol: f64, half_steps: u32) -> Result<f64> {
    let cpu0 = crate::timing::thread_cpu();
    floquet_window(k, delta, tol, hill::DEFAULT_HALF_STEPS)?;
    let cpu = crate::timing::thread_cpu() - cpu0;
    Ok(cpu * f64::from(half_steps) / f64::from(hill::DEFAULT_HALF_STEPS) * 8.0)
}

/// Refuses a step count whose damped ends move by more than `tol` when it is doubled.
fn check_converged(k: f64, delta: f64, tol: f64, half_steps: u32, w: &Window) -> Result<()> {
    let (finer, ..) = floquet_window(k, delta, tol, 2 * half_steps)?;
    for (end, a, b) in [
        ("lower", w.lower, finer.lower),
        ("upper", w.upper, finer.upper),
    ] {
        if let (Some(a), Some(b)) = (a.value(), b.value()) {
            if (a - b).abs() > tol {
                bail!(
                    "--steps {} cannot be converged: doubling it moves the Floquet {end} end \
                     by {:.1e} (more than --tol {tol:e}); use more steps (default 1000)",
                    2 * half_steps,
                    (a - b).abs()
                );
            }
        }
    }
    Ok(())
}

pub fn compute(args: &Args) -> Result<Report> {
    let p = problem(args)?;
    let tol = input::positive("--tol", args.tol)?;
    let steps = args.steps.unwrap_or(2 * hill::DEFAULT_HALF_STEPS);
    if !(2..=MAX_STEPS).contains(&steps) {
        bail!("--steps {steps} is out of range: expected 2 to 1e8");
    }
    let half_steps = steps / 2;
    let (k, delta) = (p.k, p.delta);
    if delta > 0.0 && half_steps > hill::DEFAULT_HALF_STEPS {
        let cpu = estimate(k, delta, tol, half_steps)?;
        crate::budget::check("this boundary", cpu, args.no_budget)?;
        crate::budget::announce("boundary", cpu);
    }
    let ell = p.physical.as_ref().map(|ph| ph.equivalent_length);
    let undamped = (delta > 0.0).then_some("undamped value: only Floquet includes damping");

    let (reference, traces, evals, counts) = floquet_window(k, delta, tol, half_steps)?;
    if delta > 0.0 {
        check_converged(k, delta, tol, half_steps, &reference)?;
    }
    let f_cost = seconds_per_eval(BATCH, || floquet_window(k, delta, tol, half_steps));

    let mut criteria = vec![
        criterion(
            "averaging",
            averaging::window(k)?,
            &reference,
            ell,
            undamped,
            seconds_per_eval(BATCH, || averaging::window(k)),
        ),
        criterion(
            "mathieu",
            mathieu::window(k)?,
            &reference,
            ell,
            undamped,
            seconds_per_eval(BATCH, || mathieu::window(k)),
        ),
        criterion(
            "harmonic_balance",
            harmonic_balance::window(k)?,
            &reference,
            ell,
            undamped,
            seconds_per_eval(BATCH, || harmonic_balance::window(k)),
        ),
    ];
    criteria[2].upper_m_truncated = harmonic_balance::truncated_upper(k)?.value();
    let mut f = criterion("floquet", reference, &reference, ell, None, f_cost);
    f.includes_damping = true;
    f.monodromies = Some(traces);
    f.rhs_evals = Some(evals);
    f.sturm_counts = Some(counts);
    if delta == 0.0 && args.steps.is_some() {
        f.notes.push(STEPS_UNUSED);
    }
    criteria.push(f);

    let mut subharmonics = Vec::new();
    for n in ORDERS {
        let hb = harmonic_balance::subharmonic_m(k, n)?;
        let fl = hill::subharmonic_m(k, n, tol)?;
        subharmonics.push(Subharmonic {
            order: n,
            m: hb.value(),
            m_floquet: fl.value(),
            reason: reason(hb),
            reason_floquet: reason(fl),
            amplitude: ell.map(|l| hb.value().map(|m| m * l)),
            amplitude_floquet: ell.map(|l| fl.value().map(|m| m * l)),
        });
    }
    let position = if k < 0.0 { "inverted" } else { "hanging" };
    Ok(Report {
        k,
        position,
        delta,
        physical: p.physical,
        criteria,
        subharmonics,
    })
}

fn reason(e: End) -> Option<&'static str> {
    match e {
        End::Value(_) => None,
        End::Missing(why) => Some(why),
    }
}

fn criterion(
    name: &'static str,
    w: Window,
    floquet: &Window,
    ell: Option<f64>,
    undamped: Option<&'static str>,
    seconds_per_eval: f64,
) -> Criterion {
    let diff = |a: End, b: End| a.value().zip(b.value()).map(|(a, b)| a - b);
    Criterion {
        name,
        lower_m: w.lower.value(),
        upper_m: w.upper.value(),
        lower_reason: reason(w.lower),
        upper_reason: reason(w.upper),
        lower_amplitude: ell.map(|l| w.lower.value().map(|m| m * l)),
        upper_amplitude: ell.map(|l| w.upper.value().map(|m| m * l)),
        lower_diff_from_floquet: diff(w.lower, floquet.lower),
        upper_diff_from_floquet: diff(w.upper, floquet.upper),
        seconds_per_eval,
        includes_damping: false,
        notes: w.note.into_iter().chain(undamped).collect(),
        upper_m_truncated: None,
        monodromies: None,
        rhs_evals: None,
        sturm_counts: None,
    }
}

/// Note: `--steps` given for an undamped problem.
const STEPS_UNUSED: &str =
    "--steps does not apply: undamped ends come from Hill's determinant (no integration)";

fn fmt_opt(x: Option<f64>, prec: usize) -> String {
    x.map_or("—".into(), |v| format!("{v:.prec$}"))
}

fn fmt_diff(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:+.2e}"))
}

fn fmt_seconds(s: f64) -> String {
    match s {
        s if s < 1e-6 => format!("{:.0} ns", s * 1e9),
        s if s < 1e-3 => format!("{:.1} µs", s * 1e6),
        s => format!("{:.1} ms", s * 1e3),
    }
}

fn print_table(r: &Report, out: &mut dyn Write) -> Result<()> {
    if let Some(p) = &r.physical {
        writeln!(
            out,
            "pendulum: ℓ = {:.4} m, ω = {} rad/s, ω0 = {:.3} rad/s, c = {:.4} 1/s",
            p.equivalent_length, p.omega, p.omega0, p.damping_c
        )?;
    }
    let delta = if r.delta == 0.0 {
        "0 (undamped)".into()
    } else {
        format!("{:.3e}", r.delta)
    };
    writeln!(
        out,
        "{} position: k = {:.6}, δ = c/ω = {delta}",
        r.position, r.k
    )?;
    writeln!(
        out,
        "{:<17} {:>10} {:>10} {:>11} {:>11} {:>10}",
        "criterion", "lower m", "upper m", "Δlower", "Δupper", "cost/eval"
    )?;
    let mut notes = Vec::new();
    for c in &r.criteria {
        writeln!(
            out,
            "{:<17} {:>10} {:>10} {:>11} {:>11} {:>10}",
            c.name,
            fmt_opt(c.lower_m, 6),
            fmt_opt(c.upper_m, 6),
            fmt_diff(c.lower_diff_from_floquet),
            fmt_diff(c.upper_diff_from_floquet),
            fmt_seconds(c.seconds_per_eval)
        )?;
        for (end, why) in [("lower", c.lower_reason), ("upper", c.upper_reason)] {
            if let Some(why) = why {
                notes.push(format!("  {} {end}: {why}", c.name));
            }
        }
        for why in &c.notes {
            let prefix = format!("{}: ", c.name);
            notes.push(format!(
                "  {}: {}",
                c.name,
                why.strip_prefix(prefix.as_str()).unwrap_or(why)
            ));
        }
        if let (Some(p), Some(lo)) = (&r.physical, c.lower_m) {
            let up = c.upper_m.map_or("—".into(), |u| {
                format!("{:.3} mm", u * p.equivalent_length * 1e3)
            });
            notes.push(format!(
                "  {} as amplitude A: {:.3} mm … {up}",
                c.name,
                lo * p.equivalent_length * 1e3
            ));
        }
    }
    if let Some(t) = r.criteria.iter().find_map(|c| c.upper_m_truncated) {
        notes.push(format!(
            "  harmonic_balance upper, truncated formula: {t:.6}"
        ));
    }
    writeln!(out, "(Δ: criterion minus Floquet)")?;
    for n in &notes {
        writeln!(out, "{n}")?;
    }
    writeln!(out, "order-n subharmonic thresholds in m (undamped):")?;
    writeln!(
        out,
        "{:>5} {:>17} {:>10} {:>11}",
        "n", "harmonic balance", "Floquet", "Δ"
    )?;
    for s in &r.subharmonics {
        let d = s.m.zip(s.m_floquet).map(|(a, b)| a - b);
        let why = s
            .reason_floquet
            .or(s.reason)
            .map_or(String::new(), |w| format!("  ({w})"));
        writeln!(
            out,
            "{:>5} {:>17} {:>10} {:>11}{why}",
            s.order,
            fmt_opt(s.m, 6),
            fmt_opt(s.m_floquet, 6),
            fmt_diff(d)
        )?;
    }
    Ok(())
}
