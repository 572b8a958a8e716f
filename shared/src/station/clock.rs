//! The pendulum's sample clock on a timer tick that need not divide the sample rate.
//!
//! A rate `f` on a tick of `F` Hz has a period of `F / f` ticks, which is whole only when `f`
//! divides `F`: 12 kHz on embassy-time's 1 MHz tick is 83.33 ticks. Rounding it to 83 runs the
//! clock 0.4 % fast, and that error goes straight into ω. The clock below keeps the period as a
//! fraction instead: sample k is due at
//!
//! ```text
//! t_k = t_0 + floor(k · F / f)          (ticks)
//! ```
//!
//! so k samples always take k/f seconds to within one tick, and the error never grows (the
//! remainder `k · F mod f` is carried, not dropped). Late samples are skipped, never caught up
//! in a burst: the deadline after a late one is the first grid point still ahead, and the
//! deadlines passed on the way are counted (an overrun, [`super::Sample::late`]). A burst would
//! pair stale samples with fresh drive phases and starve the control tick behind them.

/// Deadlines of a sample clock: `f` samples per `F` ticks, on the grid `t_0 + floor(k·F/f)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleClock {
    /// The tick count of sample 0.
    origin: u64,
    /// The index of the sample whose deadline is `due`.
    k: u64,
    tick_hz: u64,
    sample_hz: u64,
    due: u64,
}

impl SampleClock {
    /// A clock whose sample 0 is due at tick `origin`; `sample_hz` is raised to 1.
    pub fn new(origin: u64, tick_hz: u64, sample_hz: u32) -> Self {
        SampleClock {
            origin,
            k: 0,
            tick_hz: tick_hz.max(1),
            sample_hz: u64::from(sample_hz.max(1)),
            due: origin,
        }
    }

    /// The tick at which the current sample is due.
    pub fn due(&self) -> u64 {
        self.due
    }

    /// Sample k's deadline: `origin + floor(k·F/f)`, as `(k div f)·F + floor((k mod f)·F/f)`
    /// so no product leaves 64 bits (the firmware has no 128-bit division to spare flash on).
    fn at(&self, k: u64) -> u64 {
        let (f, big_f) = (self.sample_hz, self.tick_hz);
        let whole = (k / f).saturating_mul(big_f);
        let part = (k % f).saturating_mul(big_f) / f;
        self.origin.saturating_add(whole).saturating_add(part)
    }

    /// The sample due at [`Self::due`] ran at tick `now`: moves to the next deadline still
    /// ahead of `now` and returns it with the number of deadlines skipped on the way.
    pub fn advance(&mut self, now: u64) -> (u64, u64) {
        let next = self.at(self.k + 1);
        if now < next {
            self.k += 1;
            self.due = next;
            return (next, 0);
        }
        // The first k with at(k) > now is k = ceil(d·f/F) with d = now − origin + 1: then
        // k·F/f ≥ d, a whole number, so its floor is too; and (k − 1)·F/f is below it. Split
        // as (d div F)·f + ceil((d mod F)·f/F) to stay in 64 bits.
        let (f, big_f) = (self.sample_hz, self.tick_hz);
        let d = now - self.origin + 1;
        let k = (d / big_f)
            .saturating_mul(f)
            .saturating_add(((d % big_f) * f).div_ceil(big_f));
        let skipped = k - self.k - 1;
        self.k = k;
        self.due = self.at(k);
        (self.due, skipped)
    }

