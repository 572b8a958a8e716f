//! Has the pendulum settled, where, and what drive strength R holds it there.
//!
//! Settled: the per-period means stayed within a band (max − min) for `quiet_blocks` successive
//! blocks of `block_us`. The equilibrium angle φ0 is the mean of the last quiet block, and the
//! fast wobble's I/Q are averaged over the same block.
//!
//! ```text
//! R in situ (physics §7, model::infer):
//!   |sin 2(φ0 − θd)| ≥ 0.05:  R = −2 sin φ0 / sin 2(φ0 − θd)                (equilibrium condition)
//!   otherwise, with ωp:       R = ((ωp/ω0)² − cos φ0) / cos 2(φ0 − θd)     (slow frequency)
//!   (θd = 0° and 180° put φ0 at 0 or π, exactly where the first is 0/0.)
//! fast wobble:  amplitude = √(I² + Q²) ≈ (A/ℓ)|sin(φ0 − θd)|   →   A ≈ ℓ·amplitude/|sin(φ0 − θd)|,
//!   reported where |sin(φ0 − θd)| ≥ 0.2 (else the wobble is too small to read A from).
//! ```
//! All in fixed point: sin/cos from [`trig::sin_cos`] (4e-9), divisions exact to ½ LSB, the
//! square root `fixed`'s (1 LSB).

use super::period::PeriodMean;
use crate::model::RMethod;
use crate::rig::fixed::{approx, trig, Angle, RadPerSec, Ratio, Unit};

/// |sin 2(φ0 − θd)| below which the equilibrium formula is not used (as `model::infer`).
pub const SINGULAR_SIN_Q30: i32 = 53_687_091; // 0.05 in Q30
/// |sin(φ0 − θd)| below which the wobble does not give A.
const WOBBLE_SIN_Q30: i32 = 214_748_365; // 0.2 in Q30

/// Quiet-block detector with its last quiet block's averages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Settle {
    block_us: u32,
    band: u64,
    quiet_needed: u32,
    min: i64,
    max: i64,
    /// First angle of the block: sums run relative to it, so a large unwrapped angle (after
    /// many turns) cannot overflow them.
    base: Option<i64>,
    sum: i64,
    sum_i: i64,
    sum_q: i64,
    n: u32,
    elapsed: u32,
    quiet: u32,
    last: Option<Block>,
}

/// Averages over one quiet block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Block {
    /// Mean angle (unwrapped scale, 2^-32 turn).
    pub mean: i64,
    /// Mean wobble I/Q (Q20 turns).
    pub i: i64,
    pub q: i64,
}

impl Settle {
    pub fn new(block_us: u32, band: u64, quiet_needed: u32) -> Self {
        Self {
            block_us,
            band,
            quiet_needed: quiet_needed.max(1),
            min: i64::MAX,
            max: i64::MIN,
            base: None,
            sum: 0,
            sum_i: 0,
            sum_q: 0,
            n: 0,
            elapsed: 0,
            quiet: 0,
            last: None,
        }
    }

    pub fn reset(&mut self) {
        *self = Self::new(self.block_us, self.band, self.quiet_needed);
    }

    pub fn push(&mut self, p: &PeriodMean) {
        self.min = self.min.min(p.unwrapped);
        self.max = self.max.max(p.unwrapped);
        let base = *self.base.get_or_insert(p.unwrapped);
        self.sum = self.sum.saturating_add(p.unwrapped.wrapping_sub(base));
        self.sum_i = self.sum_i.saturating_add(p.i);
        self.sum_q = self.sum_q.saturating_add(p.q);
        self.n += 1;
        self.elapsed = self.elapsed.saturating_add(p.dt_us);
        if self.elapsed >= self.block_us {
            let n = i64::from(self.n);
            if self.max.abs_diff(self.min) <= self.band {
                self.quiet += 1;
                self.last = Some(Block {
                    mean: base.wrapping_add(approx::div_round(self.sum, n)),
                    i: approx::div_round(self.sum_i, n),
                    q: approx::div_round(self.sum_q, n),
                });
            } else {
                self.quiet = 0;
            }
            let keep = (self.quiet, self.last);
            self.reset();
            (self.quiet, self.last) = keep;
        }
    }

    pub fn settled(&self) -> bool {
        self.quiet >= self.quiet_needed
    }

    /// The last quiet block, once settled.
    pub fn block(&self) -> Option<Block> {
        self.settled().then_some(self.last).flatten()
    }
}

