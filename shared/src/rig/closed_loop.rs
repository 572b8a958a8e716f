//! The settings of closing the loop on R: holding the R the estimator measures at the one
//! asked for by trimming ω. Carried and stored with the configuration; off by default.

use crate::error::ParamError;

/// Closed-loop R: whether it runs, the band it leaves alone, and how fast it may move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedLoopR {
    pub enabled: bool,
    /// |R_measured − R_asked| below this is left alone (dimensionless, ≥ 0).
    pub band: f64,
    /// The fastest the trimmed R may change (1/s, > 0).
    pub rate_max: f64,
}

impl ClosedLoopR {
    /// Off, with a band of 0.05 in R and at most 0.1 R a second when switched on.
    pub const DEFAULT: Self = Self {
        enabled: false,
        band: 0.05,
        rate_max: 0.1,
    };

    /// Band in [0, 10), rate in (0, 100] per second; checked whether enabled or not, so what
    /// is stored is always usable.
    pub fn validate(&self) -> Result<(), ParamError> {
        if !(self.band.is_finite() && (0.0..10.0).contains(&self.band)) {
            return Err(ParamError {
                name: "closed_loop_band",
                value: self.band,
                allowed: "in [0, 10) (R)",
            });
        }
        if !(self.rate_max.is_finite() && self.rate_max > 0.0 && self.rate_max <= 100.0) {
            return Err(ParamError {
                name: "closed_loop_rate_max",
                value: self.rate_max,
                allowed: "in (0, 100] R per second",
            });
        }
        Ok(())
    }
}
