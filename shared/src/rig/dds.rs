//! The drive-phase generator: a phase accumulator (direct digital synthesis) that defines the
//! reference drive phase ωt exactly, in integers.
//!
//! ```text
//! frequency word w: the drive frequency in Q16.16 Hz   (f = w/2^16, resolution 15 µHz)
//! phase p: Q0.32 turns (an Angle), remainder ρ ∈ [0, fs)
//! per tick:  w ← w moved toward the target by ≤ s (the rate limit)
//!            p·fs + ρ  ←  p·fs + ρ + w·2^16            (split by one u64 division per change of w)
//! after n ticks at a constant w:  p_n = ⌊(p_0·fs + ρ_0 + n·w·2^16)/fs⌋ mod 2^32
//! ```
//! The phase is therefore the exact rational n·f/fs turns, truncated to 2^-32 turn: there is no
//! rounding that accumulates, so it cannot drift, however long it runs. The only difference from
//! a requested ω is the frequency word's quantisation (≤ 2^-17 Hz), a constant offset in
//! frequency that the phase lock and estimator follow exactly, not a drift of the generator.
//! [`Dds::advance`] jumps n ticks ahead in closed form (sums of arithmetic series in u128),
//! which is how "exact over 10⁹ periods" is proved without looping 10⁹ times.
//!
//! Changes of frequency are phase-continuous (only the increment changes) and rate-limited to
//! ≤ s words per tick; soft start and stop are ramps from and to w = 0.

use super::fixed::{Angle, RadPerSec};
use crate::math;

/// 2π in Q32 (for ω = 2π·f).
const TWO_PI_Q32: u64 = 26_986_075_409; // round(2π · 2^32)

/// Frequency word (Q16.16 Hz) for ω rad/s, rounded; `None` if ω is negative, not finite or
/// ≥ 65536 Hz. Boundary conversion.
pub fn word_from_omega(omega: f64) -> Option<u32> {
    if !omega.is_finite() || omega < 0.0 {
        return None;
    }
    let w = libm::round(omega / math::TAU * 65_536.0);
    (w < 4_294_967_296.0).then_some(w as u32)
}

/// ω in rad/s of a frequency word (exact in f64).
pub fn omega_of_word(w: u32) -> f64 {
    f64::from(w) / 65_536.0 * math::TAU
}

/// Largest per-tick change of the frequency word that keeps |dω/dt| ≤ `rate` (rad/s²) at
/// `sample_hz`; rounded down, so the limit is never exceeded. 0 if the limit is finer than one
/// word per tick (2π·fs/2^16 rad/s²), which the configuration check rejects.
pub fn step_from_rate(rate: f64, sample_hz: u32) -> u32 {
    let s = rate / math::TAU * 65_536.0 / f64::from(sample_hz);
    if s.is_finite() && s >= 1.0 {
        libm::floor(s).min(f64::from(u32::MAX)) as u32
    } else {
        0
    }
}

/// The phase accumulator with its ramp.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dds {
    fs: u32,
    phase: u32,
    rem: u32,
    freq: u32,
    target: u32,
    step: u32,
    inc_q: u32,
    inc_r: u32,
    ticks: u64,
}

impl Dds {
    /// Stopped, at phase 0, with a rate limit of `step` words per tick (≥ 1).
    pub fn new(sample_hz: u32, step: u32) -> Self {
        Self {
            fs: sample_hz.max(1),
            phase: 0,
            rem: 0,
            freq: 0,
            target: 0,
            step: step.max(1),
            inc_q: 0,
            inc_r: 0,
            ticks: 0,
        }
    }

    fn set_increment(&mut self) {
        let n = u64::from(self.freq) << 16;
        self.inc_q = (n / u64::from(self.fs)) as u32;
        self.inc_r = (n % u64::from(self.fs)) as u32;
    }

    /// One sample tick: ramp the frequency one step toward the target, advance the phase.
    #[inline]
    pub fn tick(&mut self) -> Angle {
        if self.freq != self.target {
            self.freq = if self.target > self.freq {
                self.freq + (self.target - self.freq).min(self.step)
            } else {
                self.freq - (self.freq - self.target).min(self.step)
            };
            self.set_increment();
        }
        self.rem += self.inc_r;
        let carry = u32::from(self.rem >= self.fs);
        self.rem -= carry * self.fs;
        self.phase = self.phase.wrapping_add(self.inc_q).wrapping_add(carry);
        self.ticks = self.ticks.wrapping_add(1);
        Angle::from_turns_u32(self.phase)
    }

