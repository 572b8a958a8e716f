//! HC10–HC14: the rig logic's hard cases (fixed point and time, run on the microcontroller):
//! exact drive phase over 10⁹ periods by jump-ahead, saturation at large angular velocity, the
//! 32-bit microsecond tick wrapping, no drift or windup over long runs, and a pendulum rotating
//! for hours.

use kapitza_core::math;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::dds::{omega_of_word, word_from_omega, Dds};
use kapitza_core::rig::estimator::period::{PeriodAverager, MAX_SAMPLES};
use kapitza_core::rig::estimator::{slow_rate, Estimate, Estimator, Tuning};
use kapitza_core::rig::fixed::{Angle, RadPerSec};

/// Feeds `n` samples of θ(t) (f64, rad) at `fs` with a drive at ω (rad/s) into an estimator,
/// stamping them from `t0_us`. Returns the last estimate.
fn run(
    est: &mut Estimator,
    fs: u32,
    omega: f64,
    t0_us: u32,
    n: u64,
    theta: impl Fn(f64) -> f64,
) -> Estimate {
    let mut dds = Dds::new(fs, u32::MAX);
    dds.set_target(word_from_omega(omega).unwrap());
    let per = 1_000_000 / fs;
    for k in 0..n {
        let psi = dds.tick();
        let t = k as f64 / f64::from(fs);
        est.push(
            t0_us.wrapping_add((k as u32).wrapping_mul(per)),
            Angle::from_rad(theta(t)),
            psi,
        );
    }
    *est.estimate()
}

/// A damped slow oscillation about φ0 with the fast wobble of the averaged theory on top.
fn pendulum(phi0: f64, omega: f64) -> impl Fn(f64) -> f64 {
    move |t| {
        let slow = phi0 + 0.1 * (-0.4 * t).exp() * (8.0 * t).cos();
        slow + 0.03 * (omega * t).cos()
    }
}

#[test]
fn hc11_saturation_at_large_angular_velocity() {
    // Rotation at 0.45 turn per sample (28 274 rad/s at 10 kHz, just inside the unwrap limit
    // π·fs): sums do not overflow (debug overflow checks are on in tests) and the slow rate is
    // right to 0.1 %. Expected: 0.45·2π·10⁴ rad/s (closed form); period means are stamped at
    // their middles, so the whole-sample jitter of the period length (209 or 210) cancels.
    let cfg = RigConfig::REFERENCE;
    let mut est = Estimator::new(&cfg, &Tuning::DEFAULT, Angle::ZERO);
    let w = 0.45 * math::TAU * 10_000.0;
    let e = run(&mut est, 10_000, 300.0, 0, 20_000, |t| w * t);
    let got: f64 = e.phi_rate.to_num();
    assert!((got / w - 1.0).abs() < 1e-3, "{got} vs {w}");
    // The longest period averaged (2^14 samples) at 0.49 turn per sample: the worst case of the
    // overflow bound in `period`'s doc. It must average, not panic or wrap.
    let mut p = PeriodAverager::new();
    let step = (0.49 * 4_294_967_296.0) as i32;
    let mut out = None;
    let psi_step = (1u64 << 32) / u64::from(MAX_SAMPLES) + 1;
    for k in 0..(3 * MAX_SAMPLES) {
        let psi = Angle::from_turns_u32((u64::from(k) * psi_step) as u32);
        let th = Angle::from_bits(step.wrapping_mul(k as i32));
        out = p.push(k * 100, th, psi).or(out);
    }
    assert!(out.is_some());
    // Beyond the format: a rate that does not fit I16F16 sticks at the end of the range with the
    // right sign instead of wrapping to a plausible small value.
    assert_eq!(slow_rate(i64::MAX / 2, 1), RadPerSec::MAX);
    assert_eq!(slow_rate(i64::MIN / 2, 1), RadPerSec::MIN);
    assert_eq!(slow_rate(-(1 << 40), 1_000), RadPerSec::MIN);
}

