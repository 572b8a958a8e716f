//! System identification from a ring-down: the pendulum let go from 10–30° with the drive off,
//! sampled at the telemetry rate.
//!
//! ```text
//! half-swings ([`super::swing`]): turning points e_k, half-heights h_k, midline crossings c_k
//! zero     z = mean over interior k of (e_{k−1} + 2 e_k + e_{k+1})/4, over an even count of k
//!            (exact for a linear envelope, Coulomb; a geometric one, viscous, leaves a bias
//!             (1 − r)²/4 of the swing that alternates in sign and cancels in pairs)
//! decay    [`super::decay`] fitted to F(h_k) (below): r per half-swing and the Coulomb shift
//!          δ = μ/ω0², the model chosen
//! ω0       Δ_j = c_{j+1} − c_j is half a period at the amplitude a_j = (h_j + h_{j+1})/2 of the
//!          turning point between them; at that amplitude the frequency is ω·AGM(1, cos(a/2))
//!          ([`super::period`]), so the small-amplitude damped frequency is
//!              ωd = (K − 1) π / Σ_j Δ_j AGM(1, cos(a_j/2))
//!          then σ = −ln(r) ωd/π, and ω0² = ωd² + σ² (the viscous oscillator's ωd² = ω0² − σ²;
//!          Coulomb friction leaves the frequency alone: each half-swing is a harmonic arc)
//! ℓ = g/ω0²   (a uniform rod: L = 3ℓ/2, physics §2);   Q = ω0/c = ω0/(2σ);   μ = δ ω0²
//! ```
//! **Wide swings.** The decay's recurrences hold for a harmonic oscillator. A pendulum at swing A
//! loses c∫θ'² dt = c ω0 J(A) of energy E = ω0²(1 − cos A) per half-swing to viscous damping,
//! with J(A) = ∫ √(2(cos θ − cos A)) dθ over [−A, A] = (π/2) A² (1 − 5A²/96 + …), so its swing
//! shrinks (1 + 11A²/96) times as fast as an oscillator's (3 % at 30°). In F(A) = A e^(−11A²/192)
//! that factor cancels to O(A⁴), and Coulomb friction, which removes μ·2A, moves F by
//! 2δ(1 − A²/192): the decay is fitted to F(h_k), an oscillator's envelope to that order.
//!
//! Only half-swings of half-height ≥ [`Limits::floor`] are used: below it a Coulomb pendulum is
//! about to stick and the sensor's noise grows relative to the swing.
//!
//! The zero is from the centre of the swing, not from where the pendulum comes to rest: Coulomb
//! friction stops it anywhere within asin(μ/ω0²) of the true bottom.

use super::decay::{self, Decay, DecayModel};
use super::error::{positive, CalibError};
use super::period::frequency_ratio;
use super::swing::{midline_crossing, turning_points, Turn, MAX_TURNS};
use crate::math;

/// What makes a ring-down plausible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// The plausible natural frequency (rad/s).
    pub omega0_min: f64,
    pub omega0_max: f64,
    /// The largest half-swing must reach this (rad).
    pub min_amplitude: f64,
    /// Half-swings smaller than this (rad) are not used.
    pub floor: f64,
    /// Half-swings needed (8: four periods).
    pub min_half_swings: usize,
    /// Turning-point hysteresis (rad): several times the sensor's noise.
    pub hysteresis: f64,
}

impl Limits {
    /// For a pendulum configured with equivalent length `ell` (m) under gravity `g`: ω0 within
    /// a factor √2 of the configured one (ℓ within a factor 2), a first swing of at least 5°.
    pub fn for_pendulum(ell: f64, g: f64) -> Result<Self, CalibError> {
        let w0 = math::sqrt(positive("gravity", g)? / positive("equivalent length", ell)?);
        Ok(Self {
            omega0_min: w0 / math::sqrt(2.0),
            omega0_max: w0 * math::sqrt(2.0),
            min_amplitude: math::to_rad(5.0),
            floor: math::to_rad(1.0),
            min_half_swings: 8,
            hysteresis: math::to_rad(0.3),
        })
    }
}

