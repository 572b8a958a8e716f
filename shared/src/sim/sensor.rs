//! The pivot encoder as the rig sees the pendulum: sampled, noisy, quantised.
//!
//! ```text
//! measured = q(θ + n),   n ~ N(0, σ²),   q(x) = round(x · 2^bits / 2π) · 2π / 2^bits, wrapped to (−π, π]
//! ```
//! Noise comes from a seeded generator ([`Noise`]), so a run is reproducible to the bit.

use super::noise::Noise;
use super::scene::Sensor;
use crate::math;

/// The sensor model with its noise generator.
#[derive(Debug, Clone)]
pub struct Encoder {
    spec: Sensor,
    noise: Noise,
}

impl Encoder {
    pub fn new(spec: Sensor, seed: u64) -> Self {
        Self {
            spec,
            noise: Noise::new(seed),
        }
    }

    /// Seconds between samples.
    pub fn interval(&self) -> f64 {
        1.0 / self.spec.rate_hz
    }

    /// What the encoder reports for the true angle θ (rad).
    pub fn measure(&mut self, theta: f64) -> f64 {
        let noisy = theta + self.spec.noise * self.noise.gaussian();
        let counts = libm::ldexp(1.0, self.spec.bits as i32);
        let lsb = math::TAU / counts;
        math::wrap_pi(libm::round(noisy / lsb) * lsb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantises_and_adds_noise_of_the_stated_size() {
        // Without noise a 12-bit encoder rounds to multiples of 2π/4096 (closed form).
        let mut e = Encoder::new(
            Sensor {
                bits: 12,
                noise: 0.0,
                rate_hz: 1000.0,
            },
            1,
        );
        let lsb = math::TAU / 4096.0;
        let m = e.measure(0.3);
        assert!((m / lsb - libm::round(m / lsb)).abs() < 1e-9 && (m - 0.3).abs() <= 0.5 * lsb);
        // With σ = 0.01 rad and a fine encoder, the sample standard deviation of 20 000 draws is
        // σ within 3 % (the standard error of a standard deviation is σ/√(2n) ≈ 0.5 %).
        let mut e = Encoder::new(
            Sensor {
                bits: 24,
                noise: 0.01,
                rate_hz: 1000.0,
            },
            42,
        );
        let n = 20_000;
        let xs: std::vec::Vec<f64> = (0..n).map(|_| e.measure(1.0) - 1.0).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        assert!(mean.abs() < 3.0 * 0.01 / (n as f64).sqrt() + 1e-6);
        assert!((sd / 0.01 - 1.0).abs() < 0.03, "sd {sd}");
    }
}
