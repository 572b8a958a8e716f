//! The stroke A from the fast wobble, measured hanging (R < 1) with the drive across the
//! pendulum (θd = 90°), where the wobble is largest and a θd error barely matters.
//!
//! The wobble's amplitude, from physics §3's full equation: put θ = φ0 + ξ with φ0 the slow
//! equilibrium and ξ the small fast part, and linearise in ξ,
//!
//! ```text
//! ξ'' + c ξ' + ω0² cos φ0 · ξ = −(Aω²/ℓ) [sin(φ0 − θd) + cos(φ0 − θd) ξ] cos ωt
//! ```
//! Across the drive |sin(φ0 − θd)| = 1 and cos(φ0 − θd) = 0, so the parametric term vanishes and
//! ξ is a forced oscillation at ω. To the next order the forcing is −(Aω²/ℓ) sin(φ0 − θd) cos ξ
//! cos ωt (the exact sin(φ0 − θd + ξ) with cos(φ0 − θd) = 0); with ξ ≈ W cos(ωt − α) the
//! fundamental of cos(W cos x) cos x is J0(W) − J2(W) = 1 − 3W²/8 + 5W⁴/192 (Bessel series), so
//! the steady amplitude W solves
//!
//! ```text
//! W √[(1 − κ)² + (c/ω)²] = (A/ℓ) |sin(φ0 − θd)| (1 − 3W²/8 + 5W⁴/192),   κ = (ω0/ω)² cos φ0
//! ⇒  A = ℓ W √[(1 − κ)² + (c/ω)²] / (|sin(φ0 − θd)| (1 − 3W²/8 + 5W⁴/192))
//! ```
//! The first-order wobble (A/ℓ) sin(φ0 − θd) is the ω ≫ ω0 limit. At R = 0.5 on the demo rod
//! κ = 0.6 %, larger than A's whole 0.4 % budget, and 3W²/8 = 0.2 % (W = 0.076 rad), half of
//! it: both corrections are kept; (c/ω)² is ~5e-5.
//! W is the rig's demodulated I/Q amplitude (`rig::estimator::period`), ω the drive's reference
//! (exact: the rig generates it), ℓ and ω0 from the ring-down, φ0 − θd from the settled angle
//! and the calibrated servo.

use super::error::{positive, CalibError};
use crate::math;

/// |sin(φ0 − θd)| needed: within 25° of across the drive.
pub const MIN_SIN: f64 = 0.9;
/// ω/ω0 needed for the slow/fast separation the formula rests on.
pub const MIN_OMEGA_RATIO: f64 = 5.0;
/// Smallest wobble read (rad): far above the demodulated noise (~1e-5 rad).
pub const MIN_WOBBLE: f64 = 1e-3;

/// One wobble measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wobble {
    /// Demodulated amplitude W (rad).
    pub amplitude: f64,
    /// Drive ω (rad/s).
    pub omega: f64,
    /// φ0 − θd (rad), the settled angle from the drive line.
    pub from_drive: f64,
    /// φ0 (rad from hanging).
    pub phi0: f64,
}

/// The pendulum as the ring-down found it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pendulum {
    pub ell: f64,
    pub omega0: f64,
    /// Viscous damping c (1/s; 0 if none).
    pub damping: f64,
}

