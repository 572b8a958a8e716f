//! The run one drive period at a time: the mean, range and mean rate of θ over each period, in a
//! bounded number of buckets however long the run.

/// One or more whole drive periods: θ in rad (unwrapped), rates in rad/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bucket {
    /// Start and end (s).
    pub t0: f64,
    pub t1: f64,
    /// Mean θ over the periods (the slow motion).
    pub mean: f64,
    /// Mean θ' over the periods.
    pub rate: f64,
    pub min: f64,
    pub max: f64,
    /// Drive periods in the bucket.
    pub periods: u64,
}

impl Bucket {
    /// The two buckets as one (`later` follows `self`).
    fn join(self, later: Bucket) -> Bucket {
        let n = (self.periods + later.periods) as f64;
        let w = |a: f64, b: f64| (a * self.periods as f64 + b * later.periods as f64) / n;
        Bucket {
            t0: self.t0,
            t1: later.t1,
            mean: w(self.mean, later.mean),
            rate: w(self.rate, later.rate),
            min: self.min.min(later.min),
            max: self.max.max(later.max),
            periods: self.periods + later.periods,
        }
    }

    /// The time in the middle of the bucket.
    pub fn t_mid(&self) -> f64 {
        0.5 * (self.t0 + self.t1)
    }
}

/// Buckets of equal width (in periods), at most `cap` of them. A growing series joins
/// neighbours in pairs (doubling the width) when full, so it always spans the whole run; a
/// fixed one keeps one period a bucket and stops when full, holding the run's beginning exactly.
#[derive(Debug, Clone)]
pub struct Periods {
    cap: usize,
    grows: bool,
    width: u64,
    buckets: Vec<Bucket>,
    open: Option<Bucket>,
}

impl Periods {
    /// Spans the whole run in at most `cap` buckets (`cap` ≥ 2).
    pub fn growing(cap: usize) -> Self {
        Self::new(cap.max(2), true)
    }

    /// The first `cap` periods, one a bucket.
    pub fn first(cap: usize) -> Self {
        Self::new(cap, false)
    }

    fn new(cap: usize, grows: bool) -> Self {
        Self {
            cap,
            grows,
            width: 1,
            buckets: Vec::with_capacity(cap),
            open: None,
        }
    }

    /// Adds the next drive period.
    pub fn push(&mut self, period: Bucket) {
        if !self.grows && self.buckets.len() == self.cap {
            return;
        }
        let b = match self.open.take() {
            Some(open) => open.join(period),
            None => period,
        };
        if b.periods < self.width {
            self.open = Some(b);
            return;
        }
        self.buckets.push(b);
        if self.grows && self.buckets.len() == self.cap {
            self.buckets = self
                .buckets
                .chunks(2)
                .map(|p| if p.len() == 2 { p[0].join(p[1]) } else { p[0] })
                .collect();
            self.width *= 2;
            // An odd count leaves a half-full bucket: it goes on filling.
            if self.buckets.last().is_some_and(|b| b.periods < self.width) {
                self.open = self.buckets.pop();
            }
        }
    }

    /// The complete buckets, oldest first.
    pub fn buckets(&self) -> &[Bucket] {
        &self.buckets
    }

    /// Whether no period was dropped: a fixed series that is not full.
    pub fn is_complete(&self) -> bool {
        self.grows || self.buckets.len() < self.cap
    }
}

/// Sums one drive period's samples into a [`Bucket`].
#[derive(Debug, Clone, Default)]
pub struct PeriodSum {
    n: u32,
    t0: f64,
    sum: f64,
    sum_rate: f64,
    min: f64,
    max: f64,
}

impl PeriodSum {
    /// Adds a sample; after `per_period` of them returns the period, ending `dt` after the last.
    pub fn add(
        &mut self,
        per_period: u32,
        dt: f64,
        t: f64,
        theta: f64,
        rate: f64,
    ) -> Option<Bucket> {
        if self.n == 0 {
            *self = Self {
                n: 0,
                t0: t,
                sum: 0.0,
                sum_rate: 0.0,
                min: theta,
                max: theta,
            };
        }
        self.n += 1;
        self.sum += theta;
        self.sum_rate += rate;
        self.min = self.min.min(theta);
        self.max = self.max.max(theta);
        if self.n < per_period {
            return None;
        }
        let n = f64::from(self.n);
        self.n = 0;
        Some(Bucket {
            t0: self.t0,
            t1: t + dt,
            mean: self.sum / n,
            rate: self.sum_rate / n,
            min: self.min,
            max: self.max,
            periods: 1,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn period(k: u64, mean: f64) -> Bucket {
        Bucket {
            t0: k as f64,
            t1: (k + 1) as f64,
            mean,
            rate: 2.0 * mean,
            min: mean - 1.0,
            max: mean + 1.0,
            periods: 1,
        }
    }

    #[test]
    fn a_growing_series_stays_bounded_and_spans_a_million_periods() {
        let mut s = Periods::growing(1000);
        for k in 0..1_000_000 {
            s.push(period(k, k as f64));
        }
        let b = s.buckets();
        assert!(b.len() <= 1000 && b.len() >= 500, "{}", b.len());
        // Contiguous from t = 0, each bucket's mean the mean of its periods' means (k's are
        // consecutive integers, so the mean is the middle one: exact in f64).
        assert_eq!(b[0].t0, 0.0);
        for w in b.windows(2) {
            assert_eq!(w[0].t1, w[1].t0);
        }
        for x in b {
            let (first, last) = (x.t0, x.t1 - 1.0);
            assert_eq!(x.mean, 0.5 * (first + last));
            assert_eq!(x.min, first - 1.0);
            assert_eq!(x.max, last + 1.0);
            assert_eq!(x.periods as f64, x.t1 - x.t0);
        }
        // All but the periods still filling the open bucket are in.
        let covered: u64 = b.iter().map(|x| x.periods).sum();
        assert!(covered > 1_000_000 - b[0].periods && covered <= 1_000_000);
    }

    #[test]
    fn a_fixed_series_keeps_the_first_periods_exactly() {
        let mut s = Periods::first(100);
        for k in 0..1000 {
            s.push(period(k, k as f64));
        }
        assert_eq!(s.buckets().len(), 100);
        assert!(!s.is_complete());
        assert_eq!(s.buckets()[99], period(99, 99.0));
    }

    #[test]
    fn a_period_sum_is_the_mean_of_its_samples() {
        // θ = 0.3 + 0.05 cos(2π j/8) over one period of 8 samples: the mean is 0.3 (the cosine's
        // equally spaced samples sum to zero), the range 0.25..0.35.
        let mut p = PeriodSum::default();
        let mut out = None;
        for j in 0..8 {
            let ph = std::f64::consts::TAU * f64::from(j) / 8.0;
            out = p.add(8, 0.125, f64::from(j) * 0.125, 0.3 + 0.05 * ph.cos(), 1.0);
        }
        let b = out.expect("a whole period");
        assert!((b.mean - 0.3).abs() < 1e-15);
        assert!((b.min - 0.25).abs() < 1e-15 && (b.max - 0.35).abs() < 1e-15);
        assert_eq!((b.t0, b.t1, b.rate), (0.0, 1.0, 1.0));
    }
}
