//! Measured cost of one evaluation of a function: the median over several batches, each long
//! enough to dwarf the clock's resolution.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// Seconds per call of `f`, the median of five batches of at least `batch` each.
pub fn seconds_per_eval<T>(batch: Duration, mut f: impl FnMut() -> T) -> f64 {
    // Find how many calls fill one batch.
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
    let mut samples: Vec<f64> = (0..5)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..n {
                black_box(f());
            }
            t.elapsed().as_secs_f64() / n as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[2]
}