/// The stroke A (m) from a wobble measurement.
pub fn stroke(w: &Wobble, p: &Pendulum) -> Result<f64, CalibError> {
    let amp = positive("wobble", w.amplitude)?;
    let omega = positive("drive omega", w.omega)?;
    let ell = positive("equivalent length", p.ell)?;
    let omega0 = positive("omega0", p.omega0)?;
    let s = math::sin(w.from_drive).abs();
    if s < MIN_SIN {
        return Err(CalibError::NotAcrossDrive {
            sin: s,
            needed: MIN_SIN,
        });
    }
    if omega / omega0 < MIN_OMEGA_RATIO {
        return Err(CalibError::DriveTooSlow {
            ratio: omega / omega0,
            needed: MIN_OMEGA_RATIO,
        });
    }
    if amp < MIN_WOBBLE {
        return Err(CalibError::WobbleTooSmall {
            wobble: amp,
            needed: MIN_WOBBLE,
        });
    }
    let kappa = (omega0 / omega) * (omega0 / omega) * math::cos(w.phi0);
    let lin = 1.0 - kappa;
    let cw = p.damping.max(0.0) / omega;
    let w2 = amp * amp;
    let forcing = 1.0 - 3.0 * w2 / 8.0 + 5.0 * w2 * w2 / 192.0;
    Ok(ell * amp * math::sqrt(lin * lin + cw * cw) / (s * forcing))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverts_the_forced_amplitude_and_refuses_off_axis() {
        // The module doc's equation for W, solved by fixed-point iteration for A = 12.7 mm,
        // ℓ = 1/6 m, ω0² = 58.86, ω = 100, c = 0.77: the formula must give A back to rounding.
        let (a, ell, w0, c, om) = (0.0127, 1.0 / 6.0, 58.86f64.sqrt(), 0.77, 100.0);
        let lin = ((1.0 - (w0 / om).powi(2)).powi(2) + (c / om).powi(2)).sqrt();
        let mut big_w = a / ell;
        for _ in 0..20 {
            let w2: f64 = big_w * big_w;
            big_w = (a / ell) * (1.0 - 3.0 * w2 / 8.0 + 5.0 * w2 * w2 / 192.0) / lin;
        }
        let w = Wobble {
            amplitude: big_w,
            omega: om,
            from_drive: -crate::math::FRAC_PI_2,
            phi0: 0.0,
        };
        let p = Pendulum {
            ell,
            omega0: w0,
            damping: c,
        };
        assert!((stroke(&w, &p).unwrap() / a - 1.0).abs() < 1e-12);
        let off = Wobble {
            from_drive: 0.3,
            ..w
        };
        assert!(matches!(
            stroke(&off, &p),
            Err(CalibError::NotAcrossDrive { .. })
        ));
        let slow = Wobble { omega: 20.0, ..w };
        assert!(matches!(
            stroke(&slow, &p),
            Err(CalibError::DriveTooSlow { .. })
        ));
    }

    #[test]
    fn recovers_the_stroke_on_the_mistyped_rig_after_its_ring_down() {
        use crate::calib::bench_rig::Bench;
        use crate::calib::ringdown::tests::{mistyped, record};
        use crate::calib::ringdown::{identify, Limits};
        use crate::calib::tolerance;
        use crate::link::convert::from_q16;
        use crate::link::Request;
        use crate::rig::fixed::Angle;
        // The whole chain on one bench: a ring-down gives ℓ, ω0, c and the zero; then R = 0.5
        // (as configured) at θd = 90° commanded, the mount truly at 92° (the servo's offset,
        // which the servo step measures: taken as known here). Truth: A = 12.7 mm.
        let (p, cfg) = mistyped(20.0, 10.0, 0.3, 1.0);
        let (t, x) = record(p, cfg, 15.0);
        let lim = Limits::for_pendulum(cfg.ell(), cfg.gravity).unwrap();
        let rd = identify(&t, &x, cfg.gravity, &lim).unwrap();
        let mut b = Bench::new(p, cfg);
        b.ask(Request::Telemetry { period_ms: 20 });
        // The mount turned to 90° with the drive off (R = 0), then the drive started.
        b.drive(0.0, 90.0);
        b.run(15.0);
        b.drive(0.5, 90.0);
        b.run(25.0);
        let last = *b.log.last().unwrap();
        assert!(last.settled, "{last:?}");
        // The telemetry's per-period wobble, averaged over the last two seconds (100 frames).
        let quiet = &b.log[b.log.len() - 100..];
        assert!(quiet.iter().all(|t| t.settled));
        let wobble = quiet.iter().map(|t| from_q16(t.wobble)).sum::<f64>() / 100.0;
        let phi0 = Angle::from_bits(last.equilibrium.unwrap()).to_rad() - rd.zero;
        let w = Wobble {
            amplitude: wobble,
            omega: b.omega(),
            from_drive: phi0 - math::to_rad(92.0),
            phi0,
        };
        let pend = Pendulum {
            ell: rd.ell,
            omega0: rd.omega0,
            damping: rd.q.map_or(0.0, |q| rd.omega0 / q),
        };
        let a = stroke(&w, &pend).unwrap();
        eprintln!(
            "A = {a:.6} m from W = {:.5} rad at ω = {:.2} rad/s",
            w.amplitude, w.omega
        );
        assert!((a / 0.0127 - 1.0).abs() < tolerance::STROKE, "A = {a}");
        // Without the two corrections the same wobble is several times further off.
        let first_order = rd.ell * w.amplitude / math::sin(w.from_drive).abs();
        let err = |a: f64| (a / 0.0127 - 1.0).abs();
        assert!(err(first_order) > 2.0 * err(a), "{first_order} vs {a}");
    }
}
