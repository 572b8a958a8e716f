//! The results as CSV files (raw numbers, shortest round-trip form, empty for "none") and as a
//! Markdown report (rounded for reading).

use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;

use super::measure::{Point, SettingName};
use super::physical::Choice;
use super::ratio::{curve_label, curves, AtTarget, PeerRatio};
use super::Results;
use crate::csv_out::{num, opt, quote};
use kapitza_core::stability::Criterion;

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}

/// Writes the CSV files into `dir`; returns their names.
pub fn csv(r: &Results, dir: &Path) -> Result<Vec<String>> {
    let mut files = Vec::new();
    let mut put = |name: &str, text: String| -> Result<()> {
        write(&dir.join(name), &text)?;
        files.push(name.to_string());
        Ok(())
    };

    let mut t = String::from(
        "scene,family,who,fidelity,format,setting_name,setting,error,wall_s,cpu_s,rhs_evals,steps,rejected\n",
    );
    for p in &r.measurements {
        let _ = writeln!(
            t,
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            p.scene,
            p.family.name(),
            p.who,
            p.fidelity,
            p.format,
            p.setting_name,
            num(p.setting),
            num(p.error),
            num(p.wall_s),
            num(p.cpu_s),
            p.rhs_evals,
            p.steps,
            p.rejected
        );
    }
    put("measurements.csv", t)?;

    let mut t = String::from(
        "scene,target_error,time_ratio,evals_ratio,cpu_ratio,ours_time_method,ours_time_s,peer_time_method,peer_time_s,ours_evals_method,ours_evals,peer_evals_method,peer_evals,averaged_time_s\n",
    );
    let m = |a: &Option<AtTarget>| {
        a.as_ref().map_or((String::new(), String::new()), |a| {
            (quote(&a.method), num(a.cost))
        })
    };
    for p in &r.peer_ratios {
        let (ot, otc) = m(&p.ours_time);
        let (pt, ptc) = m(&p.peer_time);
        let (oe, oec) = m(&p.ours_evals);
        let (pe, pec) = m(&p.peer_evals);
        let _ = writeln!(
            t,
            "{},{},{},{},{},{ot},{otc},{pt},{ptc},{oe},{oec},{pe},{pec},{}",
            p.scene,
            num(p.target_error),
            opt(p.time_ratio),
            opt(p.evals_ratio),
            opt(p.cpu_ratio),
            opt(p.averaged_time.as_ref().map(|a| a.cost))
        );
    }
    put("peer_ratios.csv", t)?;

    let mut t = String::from(
        "k,position,criterion,lower,upper,floquet_lower,floquet_upper,lower_error,upper_error,error,missing_end,seconds_per_eval\n",
    );
    for c in &r.stability_criteria {
        let _ = writeln!(
            t,
            "{},{},{},{},{},{},{},{},{},{},{},{}",
            num(c.k),
            c.position,
            c.criterion,
            opt(c.lower),
            opt(c.upper),
            opt(c.floquet_lower),
            opt(c.floquet_upper),
            opt(c.lower_error),
            opt(c.upper_error),
            opt(c.error),
            c.missing_end,
            num(c.seconds_per_eval)
        );
    }
    put("stability_criteria.csv", t)?;

    let mut t = String::from(
        "k,steps_per_period,reference_steps,lower,upper,error,seconds_per_eval,monodromies,rhs_evals\n",
    );
    for f in &r.floquet_convergence {
        let _ = writeln!(
            t,
            "{},{},{},{},{},{},{},{},{}",
            num(f.k),
            f.steps_per_period,
            f.reference_steps,
            opt(f.lower),
            opt(f.upper),
            opt(f.error),
            num(f.seconds_per_eval),
            f.monodromies,
            f.rhs_evals
        );
    }
    put("floquet_convergence.csv", t)?;

    let mut t = String::from(
        "scene,reference,method,fidelity,setting_name,setting,answer,right,wall_s,rhs_evals\n",
    );
    for p in &r.physical {
        let reference = quote(&p.reference.to_string());
        for (c, right) in p
            .ladders
            .iter()
            .map(|c| (c, true))
            .chain(p.never_right.iter().map(|c| (c, false)))
        {
            let _ = writeln!(
                t,
                "{},{reference},{},{},{},{},{},{right},{},{}",
                p.scene,
                quote(&c.method),
                c.fidelity,
                c.setting_name,
                num(c.setting),
                quote(&c.answer.to_string()),
                num(c.wall_s),
                c.rhs_evals
            );
        }
        let a = &p.auto;
        let _ = writeln!(
            t,
            "{},{reference},auto (DOP853 f64),{},rtol,1e-9,{},{},{},{}",
            p.scene,
            a.fidelity,
            quote(&a.answer.to_string()),
            a.right,
            num(a.wall_s),
            a.rhs_evals
        );
    }
    put("physical.csv", t)?;

    let mut t = String::from(
        "case,r,drive_angle_deg,ratio,a_over_l,full,averaged,difference_deg,right,auto_takes_averaged\n",
    );
    for c in &r.averaged_validity {
        let _ = writeln!(
            t,
            "{},{},{},{},{},{},{},{},{},{}",
            quote(&c.case),
            num(c.r),
            num(c.drive_angle_deg),
            num(c.ratio),
            num(c.a_over_l),
            quote(&c.full.to_string()),
            quote(&c.averaged.to_string()),
            opt(c.difference_deg),
            c.right,
            c.auto_takes_averaged
        );
    }
    put("averaged_validity.csv", t)?;
    Ok(files)
}

