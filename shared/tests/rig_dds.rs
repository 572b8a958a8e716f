//! The drive-phase generator: stepping equals the closed form, and the phase is exact over 10⁹
//! drive periods (proved by jump-ahead, not by looping).

use kapitza_core::rig::dds::{omega_of_word, Dds};
use proptest::prelude::*;

/// A generator mid-ramp: started at `phase`, ramping to `target`, after `pre` ticks.
fn dds(fs: u32, step: u32, start: u32, target: u32, pre: u64) -> Dds {
    let mut d = Dds::new(fs, step);
    d.start_at(
        kapitza_core::rig::fixed::Angle::from_turns_u32(start),
        target,
    );
    d.advance(pre);
    d
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// n calls of `tick` leave exactly the state `advance(n)` computes in closed form, through
    /// ramps up, ramps down, the landing on the target, and constant frequency.
    #[test]
    fn stepping_equals_jump_ahead(
        fs in 1_000u32..100_000,
        step in 1u32..5_000,
        start: u32,
        t1 in 0u32..(200 << 16),
        t2 in 0u32..(200 << 16),
        pre in 0u64..3_000,
        n in 0u64..30_000,
    ) {
        let mut a = dds(fs, step, start, t1, pre);
        a.set_target(t2);
        let mut b = a;
        for _ in 0..n {
            a.tick();
        }
        b.advance(n);
        prop_assert_eq!(a, b);
    }

    /// The rate limiter as a state machine under random retargeting: every tick the word moves
    /// by at most the step, toward the target, and lands on it after ⌈|Δ|/step⌉ ticks; the phase
    /// advances by the word's exact increment (⌊w·2^16/fs⌋ or one more), never jumps.
    #[test]
    fn rate_limiter_and_phase_continuity(
        fs in 1_000u32..100_000,
        step in 1u32..3_000,
        targets in prop::collection::vec((0u32..(300 << 16), 1u32..3_000), 1..12),
    ) {
        let mut d = Dds::new(fs, step);
        for (target, ticks) in targets {
            d.set_target(target);
            let need = u64::from(target.abs_diff(d.word())).div_ceil(u64::from(step));
            for k in 0..u64::from(ticks) {
                let (w0, p0) = (d.word(), d.phase());
                let p1 = d.tick();
                let w1 = d.word();
                prop_assert!(w1.abs_diff(w0) <= step);
                prop_assert!(w1.abs_diff(target) <= w0.abs_diff(target));
                if k + 1 >= need {
                    prop_assert_eq!(w1, target);
                }
                let inc = (u64::from(w1) << 16) / u64::from(fs);
                let dp = u64::from((p1 - p0).to_turns_u32());
                prop_assert!(dp == inc || dp == inc + 1, "phase step {} vs {}", dp, inc);
            }
        }
    }

    /// advance(m) then advance(n) equals advance(m + n): with the previous property, stepping
    /// any number of ticks equals one jump (induction on the number of ticks).
    #[test]
    fn jump_ahead_is_additive(
        fs in 1_000u32..100_000,
        step in 1u32..5_000,
        target in 0u32..(400 << 16),
        m in 0u64..(1 << 40),
        n in 0u64..(1 << 40),
    ) {
        let mut a = dds(fs, step, 0, target, 0);
        let mut b = a;
        a.advance(m);
        a.advance(n);
        b.advance(m + n);
        prop_assert_eq!(a, b);
    }
}

/// The exact phase after n ticks at a constant word w from phase 0: ⌊n·w·2^16/fs⌋ mod 2^32
/// (the rational n·f/fs turns truncated to 2^-32 turn; module doc of `rig::dds`).
fn exact_phase(n: u64, w: u32, fs: u32) -> (u32, u32) {
    let total = u128::from(n) * u128::from(w) * 65_536;
    (
        (total / u128::from(fs)) as u32,
        (total % u128::from(fs)) as u32,
    )
}

#[test]
fn exact_over_a_billion_periods() {
    // 50 Hz exactly at fs = 10 kHz: 200 ticks per period; after 10⁹ periods (2·10¹¹ ticks,
    // 231 days) the phase is back at exactly 0 with no remainder — zero drift.
    let mut d = Dds::new(10_000, 1);
    d.start_at(kapitza_core::rig::fixed::Angle::ZERO, 50 << 16);
    d.advance(50 << 16); // ramp at 1 word per tick lands exactly on the target
    let ramp_phase = (d.phase().to_turns_u32(), d.remainder());
    d.advance(200 * 1_000_000_000);
    assert_eq!((d.phase().to_turns_u32(), d.remainder()), ramp_phase);

    // An incommensurate frequency (49.8473 Hz as the nearest word): the phase after 10⁹ periods
    // equals the exact rational value, bit for bit (state = (phase, remainder)).
    let w = kapitza_core::rig::dds::word_from_omega(49.8473 * kapitza_core::math::TAU).unwrap();
    let mut d = Dds::new(10_000, 1 << 30); // step large enough to jump to w on the first tick
    d.set_target(w);
    let n = (1_000_000_000f64 * 10_000.0 / (f64::from(w) / 65_536.0)) as u64;
    d.advance(n);
    assert_eq!(
        (d.phase().to_turns_u32(), d.remainder()),
        exact_phase(n, w, 10_000)
    );
    // And the ω it runs at is the word's, to f64 rounding.
    assert!((omega_of_word(w) - 49.8473 * kapitza_core::math::TAU).abs() < 1e-4);
}