/// What a ring-down says about the pendulum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingDown {
    /// The centre of the swing, in the sensor's reading (rad): the reading when hanging.
    pub zero: f64,
    /// Small-amplitude damped frequency ωd and natural frequency ω0 (rad/s).
    pub omega_d: f64,
    pub omega0: f64,
    /// Equivalent length ℓ = g/ω0² (m).
    pub ell: f64,
    pub decay: Decay,
    /// Quality factor ω0/c (`None` without viscous damping).
    pub q: Option<f64>,
    /// Coulomb friction μ (rad/s²; `None` without it).
    pub coulomb: Option<f64>,
    /// Half-swings used, and the largest half-height (rad).
    pub half_swings: usize,
    pub amplitude: f64,
}

/// Identifies the pendulum from samples `theta` (rad, the sensor's reading) at times `t` (s).
pub fn identify(t: &[f64], theta: &[f64], g: f64, lim: &Limits) -> Result<RingDown, CalibError> {
    identify_with(t, theta, g, lim, linear_equivalent)
}

/// [`identify`] with the decay fitted to `envelope`(h_k).
fn identify_with(
    t: &[f64],
    theta: &[f64],
    g: f64,
    lim: &Limits,
    envelope: fn(f64) -> f64,
) -> Result<RingDown, CalibError> {
    let g = positive("gravity", g)?;
    let turns = turning_points(t, theta, lim.hysteresis);
    let all = turns.as_slice();
    // The used turning points: from the first, while each half-swing stays above the floor.
    let mut n = all.len().min(1);
    while n < all.len() && (all[n].theta - all[n - 1].theta).abs() / 2.0 >= lim.floor {
        n += 1;
    }
    let turns = &all[..n];
    let found = n.saturating_sub(1);
    let amplitude = turns
        .windows(2)
        .map(|w| (w[0].theta - w[1].theta).abs() / 2.0)
        .fold(0.0, f64::max);
    if found >= 1 && amplitude < lim.min_amplitude {
        return Err(CalibError::AmplitudeTooSmall {
            amplitude,
            needed: lim.min_amplitude,
        });
    }
    if found < lim.min_half_swings.max(4) {
        return Err(CalibError::TooFewSwings {
            found,
            needed: lim.min_half_swings.max(4),
        });
    }
    let mut h = [0.0; MAX_TURNS];
    for (hk, w) in h.iter_mut().zip(turns.windows(2)) {
        *hk = (w[0].theta - w[1].theta).abs() / 2.0;
    }
    let h = &h[..found];
    let mut linear = [0.0; MAX_TURNS];
    for (l, &hk) in linear.iter_mut().zip(h) {
        *l = envelope(hk);
    }
    let decay = decay::fit(&linear[..found])?;
    let zero = centre(turns);
    // Crossings, one per half-swing.
    let half = (turns[n - 1].t - turns[0].t) / found as f64;
    let mut c = [0.0; MAX_TURNS];
    let mut nc = 0;
    for w in turns.windows(2) {
        let Some(ck) = midline_crossing(t, theta, &w[0], &w[1], half / 8.0) else {
            return Err(CalibError::TooFewSwings {
                found: nc,
                needed: found,
            });
        };
        c[nc] = ck;
        nc += 1;
    }
    let mut corrected = 0.0;
    for j in 0..nc - 1 {
        let a = (h[j] + h[j + 1]) / 2.0;
        corrected += (c[j + 1] - c[j]) * frequency_ratio(a);
    }
    let omega_d = (nc - 1) as f64 * math::PI / corrected;
    let sigma = -math::ln(decay.ratio) * omega_d / math::PI;
    let omega0 = math::sqrt(omega_d * omega_d + sigma * sigma);
    if !(lim.omega0_min..=lim.omega0_max).contains(&omega0) {
        return Err(CalibError::FrequencyImplausible {
            omega0,
            min: lim.omega0_min,
            max: lim.omega0_max,
        });
    }
    let viscous = matches!(decay.model, DecayModel::Viscous | DecayModel::Both);
    let coulomb = matches!(decay.model, DecayModel::Coulomb | DecayModel::Both);
    Ok(RingDown {
        zero,
        omega_d,
        omega0,
        ell: g / (omega0 * omega0),
        decay,
        q: (viscous && sigma > 0.0).then(|| omega0 / (2.0 * sigma)),
        coulomb: coulomb.then_some(decay.shift * omega0 * omega0),
        half_swings: found,
        amplitude,
    })
}

