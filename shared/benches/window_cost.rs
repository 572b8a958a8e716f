//! Cost of one stability window from Hill's method, as `kapitza boundary` computes it (m up to
//! 10, tolerance 1e-7): undamped below the first tongue (k < 1/4) and above it (k ≥ 1/4, tongue
//! tips included), and damped (Q = 10 and Q = 2, δ = √|k|/Q). For each k the mean over a
//! batch of at least 20 ms, in wall time and in the thread's CPU time (the steadier figure on a
//! shared machine); per group the median and the largest over k, and the work: LDLᵀ passes
//! (undamped) or half-period integrations of tr M_u (damped).
//!
//! Run: `cargo bench -p kapitza-core --bench window_cost`. Figures: docs/stability.md.

mod support;

use kapitza_core::stability::hill;
use std::hint::black_box;
use std::time::Instant;
use support::thread_cpu_seconds;

/// Mean (wall, CPU) seconds per call of `f` over a batch of at least 20 ms of CPU time.
fn per_call<T>(mut f: impl FnMut() -> T) -> (f64, f64) {
    let mut n: u32 = 1;
    loop {
        let (t, c) = (Instant::now(), thread_cpu_seconds());
        for _ in 0..n {
            black_box(f());
        }
        let (wall, cpu) = (t.elapsed().as_secs_f64(), thread_cpu_seconds() - c);
        if cpu >= 0.02 || n >= 1 << 24 {
            return (wall / f64::from(n), cpu / f64::from(n));
        }
        n *= 2;
    }
}

/// Median and largest of the per-k figures.
fn summary(mut xs: Vec<f64>) -> (f64, f64) {
    xs.sort_by(f64::total_cmp);
    (xs[xs.len() / 2], xs[xs.len() - 1])
}

/// `window(k)` computes one window and returns its work in `unit`.
fn report(name: &str, unit: &str, ks: &[f64], mut window: impl FnMut(f64) -> u64) {
    let (mut walls, mut cpus, mut passes) = (Vec::new(), Vec::new(), Vec::new());
    let mut worst = (0.0, f64::NAN);
    for &k in ks {
        passes.push(window(k) as f64);
        let (w, c) = per_call(|| window(k));
        walls.push(w);
        cpus.push(c);
        if c > worst.0 {
            worst = (c, k);
        }
    }
    let (wm, wx) = summary(walls);
    let (cm, cx) = summary(cpus);
    let (pm, px) = summary(passes);
    println!(
        "{name:>34}: CPU median {:6.2} µs, max {:7.2} µs (k = {:.4}); wall median {:6.2} µs, \
         max {:7.2} µs; {unit} median {pm:.0}, max {px:.0} ({} values of k)",
        cm * 1e6,
        cx * 1e6,
        worst.1,
        wm * 1e6,
        wx * 1e6,
        ks.len()
    );
}

fn main() {
    const M_MAX: f64 = 10.0;
    const TOL: f64 = 1e-7;
    let below: Vec<f64> = (0..=80)
        .map(|i| -5.0 + 5.24 * f64::from(i) / 80.0)
        .collect();
    let above: Vec<f64> = (0..=160)
        .map(|i| 0.26 + 24.74 * f64::from(i) / 160.0)
        .collect();
    let tips: Vec<f64> = (1..=10).map(|j| f64::from(j * j) / 4.0).collect();
    let undamped = |k: f64| hill::first_window(k, M_MAX, TOL).expect("window").2;
    println!("one window per call, m ≤ {M_MAX}, tolerance {TOL:e}");
    report("undamped, k ∈ [−5, 0.24]", "passes", &below, undamped);
    report("undamped, k ∈ [0.26, 25]", "passes", &above, undamped);
    report("undamped, tongue tips k = j²/4", "passes", &tips, undamped);
    for q in [10.0, 2.0] {
        let damped = |k: f64| {
            let delta = k.abs().sqrt() / q;
            let d = hill::damped_window(k, delta, TOL, hill::DEFAULT_HALF_STEPS).expect("window");
            d.traces
        };
        let ks_below: Vec<f64> = below.iter().step_by(8).copied().collect();
        let ks_above: Vec<f64> = above.iter().step_by(16).copied().collect();
        report(
            &format!("damped Q = {q}, k ∈ [−5, 0.24]"),
            "tr M_u",
            &ks_below,
            damped,
        );
        report(
            &format!("damped Q = {q}, k ∈ [0.26, 25]"),
            "tr M_u",
            &ks_above,
            damped,
        );
    }
}