#[test]
fn hc12_microsecond_tick_wrap_changes_nothing() {
    // The same samples stamped from 0 and from 3 s before the u32 wrap (71.6 min): every
    // estimate is bit-identical, because only wrapping differences of stamps are used.
    let cfg = RigConfig::REFERENCE;
    let theta_d = Angle::from_deg(90.0);
    let mut a = Estimator::new(&cfg, &Tuning::DEFAULT, theta_d);
    let mut b = a;
    let omega = 313.0;
    let ea = run(&mut a, 10_000, omega, 0, 200_000, pendulum(0.9, omega));
    let eb = run(
        &mut b,
        10_000,
        omega,
        u32::MAX - 3_000_000,
        200_000,
        pendulum(0.9, omega),
    );
    assert!(ea.omega_p.is_some() && ea.settled);
    assert_eq!(ea, eb);
}

#[test]
fn hc13_no_drift_or_windup_over_a_long_run() {
    // Two hours of a settled pendulum (72 M samples; the µs tick wraps once). Per-period sums
    // restart every period and block sums every second, so nothing accumulates:
    // * a still pendulum: the equilibrium after 2 h is bit-identical to the one after 1 min;
    // * with the fast wobble: it stays at the signal's centre 0.9 rad to 1e-5 rad — the scatter
    //   is the wobble's leakage through a whole-sample boxcar (≲ |ξ|/N per period, `period` doc),
    //   which differs from block to block but does not grow.
    let cfg = RigConfig::REFERENCE;
    let theta_d = Angle::from_deg(90.0);
    let omega = 313.0;
    for (wobble, tol) in [(0.0, 0.0), (0.03, 1e-5)] {
        let sig = |t: f64| 0.9 + wobble * (omega * t).cos();
        let mut est = Estimator::new(&cfg, &Tuning::DEFAULT, theta_d);
        let early = run(&mut est, 10_000, omega, 0, 600_000, sig);
        let mut long = Estimator::new(&cfg, &Tuning::DEFAULT, theta_d);
        let late = run(&mut long, 10_000, omega, 0, 72_000_000, sig);
        let (e0, e1) = (early.equilibrium.unwrap(), late.equilibrium.unwrap());
        assert!(
            (e1 - e0).to_rad().abs() <= tol,
            "{} vs {}",
            e0.to_rad(),
            e1.to_rad()
        );
        assert!((e1.to_rad() - 0.9).abs() <= tol + 1e-9, "{}", e1.to_rad());
        assert!(late.settled);
    }
}

#[test]
fn hc14_rotation_for_hours_keeps_full_precision() {
    // Unidirectional rotation at 20 rad/s for 3 hours (216 000 rad, 34 000 turns; 1 kHz samples,
    // 10 Hz drive): the period mean is the angle at mid-period to 1e-6 rad, as at the start —
    // angles wrap, they do not lose resolution. Expected: θ(t_mid) in closed form.
    let cfg = RigConfig::REFERENCE;
    let mut est = Estimator::new(&cfg, &Tuning::DEFAULT, Angle::ZERO);
    let fs = 1_000;
    let omega = math::TAU * 10.0;
    let n = 3 * 3600 * 1000;
    let mut dds = Dds::new(fs, u32::MAX);
    dds.set_target(word_from_omega(omega).unwrap());
    let mut worst: f64 = 0.0;
    let mut end_of_period = Vec::new();
    for k in 0..n {
        let psi = dds.tick();
        let t = k as f64 / 1000.0;
        if let Some(e) = est.push(
            (k as u32).wrapping_mul(1000),
            Angle::from_rad(20.0 * t),
            psi,
        ) {
            end_of_period.push((k, e.phi));
            if end_of_period.len() > 2 {
                end_of_period.remove(0);
            }
            if let [(k0, _), (k1, phi)] = end_of_period[..] {
                // samples k0+1 ..= k1 were averaged… the period runs from sample k0 to k1 − 1
                let mid = (k0 + k1 - 1) as f64 / 2.0 / 1000.0;
                let err = math::wrap_pi(phi.to_rad() - 20.0 * mid);
                worst = worst.max(err.abs());
            }
        }
    }
    assert!(worst < 1e-6, "worst {worst}");
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
fn hc10_exact_drive_phase_over_a_billion_periods() {
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