/// Where a record of a held-and-released pendulum starts swinging freely: the last sample of
/// the hold, found as the sample farthest from where the record ends (at rest), followed
/// forward while the reading stays within `hysteresis` of it. A record that starts before the
/// pendulum was lifted has a lift in it that is no free swing; [`identify`] wants the record
/// from here on.
pub fn release_index(theta: &[f64], hysteresis: f64) -> usize {
    let Some(&end) = theta.last() else {
        return 0;
    };
    let far = theta
        .iter()
        .enumerate()
        .fold((0, 0.0), |(k, d), (i, x)| {
            let di = (x - end).abs();
            if di > d {
                (i, di)
            } else {
                (k, d)
            }
        })
        .0;
    let held = theta[far];
    let mut k = far;
    while k + 1 < theta.len() && (theta[k + 1] - held).abs() < hysteresis {
        k += 1;
    }
    k
}

/// F(A) = A e^(−11A²/192): the swing A of the pendulum as the amplitude of the harmonic
/// oscillator whose decay [`decay`] fits (module doc).
fn linear_equivalent(a: f64) -> f64 {
    a * math::exp(-11.0 / 192.0 * a * a)
}

/// The swing's centre from the turning points (module doc).
fn centre(turns: &[Turn]) -> f64 {
    let interior = turns.len().saturating_sub(2);
    let k = interior - interior % 2;
    if k == 0 {
        return turns.iter().map(|p| p.theta).sum::<f64>() / turns.len().max(1) as f64;
    }
    let sum: f64 = turns
        .windows(3)
        .take(k)
        .map(|w| (w[0].theta + 2.0 * w[1].theta + w[2].theta) / 4.0)
        .sum();
    sum / k as f64
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::calib::bench_rig::Bench;
    use crate::calib::direction::sensor_sign;
    use crate::calib::tolerance;
    use crate::link::Request;
    use crate::model::Geometry;
    use crate::rig::config::RigConfig;
    use crate::simrig::Params;

    /// `rigs/mistyped.toml`'s bench: a 0.25 m rod typed in as 0.26 m, Q = 10, Coulomb
    /// μ = 0.3 rad/s², the sensor's zero 1.5° off, 0.05° of noise, no actuator body (the
    /// stroke's drive across the hanging rod would leave it on the body's face); let go from
    /// `release`.
    pub(crate) fn mistyped(release_deg: f64, q: f64, mu: f64, sign: f64) -> (Params, RigConfig) {
        let omega0 = math::sqrt(9.81 / (2.0 * 0.25 / 3.0));
        let p = Params {
            damping: if q > 0.0 { omega0 / q } else { 0.0 },
            coulomb: mu,
            sensor_noise: math::to_rad(0.05),
            sensor_zero: math::to_rad(1.5),
            sensor_sign: sign,
            connecting_rod: Some(0.06),
            servo_offset_deg: 2.0,
            theta0: math::to_rad(release_deg),
            body: None,
            ..Params::DEMO
        };
        let cfg = RigConfig {
            geometry: Geometry::Rod { length: 0.26 },
            amplitude: 0.0125,
            ..p.configured()
        };
        (p, cfg)
    }

    /// The ring-down as the telemetry gives it: 20 ms frames for `secs`.
    pub(crate) fn record(p: Params, cfg: RigConfig, secs: f64) -> (Vec<f64>, Vec<f64>) {
        let mut b = Bench::new(p, cfg);
        b.ask(Request::Telemetry { period_ms: 20 });
        b.run(secs);
        b.take_theta()
    }

    fn identify_on(p: Params, cfg: RigConfig, secs: f64) -> Result<RingDown, CalibError> {
        let (t, x) = record(p, cfg, secs);
        let lim = Limits::for_pendulum(cfg.ell(), cfg.gravity).unwrap();
        identify(&t, &x, cfg.gravity, &lim)
    }

    #[test]
    fn recovers_the_mistyped_rod_through_its_telemetry() {
        // Truth: ℓ = 2L/3 = 1/6 m (physics §2), Q = 10, μ = 0.3; the sensor reads −zero at the
        // bottom (simrig: reading = sign·(θ − zero)). Tolerances: calib::tolerance.
        for sign in [1.0, -1.0] {
            let (p, cfg) = mistyped(20.0, 10.0, 0.3, sign);
            let (t, x) = record(p, cfg, 15.0);
            let lim = Limits::for_pendulum(cfg.ell(), cfg.gravity).unwrap();
            let rd = identify(&t, &x, cfg.gravity, &lim).unwrap();
            let ell = 0.25 * 2.0 / 3.0;
            let zero = -sign * math::to_rad(1.5);
            eprintln!(
                "sensor sign {sign}: ℓ {:+.2} %, Q {:+.2} %, μ {:+.2} %, zero {:+.3}°",
                100.0 * (rd.ell / ell - 1.0),
                100.0 * (rd.q.unwrap_or(f64::NAN) / 10.0 - 1.0),
                100.0 * (rd.coulomb.unwrap_or(f64::NAN) / 0.3 - 1.0),
                math::to_deg(rd.zero - zero)
            );
            assert!((rd.ell / ell - 1.0).abs() < tolerance::LENGTH, "{rd:?}");
            assert_eq!(rd.decay.model, DecayModel::Both, "{rd:?}");
            assert!((rd.q.unwrap() / 10.0 - 1.0).abs() < tolerance::Q, "{rd:?}");
            assert!(
                (rd.coulomb.unwrap() / 0.3 - 1.0).abs() < tolerance::COULOMB,
                "{rd:?}"
            );
            assert!(
                math::to_deg(rd.zero - zero).abs() < tolerance::ZERO_DEG,
                "zero {} vs {}",
                math::to_deg(rd.zero),
                math::to_deg(zero)
            );
            // Let go counter-clockwise: the first reading, against the centre, gives the sign.
            assert_eq!(sensor_sign(x[0], rd.zero), Ok(sign));
        }
    }

    #[test]
    fn a_wide_swing_is_fitted_as_the_pendulum_it_is() {
        // Noise-free ring-downs from 30°, where the pendulum's decay is not a harmonic
        // oscillator's. Fitted on the raw half-heights, Q and μ come out more than 1.5 % low
        // (the effect is there to be corrected); through F(A) what is left is O(A⁴) and the
        // damping's change within a half-swing: within 1 % of the simulated truth (Q = 10,
        // μ = 0.3 rad/s²), and friction alone is told from friction plus viscous damping.
        let noiseless = |q: f64, mu: f64, envelope: fn(f64) -> f64| {
            let (p, cfg) = mistyped(30.0, q, mu, 1.0);
            let p = Params {
                sensor_noise: 0.0,
                ..p
            };
            let (t, x) = record(p, cfg, 25.0);
            let lim = Limits::for_pendulum(cfg.ell(), cfg.gravity).unwrap();
            identify_with(&t, &x, cfg.gravity, &lim, envelope).unwrap()
        };
        let off = |rd: &RingDown| {
            (
                rd.q.unwrap_or(f64::NAN) / 10.0 - 1.0,
                rd.coulomb.unwrap_or(f64::NAN) / 0.3 - 1.0,
            )
        };
        let raw = noiseless(10.0, 0.3, |a| a);
        let both = noiseless(10.0, 0.3, linear_equivalent);
        let ((q_raw, mu_raw), (q, mu)) = (off(&raw), off(&both));
        eprintln!(
            "noise-free from 30°: Q {:+.2} %, μ {:+.2} % (raw half-heights: {:+.2} %, {:+.2} %)",
            100.0 * q,
            100.0 * mu,
            100.0 * q_raw,
            100.0 * mu_raw
        );
        assert!(q_raw < -0.015 && mu_raw < -0.015, "{raw:?}");
        assert_eq!(both.decay.model, DecayModel::Both, "{both:?}");
        assert!((both.q.unwrap() / 10.0 - 1.0).abs() < 0.01, "{both:?}");
        assert!((both.coulomb.unwrap() / 0.3 - 1.0).abs() < 0.01, "{both:?}");
        let friction = noiseless(0.0, 0.3, linear_equivalent);
        assert_eq!(friction.decay.model, DecayModel::Coulomb, "{friction:?}");
        assert!(
            (friction.coulomb.unwrap() / 0.3 - 1.0).abs() < 0.01,
            "{friction:?}"
        );
        let viscous = noiseless(10.0, 0.0, linear_equivalent);
        assert_eq!(viscous.decay.model, DecayModel::Viscous, "{viscous:?}");
        assert!(
            (viscous.q.unwrap() / 10.0 - 1.0).abs() < 0.01,
            "{viscous:?}"
        );
    }

    #[test]
    fn tells_viscous_from_coulomb() {
        let (p, cfg) = mistyped(20.0, 10.0, 0.0, 1.0);
        let rd = identify_on(p, cfg, 15.0).unwrap();
        assert_eq!(rd.decay.model, DecayModel::Viscous, "{rd:?}");
        assert!((rd.q.unwrap() / 10.0 - 1.0).abs() < tolerance::Q, "{rd:?}");
        assert!(
            (rd.ell / (0.5 / 3.0) - 1.0).abs() < tolerance::LENGTH,
            "{rd:?}"
        );
        // Coulomb alone: a linear envelope, 4δ = 4μ/ω0² = 1.17° lost per period from 20°.
        let (p, cfg) = mistyped(20.0, 0.0, 0.3, 1.0);
        let rd = identify_on(p, cfg, 15.0).unwrap();
        assert_eq!(rd.decay.model, DecayModel::Coulomb, "{rd:?}");
        assert!(
            (rd.coulomb.unwrap() / 0.3 - 1.0).abs() < tolerance::COULOMB,
            "{rd:?}"
        );
        assert!(
            (rd.ell / (0.5 / 3.0) - 1.0).abs() < tolerance::LENGTH,
            "{rd:?}"
        );
    }

    #[test]
    fn refuses_implausible_ring_downs() {
        // Let go from 2°: below the 5° needed.
        let (p, cfg) = mistyped(2.0, 10.0, 0.0, 1.0);
        let e = identify_on(p, cfg, 10.0);
        assert!(
            matches!(e, Err(CalibError::AmplitudeTooSmall { .. })),
            "{e:?}"
        );
        // Two seconds: fewer than 8 half-swings.
        let (p, cfg) = mistyped(20.0, 10.0, 0.3, 1.0);
        let e = identify_on(p, cfg, 2.0);
        assert!(matches!(e, Err(CalibError::TooFewSwings { .. })), "{e:?}");
        // Configured as a 1.2 m rod: the 0.25 m rod's ω0 is 2.2 times the configured one.
        let cfg = RigConfig {
            geometry: Geometry::Rod { length: 1.2 },
            ..cfg
        };
        let e = identify_on(p, cfg, 15.0);
        assert!(
            matches!(e, Err(CalibError::FrequencyImplausible { .. })),
            "{e:?}"
        );
    }
}
