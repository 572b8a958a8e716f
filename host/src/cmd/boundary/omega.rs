//! `kapitza boundary --rod L --amplitude A`: the window of drive frequencies ω in which a given
//! stroke holds the rod upside down (undamped, exact).
//!
//! At fixed m = A/ℓ (q = 2m) the inverted position is stable exactly for a₀(q) < 4k < b₁(q)
//! with k = −g/(ℓω²) < 0 (`kapitza_core::stability::hill`), so
//!
//! ```text
//! ω_low  = √(−4g / (ℓ a₀(q)))                   below it the rod falls
//! ω_high = √(−4g / (ℓ b₁(q)))  if b₁(q) < 0       above it it flutters (period 2); none if b₁ ≥ 0
//! ```

use anyhow::Result;
use serde::Serialize;
use std::io::Write;

use kapitza_core::stability::hill;

/// The `--json` output of the frequency window.
#[derive(Debug, Serialize)]
pub struct OmegaWindow {
    pub equivalent_length: f64,
    pub amplitude: f64,
    pub gravity: f64,
    /// m = A/ℓ.
    pub m: f64,
    /// ωc = √(2gℓ)/A (rad/s): averaging's threshold, R = (ω/ωc)² > 1.
    pub omega_c: f64,
    pub lower: Frequency,
    /// `null` when the stroke never flutters (b₁(2m) ≥ 0: m below 0.454).
    pub upper: Option<Frequency>,
}

/// One frequency in the units people use.
#[derive(Debug, Serialize)]
pub struct Frequency {
    pub omega: f64,
    pub hz: f64,
    pub rpm: f64,
}

fn frequency(omega: f64) -> Frequency {
    Frequency {
        omega,
        hz: omega / std::f64::consts::TAU,
        rpm: omega * 60.0 / std::f64::consts::TAU,
    }
}

pub fn compute(ell: f64, amplitude: f64, gravity: f64) -> Result<OmegaWindow> {
    let m = amplitude / ell;
    if m > kapitza_core::stability::M_MAX {
        anyhow::bail!("--amplitude {amplitude} is out of range: A/ℓ must be <= 25");
    }
    let q = 2.0 * m;
    let a0 = hill::eigenvalue(0.0, q, 0);
    let b1 = hill::eigenvalue(1.0, q, 0);
    let omega_for = |a: f64| (-4.0 * gravity / (ell * a)).sqrt();
    Ok(OmegaWindow {
        equivalent_length: ell,
        amplitude,
        gravity,
        m,
        omega_c: (2.0 * gravity * ell).sqrt() / amplitude,
        lower: frequency(omega_for(a0)),
        upper: (b1 < 0.0).then(|| frequency(omega_for(b1))),
    })
}

pub fn print(w: &OmegaWindow, out: &mut dyn Write) -> Result<()> {
    writeln!(
        out,
        "pendulum: ℓ = {:.4} m, stroke A = {} m (m = A/ℓ = {:.4}); inverted position, undamped",
        w.equivalent_length, w.amplitude, w.m
    )?;
    let f = |x: &Frequency| format!("{:.2} rad/s = {:.2} Hz = {:.0} rpm", x.omega, x.hz, x.rpm);
    writeln!(out, "stands upside down above ω = {}", f(&w.lower))?;
    match &w.upper {
        Some(u) => writeln!(out, "starts to flutter (period 2) above ω = {}", f(u))?,
        None => writeln!(
            out,
            "does not flutter at any ω with this stroke (m < 0.454)"
        )?,
    }
    writeln!(
        out,
        "ωc = √(2gℓ)/A = {:.2} rad/s: the averaged theory's threshold (R = (ω/ωc)² > 1); the exact one above is higher",
        w.omega_c
    )?;
    Ok(())
}
