//! The slow oscillation's frequency and decay, from the extrema of the per-period means.
//!
//! ```text
//! x(t) = φ0 + a e^{−σt} cos(ωd t + ϕ)     small slow oscillation, damping c = 2σ
//! successive extrema are exactly π/ωd apart, and their swings x_j − x_{j−1} shrink by e^{−σπ/ωd}:
//!   ωd = π·n / (t_last − t_first)                 over the last n ≤ 7 half-periods (8 extrema)
//!   σ  = ln(swing_first / swing_last) / (t_swing_last − t_swing_first)   over the same window
//!   ωp = √(ωd² + σ²)                              undamped slow frequency (x'' + 2σx' + ωp² x = 0)
//! ```
//! An extremum is declared when the signal has come back from its running maximum (minimum) by a
//! hysteresis h well above the per-period noise, and its time and value are refined by the
//! parabola through the extreme sample and its two neighbours:
//!
//! ```text
//! δ = (x₋ − x₊) / (2(x₋ − 2x₀ + x₊)) ∈ [−½, ½] samples,  t* = t₀ + δ·(t₊ − t₋)/2,
//! x* = x₀ − (x₋ − x₊)·δ/4
//! ```
//! The window slides, so large first swings (whose frequency is shifted by the nonlinearity of
//! the effective potential) give way to small ones, and the estimate freezes on the last window
//! of usable swings once the motion has decayed: that is the small-oscillation ωp of physics §3.
//! Only swings ≥ `min_swing` count (smaller ones are noise-timed); the motion's first extremum —
//! the release from the hand, or a drive transient — is never declared, because the direction is
//! not known until the signal has moved by h. Times are 32-bit µs stamps; only their wrapping
//! differences are used, so the 71.6-minute wrap of the tick counter changes nothing.

use crate::rig::fixed::{approx, RadPerSec};

/// π·10⁶·2^16: ωd in I16F16 = n·this / Δt_µs.
const PI_E6_Q16: i64 = 205_887_416_146;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Point {
    x: i64,
    t: u32,
}

/// Extremum tracker and the frequency/decay fit over the current run of swings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SwingTracker {
    h: i64,
    min_swing: i64,
    dir: i8,
    start: Option<Point>,
    last: Option<Point>,
    ext: Point,
    ext_prev: Option<Point>,
    ext_next: Option<Point>,
    awaiting_next: bool,
    prev_ext: Option<Point>,
    /// The last extrema joined by usable swings, oldest first, `len` of them.
    window: [Point; WINDOW],
    len: usize,
    omega_d: Option<RadPerSec>,
    sigma: Option<RadPerSec>,
    last_swing: Option<u64>,
}

/// Extrema kept for the fit: 7 half-periods.
const WINDOW: usize = 8;

impl SwingTracker {
    /// `h` and `min_swing` in 2^-32 turn.
    pub fn new(h: i64, min_swing: i64) -> Self {
        Self {
            h: h.max(1),
            min_swing,
            dir: 0,
            start: None,
            last: None,
            ext: Point { x: 0, t: 0 },
            ext_prev: None,
            ext_next: None,
            awaiting_next: false,
            prev_ext: None,
            window: [Point { x: 0, t: 0 }; WINDOW],
            len: 0,
            omega_d: None,
            sigma: None,
            last_swing: None,
        }
    }

    pub fn reset(&mut self) {
        *self = Self::new(self.h, self.min_swing);
    }

    fn set_ext(&mut self, p: Point) {
        self.ext = p;
        self.ext_prev = self.last;
        self.ext_next = None;
        self.awaiting_next = true;
    }

    /// One per-period mean x (unwrapped, 2^-32 turn) at stamp t.
    pub fn push(&mut self, x: i64, t: u32) {
        let p = Point { x, t };
        if self.awaiting_next {
            self.ext_next = Some(p);
            self.awaiting_next = false;
        }
        match self.dir {
            0 => {
                let s = *self.start.get_or_insert(p);
                if x >= s.x.saturating_add(self.h) {
                    self.dir = 1;
                    self.set_ext(p);
                } else if x <= s.x.saturating_sub(self.h) {
                    self.dir = -1;
                    self.set_ext(p);
                }
            }
            d => {
                let beyond = if d > 0 {
                    x > self.ext.x
                } else {
                    x < self.ext.x
                };
                let back = if d > 0 {
                    x < self.ext.x.saturating_sub(self.h)
                } else {
                    x > self.ext.x.saturating_add(self.h)
                };
                if beyond {
                    self.set_ext(p);
                } else if back {
                    let e = self.refined();
                    self.emit(e);
                    self.dir = -d;
                    self.set_ext(p);
                }
            }
        }
        self.last = Some(p);
    }