    /// Continues at `sample_hz` from the current deadline (a new rate restarts the grid there).
    pub fn set_rate(&mut self, sample_hz: u32) {
        *self = SampleClock::new(self.due, self.tick_hz, sample_hz);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// embassy-time's tick rate in the firmware (its default, 1 MHz: firmware/Cargo.toml).
    const TICK_HZ: u64 = 1_000_000;

    /// One sample on a whole-tick period of 100 ticks: the one due at `due` ran at `now`.
    fn whole_tick_step(due: u64, now: u64) -> (u64, u64) {
        SampleClock::new(due, 100, 1).advance(now)
    }

    #[test]
    fn a_whole_tick_period_skips_missed_ticks_instead_of_bursting() {
        // On time and a little late: the next boundary, nothing skipped.
        assert_eq!(whole_tick_step(1000, 1000), (1100, 0));
        assert_eq!(whole_tick_step(1000, 1099), (1100, 0));
        // Exactly one period late: that boundary is now, so it is skipped.
        assert_eq!(whole_tick_step(1000, 1100), (1200, 1));
        // 2.5 periods late: ticks at 1100 and 1200 skipped, the next at 1300 is ahead.
        assert_eq!(whole_tick_step(1000, 1250), (1300, 2));
        // The deadline stays on the grid of `due` + k·period.
        let (n, _) = whole_tick_step(1000, 98_765);
        assert_eq!((n - 1000) % 100, 0);
        assert!(n > 98_765 && n <= 98_865);
    }

    #[test]
    fn a_rate_the_tick_divides_is_the_whole_tick_grid() {
        // 10 kHz on 1 MHz: 100 ticks exactly, every deadline 100 ticks after the last.
        let mut c = SampleClock::new(1000, TICK_HZ, 10_000);
        let mut due = 1000;
        for _ in 0..1000 {
            assert_eq!(c.advance(due), (due + 100, 0));
            due += 100;
        }
    }

    #[test]
    fn twelve_khz_takes_exactly_n_over_f_within_one_tick_over_a_million_samples() {
        // Closed form: N samples at 12 kHz on a 1 MHz tick take N·10^6/12 000 ticks; the clock
        // may round each deadline down, by less than one tick, and never accumulates.
        let mut c = SampleClock::new(0, TICK_HZ, 12_000);
        let mut prev = 0;
        for n in 1..=1_000_000u64 {
            let (t, skipped) = c.advance(prev);
            assert_eq!(skipped, 0);
            // t ≤ n·10^6/12 000 < t + 1, in integers.
            assert!(
                t * 12_000 <= n * 1_000_000 && n * 1_000_000 < (t + 1) * 12_000,
                "n {n}: {t}"
            );
            // Each period is 83 or 84 ticks (83.33 on average).
            assert!((83..=84).contains(&(t - prev)), "n {n}");
            prev = t;
        }
        // 10^6 samples are 83 333 333.3 µs: the last deadline is its floor, not 83 000 000
        // (the whole-tick period's, 0.4 % fast).
        assert_eq!(prev, 83_333_333);
    }

    #[test]
    fn late_samples_are_skipped_onto_the_same_grid() {
        let mut c = SampleClock::new(500, TICK_HZ, 12_000);
        // Sample 0 ran 250 µs late: the deadlines at 583, 666 and 750 have passed (3 skipped,
        // counted as skipped), 833 is ahead.
        let (t, skipped) = c.advance(750);
        assert_eq!((t, skipped), (500 + 333, 3));
        // The grid is unchanged: sample 10 is at floor(10·10^6/12 000) = 833 µs after 500.
        for _ in 0..6 {
            c.advance(c.due());
        }
        assert_eq!(c.due(), 500 + 833);
        // After a 1 s stall the next deadline is still on the grid: sample 12 001, the first
        // with floor(k·10^6/12 000) > 10^6, at 1 000 083 µs; samples 11..=12 000 are skipped.
        let (t, skipped) = c.advance(500 + 1_000_000);
        assert_eq!(t, 500 + 1_000_083);
        assert_eq!(skipped, 11_990);
    }

    #[test]
    fn deadlines_far_out_do_not_overflow() {
        // Jump-ahead: 10^12 samples at 12 kHz (2.6 years) in one step; the deadline is the
        // closed form floor(k·10^6/12 000) with k the first sample past `now`.
        let mut c = SampleClock::new(0, TICK_HZ, 12_000);
        let now = 1_000_000_000_000u64 * 1_000_000 / 12_000;
        let (t, _) = c.advance(now);
        assert!(t > now && t - now <= 84);
        assert_eq!(u128::from(t), u128::from(c.k) * 1_000_000 / 12_000);
    }

    #[test]
    fn the_64_bit_split_is_the_closed_form() {
        // floor(k·F/f) computed in 128 bits, for every rate in the range's corners and one
        // that shares no factor with the tick, at k around whole seconds and far out.
        for hz in [1_000u32, 7_001, 10_000, 12_000] {
            let c = SampleClock::new(5, TICK_HZ, hz);
            let f = u64::from(hz);
            for base in [0, f, 1_000 * f, 1_000_000_007 * f] {
                for k in base.saturating_sub(3)..base + 3 {
                    let exact = u128::from(k) * u128::from(TICK_HZ) / u128::from(f);
                    assert_eq!(u128::from(c.at(k) - 5), exact, "{hz} Hz, k {k}");
                }
            }
        }
    }

    #[test]
    fn a_new_rate_continues_from_the_current_deadline() {
        let mut c = SampleClock::new(0, TICK_HZ, 12_000);
        c.advance(0);
        c.set_rate(1_000);
        assert_eq!(c.due(), 83);
        assert_eq!(c.advance(83), (1083, 0));
    }
}
