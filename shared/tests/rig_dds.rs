//! The drive-phase generator: stepping equals the closed form (jump-ahead), which is additive.
//! Exactness over 10⁹ drive periods, proved with it, is hard case HC10 (tests/hard_cases/rig.rs).

use kapitza_core::rig::dds::Dds;
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