/// 1.2e-6 style.
pub fn sci(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.is_finite() {
        format!("{x:.1e}")
    } else {
        "—".into()
    }
}

/// Seconds for people.
pub fn secs(s: f64) -> String {
    match s {
        s if !s.is_finite() => "—".into(),
        s if s < 1e-6 => format!("{:.0} ns", s * 1e9),
        s if s < 1e-3 => format!("{:.1} µs", s * 1e6),
        s if s < 1.0 => format!("{:.2} ms", s * 1e3),
        s => format!("{s:.2} s"),
    }
}

fn setting(p: &Point) -> String {
    if p.setting_name == SettingName::Rtol {
        format!("tol {}", sci(p.setting))
    } else {
        format!("{} steps/T", p.setting)
    }
}

fn at(a: &Option<AtTarget>, time: bool) -> String {
    a.as_ref().map_or("not reached".into(), |a| {
        let cost = if time {
            secs(a.cost)
        } else {
            format!("{:.3e}", a.cost)
        };
        let mark = if a.interpolated { "" } else { " *" };
        format!("{} ({cost}{mark})", a.method)
    })
}

fn ratio(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("**{v:.2}**"))
}

fn choice(c: &Choice) -> String {
    let s = if c.setting_name == SettingName::Rtol {
        format!("tol {}", sci(c.setting))
    } else {
        format!("{} steps/T", c.setting)
    };
    format!("{} at {s}", c.method)
}

/// A peer-ratio table (also printed by the command).
pub fn peer_table(rows: &[PeerRatio]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| scene | target error | time ratio | evaluations ratio | CPU-time ratio | our best by time | peer's best by time | our best by evaluations | peer's best by evaluations | averaged model (beside, by time) |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for p in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            p.scene,
            sci(p.target_error),
            ratio(p.time_ratio),
            ratio(p.evals_ratio),
            ratio(p.cpu_ratio),
            at(&p.ours_time, true),
            at(&p.peer_time, true),
            at(&p.ours_evals, false),
            at(&p.peer_evals, false),
            p.averaged_time
                .as_ref()
                .map_or("not reached".into(), |a| secs(a.cost))
        );
    }
    s
}

