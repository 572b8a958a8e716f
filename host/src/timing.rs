//! What a call costs in time: wall-clock time and this thread's CPU time, each the median of
//! five batches, each batch long enough to dwarf the clocks' resolution.
//!
//! Wall time is what a person waits for. On a machine shared with other work it also counts
//! the time the thread waits for a core, so the bench records the thread's CPU time beside it
//! (`CLOCK_THREAD_CPUTIME_ID`), which other processes do not inflate; where the two disagree
//! the machine was busy, and ratios of CPU times are the steadier ones.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// Median wall seconds per call of `f` over five batches of at least `batch` each.
pub fn seconds_per_eval<T>(batch: Duration, f: impl FnMut() -> T) -> f64 {
    cost(batch, f).wall_s
}

/// Seconds per call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cost {
    pub wall_s: f64,
    pub cpu_s: f64,
}

/// CPU time consumed by the calling thread (s); wall time where the platform has no such clock.
#[cfg(unix)]
pub fn thread_cpu() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec into the valid, exclusively borrowed `ts`.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc == 0 {
        ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
    } else {
        f64::NAN
    }
}

#[cfg(not(unix))]
pub fn thread_cpu() -> f64 {
    static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_secs_f64()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Seconds per call of `f`: medians of five batches of at least `batch` each.
pub fn cost<T>(batch: Duration, mut f: impl FnMut() -> T) -> Cost {
    let mut n: u64 = 1;
    loop {
        let t = Instant::now();
        for _ in 0..n {
            black_box(f());
        }
        if t.elapsed() >= batch || n >= 1 << 30 {
            break;
        }
        n *= 2;
    }
    let (mut wall, mut cpu) = (Vec::new(), Vec::new());
    for _ in 0..5 {
        let (t, c) = (Instant::now(), thread_cpu());
        for _ in 0..n {
            black_box(f());
        }
        cpu.push((thread_cpu() - c) / n as f64);
        wall.push(t.elapsed().as_secs_f64() / n as f64);
    }
    Cost {
        wall_s: median(wall),
        cpu_s: median(cpu),
    }
}
