//! How much of the run's beginning the transient panel shows: enough to see the motion settle,
//! not so much that the settling is squeezed into the first tenth of the axis.

use crate::record::Bucket;

/// Periods the transient panel always shows (unless the run is shorter).
const MIN_PERIODS: usize = 20;

/// Longest repeat (in drive periods) looked for in the settled motion.
const MAX_REPEAT: usize = 8;

/// The number of leading periods to draw, from one bucket a period (oldest first): twice the
/// time the motion takes to settle, or the whole run when it never settles (chaos) or settles
/// in its second half.
///
/// The run's last tenth sets what settled looks like: its repeat q (1 at rest, 2 for flutter,
/// n for an order-n subharmonic; 1 when nothing repeats) and, for each period of the repeat,
/// the spread of its mean rate, its range (max − min) and, unless it rotates, its mean angle.
/// Settled means every later period stays within that spread (at least 1°, 2° and 1° per
/// period) of the tail's periods at the same place in the repeat.
pub fn shown_periods(periods: &[Bucket]) -> usize {
    let n = periods.len();
    if n <= MIN_PERIODS {
        return n;
    }
    let tail_len = (n / 10).max(2 * MAX_REPEAT);
    let tail_from = n.saturating_sub(tail_len);
    let tail = &periods[tail_from..];
    let period = (tail[0].t1 - tail[0].t0).max(f64::MIN_POSITIVE);
    let rate = |b: &Bucket| b.rate.to_degrees() * period;
    let rotates = tail.iter().all(|b| rate(b).abs() > 90.0);
    // (value, floor) of each feature of a period, in degrees.
    let features = |b: &Bucket| -> [(f64, f64); 3] {
        let mean = if rotates { 0.0 } else { b.mean.to_degrees() };
        [
            (rate(b), 1.0),
            ((b.max - b.min).to_degrees(), 2.0),
            (mean, 1.0),
        ]
    };
    let repeat = (1..=MAX_REPEAT)
        .find(|&q| {
            tail.windows(q + 1).all(|w| {
                let (a, b) = (features(&w[0]), features(&w[q]));
                a.iter()
                    .zip(&b)
                    .all(|(x, y)| (x.0 - y.0).abs() <= 0.5 * x.1)
            })
        })
        .unwrap_or(1);
    // Per place in the repeat and feature: the band the tail spans, widened by its spread.
    let mut bands = vec![[(f64::INFINITY, f64::NEG_INFINITY); 3]; repeat];
    for (i, b) in tail.iter().enumerate() {
        let band = &mut bands[(tail_from + i) % repeat];
        for (slot, (x, _)) in band.iter_mut().zip(features(b)) {
            *slot = (slot.0.min(x), slot.1.max(x));
        }
    }
    let settled = |k: usize, b: &Bucket| {
        bands[k % repeat]
            .iter()
            .zip(features(b))
            .all(|(&(lo, hi), (x, floor))| {
                let slack = (hi - lo).max(floor);
                x >= lo - slack && x <= hi + slack
            })
    };
    let settle = (0..n)
        .rev()
        .find(|&k| !settled(k, &periods[k]))
        .map_or(0, |k| k + 1);
    let shown = (2 * settle).max(MIN_PERIODS);
    if settle == 0 || shown * 2 > n {
        n
    } else {
        shown
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A period k of a motion whose mean decays from 10° off `rest` (degrees) with time
    /// constant `tau` periods, a ±`wiggle`° range.
    fn decaying(k: usize, rest: f64, tau: f64, wiggle: f64) -> Bucket {
        let mean = (rest + 10.0 * (-(k as f64) / tau).exp()).to_radians();
        let w = wiggle.to_radians();
        Bucket {
            t0: k as f64,
            t1: k as f64 + 1.0,
            mean,
            rate: 0.0,
            min: mean - w,
            max: mean + w,
            periods: 1,
        }
    }

    #[test]
    fn a_decay_is_shown_until_it_settles() {
        // 10° e^(−k/100) falls below the 1° floor at k = 100 ln 10 ≈ 230: about 460 shown of 6000.
        let run: Vec<Bucket> = (0..6000).map(|k| decaying(k, 180.0, 100.0, 3.0)).collect();
        let shown = shown_periods(&run);
        assert!((400..=520).contains(&shown), "{shown}");
    }

    #[test]
    fn a_motion_that_never_settles_is_shown_whole() {
        // A mean that wanders over the whole run (no quieter last tenth): all of it.
        let run: Vec<Bucket> = (0..3000)
            .map(|k| decaying(k, 180.0 + 50.0 * (k as f64 * 0.37).sin(), 1.0, 3.0))
            .collect();
        assert_eq!(shown_periods(&run), 3000);
    }

    #[test]
    fn a_late_settling_run_is_shown_whole() {
        let run: Vec<Bucket> = (0..1000).map(|k| decaying(k, 0.0, 300.0, 1.0)).collect();
        assert_eq!(shown_periods(&run), 1000);
    }

    #[test]
    fn a_subharmonic_settles_when_its_nodding_does() {
        // Period means repeating every 4 periods (±4°), their swing decaying from ±9° with
        // 100 periods' time constant: above the 1° floor until k = 100 ln 5 ≈ 161.
        let run: Vec<Bucket> = (0..4000)
            .map(|k| {
                let swing = 4.0 + 5.0 * (-(k as f64) / 100.0).exp();
                let nod = [1.0, 0.3, -1.0, -0.3][k % 4];
                let mut b = decaying(k, 180.0, 1.0, 3.0);
                b.mean = (180.0 + swing * nod).to_radians();
                b.min = b.mean - 0.05;
                b.max = b.mean + 0.05;
                b
            })
            .collect();
        let shown = shown_periods(&run);
        assert!((300..=340).contains(&shown), "{shown}");
    }

    #[test]
    fn a_steady_rotation_settles_on_its_rate() {
        // One turn a period after 50 periods of speeding up; the mean angle grows without end.
        let run: Vec<Bucket> = (0..2000)
            .map(|k| {
                let turns = if k < 50 { k as f64 / 50.0 } else { 1.0 };
                let rate = turns * std::f64::consts::TAU;
                Bucket {
                    t0: k as f64,
                    t1: k as f64 + 1.0,
                    mean: rate * k as f64,
                    rate,
                    min: rate * k as f64 - 3.0,
                    max: rate * k as f64 + 3.0,
                    periods: 1,
                }
            })
            .collect();
        let shown = shown_periods(&run);
        assert!((90..=110).contains(&shown), "{shown}");
    }
}