    /// Exactly what `n` calls of [`Dds::tick`] do, in closed form.
    pub fn advance(&mut self, n: u64) {
        let n128 = u128::from(n);
        let mut sum: u128 = 0; // Σ of the frequency words of the n ticks
        let mut done: u128 = 0;
        if self.freq != self.target {
            let up = self.target > self.freq;
            let diff = u128::from(self.target.abs_diff(self.freq));
            let s = u128::from(self.step);
            let k = diff.div_ceil(s); // the k-th tick lands on the target
            let m = n128.min(k);
            let free = if m == k { k - 1 } else { m }; // ticks not clamped
            let f0 = u128::from(self.freq);
            let ramp = s * free * (free + 1) / 2;
            sum += if up {
                f0 * free + ramp
            } else {
                f0 * free - ramp
            };
            if m == k {
                sum += u128::from(self.target);
                self.freq = self.target;
            } else {
                let moved = (s * m) as u32;
                self.freq = if up {
                    self.freq + moved
                } else {
                    self.freq - moved
                };
            }
            done = m;
            self.set_increment();
        }
        sum += (n128 - done) * u128::from(self.freq);
        let total = u128::from(self.rem) + (sum << 16);
        let fs = u128::from(self.fs);
        self.phase = self.phase.wrapping_add((total / fs) as u32); // mod 2^32
        self.rem = (total % fs) as u32;
        self.ticks = self.ticks.wrapping_add(n);
    }

    /// Ramp toward a new frequency word, phase-continuously.
    pub fn set_target(&mut self, word: u32) {
        self.target = word;
    }

    /// Soft start from standstill: align the phase to `phase` (the crank's, so the phase lock
    /// starts with zero error) and ramp to `word`. Ignored unless stopped.
    pub fn start_at(&mut self, phase: Angle, word: u32) {
        if self.is_stopped() {
            self.phase = phase.to_turns_u32();
            self.rem = 0;
            self.target = word;
        }
    }

    /// Soft stop: ramp down to zero at the rate limit.
    pub fn stop(&mut self) {
        self.target = 0;
    }

    /// Immediate stop (e-stop, faults): frequency and target to zero now; the phase stays.
    pub fn halt(&mut self) {
        self.freq = 0;
        self.target = 0;
        self.set_increment();
    }

    pub fn set_step(&mut self, step: u32) {
        self.step = step.max(1);
    }

    #[inline]
    pub fn phase(&self) -> Angle {
        Angle::from_turns_u32(self.phase)
    }
    /// The phase remainder ρ ∈ [0, fs): with it, (phase, ρ) is the exact state.
    pub fn remainder(&self) -> u32 {
        self.rem
    }
    pub fn word(&self) -> u32 {
        self.freq
    }
    pub fn target_word(&self) -> u32 {
        self.target
    }
    pub fn step(&self) -> u32 {
        self.step
    }
    pub fn ticks(&self) -> u64 {
        self.ticks
    }
    pub fn sample_hz(&self) -> u32 {
        self.fs
    }
    pub fn is_stopped(&self) -> bool {
        self.freq == 0 && self.target == 0
    }
    pub fn is_ramping(&self) -> bool {
        self.freq != self.target
    }

    /// The reference ω = 2π·w/2^16 as I16F16 rad/s (rounded).
    #[inline]
    pub fn omega(&self) -> RadPerSec {
        RadPerSec::from_bits(((u64::from(self.freq) * TWO_PI_Q32 + (1 << 31)) >> 32) as i32)
    }

    /// The reference dω/dt while ramping (rad/s², I16F16, saturating), else 0.
    pub fn accel(&self) -> RadPerSec {
        if self.freq == self.target {
            return RadPerSec::ZERO;
        }
        // step words/tick · fs ticks/s · 2π/2^16 rad/s per word, in Q16: step·fs·2π
        let mag = (u64::from(self.step) * u64::from(self.fs)).saturating_mul(TWO_PI_Q32) >> 32;
        let mag = mag.min(i32::MAX as u64) as i32;
        RadPerSec::from_bits(if self.target > self.freq { mag } else { -mag })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_rates() {
        // 50 Hz = 314.159 rad/s is word 50·2^16 exactly.
        assert_eq!(word_from_omega(50.0 * math::TAU), Some(50 << 16));
        assert_eq!(word_from_omega(-1.0), None);
        assert_eq!(word_from_omega(f64::NAN), None);
        // 60 rad/s² at 10 kHz: 60/2π·2^16/1e4 = 62.58 → 62 words per tick (rounded down).
        assert_eq!(step_from_rate(60.0, 10_000), 62);
        assert_eq!(step_from_rate(1e-3, 10_000), 0);
        let mut d = Dds::new(10_000, 1);
        d.set_target(50 << 16);
        d.advance(u64::from(50u32 << 16));
        // ω = 2π·50 = 314.159…, I16F16 rounding ±1 LSB.
        assert!((d.omega().to_num::<f64>() - 100.0 * math::PI).abs() < 2e-5);
    }

    #[test]
    fn ramp_is_rate_limited_and_phase_continuous() {
        let mut d = Dds::new(10_000, 62);
        d.start_at(Angle::from_deg(33.0), 40 << 16);
        let mut prev_w = d.word();
        let mut prev_p = d.phase();
        for _ in 0..100_000 {
            let p = d.tick();
            assert!(d.word().abs_diff(prev_w) <= 62);
            // Phase step = this tick's increment (≤ w/fs turns + 1 LSB): no jumps.
            let dp = (p - prev_p).to_turns_u32();
            assert!(u64::from(dp) <= (u64::from(d.word()) << 16) / 10_000 + 1);
            prev_w = d.word();
            prev_p = p;
        }
        assert_eq!(d.word(), 40 << 16);
        d.stop();
        d.advance(1_000_000);
        assert!(d.is_stopped());
    }
}