    fn refined(&self) -> Point {
        let (Some(a), Some(b)) = (self.ext_prev, self.ext_next) else {
            return self.ext;
        };
        let x0 = self.ext.x;
        // Differences first: x itself may be far from 0 after many turns.
        let den = (a.x - x0) + (b.x - x0);
        if den == 0 {
            return self.ext;
        }
        // δ in Q16, clamped to ±½
        let d = approx::div_round((a.x - b.x).saturating_mul(1 << 15), den).clamp(-32_768, 32_768);
        let span = i64::from(b.t.wrapping_sub(a.t));
        let dt = (d * span) >> 17; // δ·span/2
        let dx = ((a.x - b.x) as i128 * i128::from(d)) >> 18; // (x₋ − x₊)·δ/4
        Point {
            x: x0 - dx as i64,
            t: self.ext.t.wrapping_add(dt as i32 as u32),
        }
    }

    fn emit(&mut self, e: Point) {
        if let Some(prev) = self.prev_ext {
            let swing = e.x.abs_diff(prev.x);
            if swing >= self.min_swing.unsigned_abs() {
                if self.len == 0 {
                    self.window[0] = prev;
                    self.len = 1;
                }
                if self.len == WINDOW {
                    self.window.copy_within(1.., 0);
                    self.len -= 1;
                }
                self.window[self.len] = e;
                self.len += 1;
                self.last_swing = Some(swing);
                self.fit();
            } else {
                // The run of usable swings ends; the estimates stay as the last window left them.
                self.len = 0;
            }
        }
        self.prev_ext = Some(e);
    }

    /// ωd from the window's span, σ from its first and last swings.
    fn fit(&mut self) {
        let w = &self.window[..self.len];
        let n = self.len - 1; // half-periods
        if n < 2 {
            return;
        }
        let dt = i64::from(w[n].t.wrapping_sub(w[0].t));
        if dt > 0 {
            let wd = approx::div_round(n as i64 * PI_E6_Q16, dt);
            self.omega_d = Some(RadPerSec::from_bits(approx::sat_i32(wd)));
        }
        if n < 3 {
            return;
        }
        let first = w[1].x.abs_diff(w[0].x);
        let last = w[n].x.abs_diff(w[n - 1].x);
        let dt = i64::from(w[n].t.wrapping_sub(w[1].t));
        if last > 0 && dt > 0 {
            let ln = i64::from(approx::ln_ratio(first, last).to_bits()); // Q24
                                                                         // σ in Q16 = ln·2^-24 · 10⁶/Δt · 2^16
            let s = approx::div_round(ln * 1_000_000, dt << 8);
            self.sigma = Some(RadPerSec::from_bits(approx::sat_i32(s)));
        }
    }

    /// Half-periods in the current window.
    pub fn half_periods(&self) -> u32 {
        self.len.saturating_sub(1) as u32
    }

    /// Latest usable swing (peak to peak), 2^-32 turn.
    pub fn last_swing(&self) -> Option<u64> {
        self.last_swing
    }

    /// ωd (rad/s), once two half-periods have been timed.
    pub fn omega_d(&self) -> Option<RadPerSec> {
        self.omega_d
    }

    /// σ (1/s), once three swings have been measured.
    pub fn sigma(&self) -> Option<RadPerSec> {
        self.sigma
    }

    /// ωp² = ωd² + σ² (1/s², I16F16, saturating); σ taken as 0 until it is measured.
    pub fn omega_p_sq(&self) -> Option<RadPerSec> {
        let wd = self.omega_d?;
        let s = self.sigma.unwrap_or(RadPerSec::ZERO);
        Some(wd.saturating_mul(wd).saturating_add(s.saturating_mul(s)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damped_cosine_frequency_and_decay() {
        // x = 0.2 e^{−0.3t} cos(8t) sampled at 50 Hz with stamps starting just before the u32
        // wrap: ωd = 8 rad/s and σ = 0.3 /s (the generating values) within 0.3 % and 2 %.
        let turn = 4_294_967_296.0 / crate::math::TAU;
        let mut s = SwingTracker::new((0.003 * turn) as i64, (0.01 * turn) as i64);
        let t0 = u32::MAX - 3_000_000;
        for k in 0..600u32 {
            let t = f64::from(k) * 0.02;
            let x = 0.2 * libm::exp(-0.3 * t) * libm::cos(8.0 * t);
            s.push((x * turn) as i64, t0.wrapping_add(k * 20_000));
        }
        let wd: f64 = s.omega_d().unwrap().to_num();
        let sg: f64 = s.sigma().unwrap().to_num();
        assert!((wd - 8.0).abs() < 0.024, "ωd {wd}");
        assert!((sg - 0.3).abs() < 0.006, "σ {sg}");
        assert_eq!(s.half_periods(), 7);
    }
}
