//! The stability map of the linearised equation over a grid of (k, m), every cell from Hill's
//! Sturm counts (damped: through the exact mapping of `kapitza_core::stability::hill`), cells
//! computed in parallel.

use anyhow::Result;
use rayon::prelude::*;

use kapitza_core::math;
use kapitza_core::stability::hill;

/// N samples from `from` to `to`, both ends included.
pub fn samples(from: f64, to: f64, n: usize) -> Vec<f64> {
    if n < 2 {
        return vec![from];
    }
    (0..n)
        .map(|i| from + (to - from) * i as f64 / (n - 1) as f64)
        .collect()
}

/// How damping enters: none, or a quality factor Q (δ = √|k|/Q, physics §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Damping {
    None,
    Quality(f64),
}

impl Damping {
    /// δ = c/ω at signed k.
    pub fn delta(self, k: f64) -> f64 {
        match self {
            Damping::None => 0.0,
            Damping::Quality(q) => k.abs().sqrt() / q,
        }
    }
}

/// `stable[i][j]`: whether (ks[i], ms[j]) is stable.
pub struct StabilityMap {
    pub ks: Vec<f64>,
    pub ms: Vec<f64>,
    pub stable: Vec<Vec<bool>>,
    /// Half-period integrations of tr M the damped cells needed (0 undamped).
    pub traces: u64,
}

/// Computes the map; damped cells integrate tr M_u with `hill::DEFAULT_HALF_STEPS` steps, the
/// cosines tabulated once.
pub fn stability_map(ks: &[f64], ms: &[f64], damping: Damping) -> Result<StabilityMap> {
    let n = hill::DEFAULT_HALF_STEPS;
    let h = math::PI / f64::from(n);
    let table: Vec<f64> = (0..=2 * n)
        .map(|j| math::cos(0.5 * h * f64::from(j)))
        .collect();
    let columns: Vec<(Vec<bool>, u64)> = ks
        .par_iter()
        .map(|&k| {
            let delta = damping.delta(k);
            let (kp, bound) = hill::damped::shift(k, delta);
            let mut traces = 0;
            let col = ms
                .iter()
                .map(|&m| {
                    if hill::stability_count(4.0 * kp, 2.0 * m) % 2 == 1 {
                        return true;
                    }
                    if delta == 0.0 {
                        return false;
                    }
                    traces += 1;
                    hill::trace_u_with(kp, m, n, |j| table[j as usize]).abs() < bound
                })
                .collect();
            (col, traces)
        })
        .collect();
    let traces = columns.iter().map(|c| c.1).sum();
    Ok(StabilityMap {
        ks: ks.to_vec(),
        ms: ms.to_vec(),
        stable: columns.into_iter().map(|c| c.0).collect(),
        traces,
    })
}
