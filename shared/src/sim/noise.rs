//! Reproducible noise without a dependency: xorshift64* (Vigna 2016) for uniform bits, the top
//! 53 of the scrambled output as a uniform in (0, 1), and Box–Muller for Gaussians (both of a
//! pair used). The same seed gives the same run, to the bit, on every machine.

use crate::math;

/// A seeded noise source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    state: u64,
    spare: Option<f64>,
}

impl Noise {
    /// A source from `seed` (0 is replaced by 1: xorshift has no zero state).
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed.max(1),
            spare: None,
        }
    }

    /// Uniform in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        let x = self.state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn gaussian(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u, v) = (self.uniform(), self.uniform());
        let r = math::sqrt(-2.0 * math::ln(u));
        let (s, c) = math::sin_cos(math::TAU * v);
        self.spare = Some(r * s);
        r * c
    }
}