/// R from the settled angle, or from ωp² where that is singular; `None` where neither formula
/// applies or the result is negative (not an equilibrium).
pub fn r_in_situ(
    phi0: Angle,
    theta_d: Angle,
    omega_p_sq: Option<RadPerSec>,
    omega0_sq: RadPerSec,
) -> Option<(Ratio, RMethod)> {
    let psi = phi0 - theta_d;
    let (s2, c2) = trig::sin_cos(psi.double());
    let (sp, cp) = trig::sin_cos(phi0);
    let (s2, c2, sp, cp) = (
        i64::from(s2.to_bits()),
        i64::from(c2.to_bits()),
        i64::from(sp.to_bits()),
        i64::from(cp.to_bits()),
    );
    if s2.abs() >= i64::from(SINGULAR_SIN_Q30) {
        // R (Q16) = −2 sp / s2
        let r = approx::div_round((-2 * sp) << 16, s2);
        return (r >= 0).then(|| {
            (
                Ratio::from_bits(approx::sat_i32(r)),
                RMethod::EquilibriumAngle,
            )
        });
    }
    let wp2 = i64::from(omega_p_sq?.to_bits());
    if c2.abs() < i64::from(SINGULAR_SIN_Q30) || omega0_sq <= RadPerSec::ZERO {
        return None;
    }
    let ratio_q30 = approx::div_round(wp2 << 30, i64::from(omega0_sq.to_bits()));
    let r = approx::div_round((ratio_q30 - cp) << 16, c2);
    (r >= 0).then(|| (Ratio::from_bits(approx::sat_i32(r)), RMethod::SlowFrequency))
}

/// Fast-wobble amplitude (rad, from I/Q in Q20 turns) and the stroke A it implies (m), given
/// ℓ (m, I16F16); A only where |sin(φ0 − θd)| ≥ 0.2.
pub fn wobble(
    i: i64,
    q: i64,
    phi0: Angle,
    theta_d: Angle,
    ell: RadPerSec,
) -> (Unit, Option<RadPerSec>) {
    // Q20 turns → Q30 rad: ·2π·2^10; as I2F30 the amplitude is < 2 rad by far.
    const TWO_PI_Q30: i64 = 6_746_518_852; // 2π·2^30
    let to_q30 = |x: i64| approx::sat_i32(((x as i128 * i128::from(TWO_PI_Q30)) >> 20) as i64);
    let (iq, qq) = (Unit::from_bits(to_q30(i)), Unit::from_bits(to_q30(q)));
    let amp = approx::sqrt_unit(iq.saturating_mul(iq).saturating_add(qq.saturating_mul(qq)));
    let (s, _) = trig::sin_cos(phi0 - theta_d);
    let s = s.to_bits().unsigned_abs();
    if s < WOBBLE_SIN_Q30 as u32 {
        return (amp, None);
    }
    // A (Q16 m) = ℓ(Q16)·amp(Q30)/s(Q30)
    let a = approx::div_round(
        i64::from(ell.to_bits()) * i64::from(amp.to_bits()),
        i64::from(s),
    );
    (amp, Some(RadPerSec::from_bits(approx::sat_i32(a))))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{equilibria, DriveAngle};

    #[test]
    fn r_matches_the_f64_inference() {
        // Against model::infer_r (f64) at stable equilibria of the averaged model: the fixed-point
        // R agrees to 2e-4 (I16F16 LSB 1.5e-5 times the conditioning 1/|sin 2ψ| ≤ 20, plus Q30).
        for (r, deg) in [(1.75, 90.0), (3.0, 135.0), (2.5, 120.0), (1.2, 60.0)] {
            let d = DriveAngle::from_deg(deg).unwrap();
            for e in equilibria(r, d).unwrap().stable() {
                let got = r_in_situ(
                    Angle::from_rad(e.angle),
                    Angle::from_deg(deg),
                    None,
                    RadPerSec::from_num(58.86),
                );
                let (got, m) = got.unwrap();
                assert_eq!(m, RMethod::EquilibriumAngle);
                assert!(
                    (got.to_num::<f64>() - r).abs() < 2e-4,
                    "R {r} θd {deg}: {got}"
                );
            }
        }
        // Singular: θd = 180°, φ0 = π, ωp² = ω0²(R − 1) with R = 3 (physics §3 closed form).
        let w02 = RadPerSec::from_num(58.86);
        let wp2 = RadPerSec::from_num(58.86 * 2.0);
        assert_eq!(
            r_in_situ(Angle::HALF_TURN, Angle::HALF_TURN, None, w02),
            None
        );
        let (r, m) = r_in_situ(Angle::HALF_TURN, Angle::HALF_TURN, Some(wp2), w02).unwrap();
        assert_eq!(m, RMethod::SlowFrequency);
        assert!((r.to_num::<f64>() - 3.0).abs() < 1e-4, "{r}");
    }
}