/// The real-time factors (also printed by the command).
pub fn realtime_table(r: &Results) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| model | method | controller | rtol = atol | final error | CPU per 60 s run | real-time factor |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for f in &r.real_time_factors {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} |",
            f.model,
            f.method,
            f.controller,
            sci(f.setting),
            sci(f.error),
            secs(f.cpu_s),
            sci(f.factor)
        );
    }
    s
}

/// The physical-question table alone (also printed by the command).
pub fn physical_table(r: &Results) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| scene | reference answer | cheapest right answer | its time | `auto` + default method | `auto` right? | `auto` time |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for p in &r.physical {
        let (c, t) = p
            .cheapest
            .as_ref()
            .map_or(("none".into(), "—".into()), |c| {
                (choice(c), secs(c.wall_s))
            });
        let _ = writeln!(
            s,
            "| {} | {} | {c} | {t} | {} model, DOP853 tol 1e-9 f64 | {} | {} |",
            p.scene,
            p.reference,
            p.auto.fidelity,
            if p.auto.right { "yes" } else { "**no**" },
            secs(p.auto.wall_s)
        );
    }
    s
}

/// The Markdown report of a run.
pub fn markdown(r: &Results, command: &str) -> String {
    let mut s = String::new();
    let kind = if r.quick { "quick" } else { "full" };
    let _ = writeln!(s, "# Work-precision measurements ({kind} run)\n");
    let _ = writeln!(s, "Regenerate: `{command}`.\n");
    let load = |l: Option<f64>| l.map_or("unknown".into(), |l| format!("{l:.2}"));
    let _ = writeln!(
        s,
        "Machine: {} ({} cores); 1-minute load {} at the start, {} at the end; the run took {:.0} s. \
         Times are medians of five batches; ratios to the peer come from this same process.\n",
        r.machine.cpu,
        r.machine.cores,
        load(r.machine.load_start),
        load(r.machine.load_end),
        r.wall_s
    );

    let _ = writeln!(s, "## Scenes and references\n");
    let _ = writeln!(
        s,
        "Reference: DOP853 at rtol = atol = 1e-13 (f64); its check is the same run at 1e-12, and \
         their difference (error measure) is listed.\n"
    );
    let _ = writeln!(
        s,
        "| scene | from | what | horizon | drive periods | ω/ω0 | reference check |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for c in &r.scenes {
        let _ = writeln!(
            s,
            "| {} | `{}` `{}` | {} | {:.2} s | {:.0} | {:.1} | {} |",
            c.name,
            c.file,
            c.sets.join(" "),
            c.what,
            c.horizon_s,
            c.periods,
            c.omega / c.omega0,
            sci(c.reference.check_difference)
        );
    }
    for c in &r.scenes {
        if let (Some(l), Some(tp)) = (c.lyapunov, c.predictability_s) {
            let _ = writeln!(
                s,
                "\n{}: finite-time Lyapunov exponent λ = {l:.2}/s (the shipped scene, classified), so a \
                 rounding-size error (2.2e-16) grows to order one in ln(1/2.2e-16)/λ ≈ {tp:.1} s; the \
                 horizon, {:.1} s, keeps the 1e-12 and 1e-13 references within {}.",
                c.name,
                c.horizon_s,
                sci(c.reference.check_difference)
            );
        }
    }

    let _ = writeln!(s, "\n## Ours against the peer at matched error\n");
    let _ = writeln!(
        s,
        "Ratio = our best full-model method's cost over the peer's best (ode_solvers Dopri5 or \
         Dop853), each read off its work-precision curve at the target error (log-log \
         interpolation between the two points around it; * = the loosest setting already met the \
         target, so its cost is an upper bound). Goal: ≤ 0.5.\n"
    );
    s.push_str(&peer_table(&r.peer_ratios));
    let _ = writeln!(
        s,
        "\nAgainst the peer as published (its Dop853 stops on our time-dependent equation, so its \
         best is Dopri5):\n"
    );
    s.push_str(&peer_table(&r.peer_as_published_ratios));
    let _ = writeln!(
        s,
        "\n## Real-time factors\n\n60 s of the `realtime` benchmark's scene (tilted 135°, Q = 50), \
         each method at the loosest tolerance that reaches a final error of 1e-6 (the averaged model \
         against its own converged answer); CPU time of one run.\n"
    );
    s.push_str(&realtime_table(r));
    let _ = writeln!(
        s,
        "\nOne evaluation of the right-hand side alone costs {} of CPU time (the sin/cos of θ and cos ωt).",
        r.scenes
            .iter()
            .map(|c| format!("{} on {}", secs(c.rhs_seconds), c.name))
            .collect::<Vec<_>>()
            .join(", ")
    );

    let _ = writeln!(s, "\n## Work-precision points\n");
    for c in &r.scenes {
        let _ = writeln!(s, "### {}\n", c.name);
        let _ = writeln!(
            s,
            "| method | setting | error | evaluations | steps | rejected | time | CPU time |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
        for ((family, format), mut pts) in curves(&r.measurements, c.name) {
            pts.sort_by_key(|p| p.rhs_evals);
            for p in pts {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} | {} |",
                    curve_label(family, format),
                    setting(p),
                    sci(p.error),
                    p.rhs_evals,
                    p.steps,
                    p.rejected,
                    secs(p.wall_s),
                    secs(p.cpu_s)
                );
            }
        }
        let _ = writeln!(s);
    }

    let _ = writeln!(s, "## Stability criteria against Floquet\n");
    let _ = writeln!(
        s,
        "Undamped windows in m; error = the larger |end − Floquet end| over the ends both give \
         (Floquet at 1000 RK4 steps per period, bisected to 1e-11); cost = one evaluation of the \
         window.\n"
    );
    let _ = writeln!(
        s,
        "| k | Floquet window | averaging | Mathieu series | harmonic balance | cost: averaging / Mathieu / harmonic balance / Floquet |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    let mut ks: Vec<f64> = r.stability_criteria.iter().map(|c| c.k).collect();
    ks.dedup();
    for k in ks {
        let rows: Vec<_> = r.stability_criteria.iter().filter(|c| c.k == k).collect();
        let get = |name: Criterion| rows.iter().find(|c| c.criterion == name);
        let err = |name: Criterion| {
            get(name).map_or("—".into(), |c| {
                let e = c.error.map_or("none".into(), sci);
                if c.missing_end {
                    format!("{e} (no upper end)")
                } else {
                    e
                }
            })
        };
        let cost = |name: Criterion| get(name).map_or("—".into(), |c| secs(c.seconds_per_eval));
        let window = get(Criterion::Floquet).map_or("—".into(), |c| {
            format!(
                "{} … {}",
                c.lower.map_or("—".into(), |v| format!("{v:.6}")),
                c.upper.map_or("—".into(), |v| format!("{v:.6}"))
            )
        });
        let _ = writeln!(
            s,
            "| {k} | {window} | {} | {} | {} | {} / {} / {} / {} |",
            err(Criterion::Averaging),
            err(Criterion::Mathieu),
            err(Criterion::HarmonicBalance),
            cost(Criterion::Averaging),
            cost(Criterion::Mathieu),
            cost(Criterion::HarmonicBalance),
            cost(Criterion::Floquet)
        );
    }

    let _ = writeln!(s, "\n### Floquet's own error against its cost\n");
    let _ = writeln!(
        s,
        "| k | RK4 steps per period | error (vs the reference step count) | monodromy matrices | evaluations | cost per window |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for f in &r.floquet_convergence {
        let _ = writeln!(
            s,
            "| {} | {} | {} (vs {}) | {} | {} | {} |",
            f.k,
            f.steps_per_period,
            f.error.map_or("—".into(), sci),
            f.reference_steps,
            f.monodromies,
            f.rhs_evals,
            secs(f.seconds_per_eval)
        );
    }

    let _ = writeln!(
        s,
        "\n## The physical question: where accuracy stops mattering\n"
    );
    let _ = writeln!(
        s,
        "Right = the reference's outcome kind (scene as shipped, DOP853 at 1e-12) and its angle \
         within 0.1°; each ladder's cheapest setting that is right with its next finer setting \
         right too; time of the classified run (including the Lyapunov run when needed).\n"
    );
    s.push_str(&physical_table(r));
    let _ = writeln!(s, "\nEach ladder's cheapest right setting:\n");
    let _ = writeln!(s, "| scene | method | answer | time | evaluations |");
    let _ = writeln!(s, "|---|---|---|---|---|");
    for p in &r.physical {
        for c in &p.ladders {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} |",
                p.scene,
                choice(c),
                c.answer,
                secs(c.wall_s),
                c.rhs_evals
            );
        }
        for c in &p.never_right {
            let _ = writeln!(
                s,
                "| {} | {} never right; finest: {} | {} | — | — |",
                p.scene,
                c.method,
                choice(c),
                c.answer
            );
        }
    }
    let _ = writeln!(s, "\n`auto`'s reasons:\n");
    for p in &r.physical {
        let _ = writeln!(s, "* {}: {}", p.scene, p.auto.reason);
    }

    if !r.chaotic_fate.is_empty() {
        let _ = writeln!(
            s,
            "\nThe chaotic scene as shipped but over {} drive periods, DOP853 f64 at each tolerance:\n",
            super::physical::FATE_PERIODS
        );
        let _ = writeln!(s, "| tolerance | outcome |");
        let _ = writeln!(s, "|---|---|");
        for f in &r.chaotic_fate {
            let _ = writeln!(s, "| {} | {} |", sci(f.tolerance), f.outcome);
        }
    }

    let _ = writeln!(s, "\n## The averaged model's validity at fixed R\n");
    let _ = writeln!(
        s,
        "Each base scene at its R and θd, ω/ω0 varied (A/ℓ = √(2R)/(ω/ω0)); full and averaged \
         model by DOP853 at 1e-10, classified.\n"
    );
    let _ = writeln!(
        s,
        "| case | ω/ω0 | A/ℓ | full model | averaged model | averaged − full | right (0.1°) | `auto` takes averaged |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for c in &r.averaged_validity {
        let _ = writeln!(
            s,
            "| {} (R = {:.2}, θd = {}°) | {} | {:.3} | {} | {} | {} | {} | {} |",
            c.case,
            c.r,
            c.drive_angle_deg,
            c.ratio,
            c.a_over_l,
            c.full,
            c.averaged,
            c.difference_deg.map_or("—".into(), |d| format!("{d:+.3}°")),
            if c.right { "yes" } else { "no" },
            if c.auto_takes_averaged { "yes" } else { "no" }
        );
    }

    if !r.averaged_thresholds.is_empty() {
        let _ = writeln!(
            s,
            "\nFitted |averaged − full| ≈ C (A/ℓ)² (C the median of |Δ|/(A/ℓ)² over the sweep), and \
             where it reaches 0.1° (`auto` takes the averaged model for A/ℓ ≤ 0.1 and ω/ω0 ≥ 10):\n"
        );
        let _ = writeln!(s, "| case | C (degrees) | A/ℓ at 0.1° | ω/ω0 at 0.1° |");
        let _ = writeln!(s, "|---|---|---|---|");
        for t in &r.averaged_thresholds {
            let _ = writeln!(
                s,
                "| {} (R = {:.2}, θd = {}°) | {:.2} | {:.3} | {:.1} |",
                t.case, t.r, t.drive_angle_deg, t.c_deg, t.a_over_l_at_tol, t.ratio_at_tol
            );
        }
    }

    if !r.skipped.is_empty() || !r.notes.is_empty() {
        let _ = writeln!(s, "\n## Left out, failed, notes\n");
        for x in r.skipped.iter().chain(&r.notes) {
            let _ = writeln!(s, "* {x}");
        }
    }
    s
}
