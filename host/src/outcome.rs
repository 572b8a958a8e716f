//! The simulator's verdict in user terms (degrees, kind names), and a scene's expected outcome
//! (`[expect]`) judged against it.

use serde::{Deserialize, Serialize};
use std::fmt;

use kapitza_core::math;
use kapitza_core::sim::classify::Undecided;
use kapitza_core::sim::Outcome;

/// Radians to degrees in (−180°, 180°].
pub fn deg(rad: f64) -> f64 {
    math::wrap_deg(math::to_deg(rad))
}

/// An angle in (−180°, 180°] for people, to two decimals: a value that rounds to −180.00 is
/// shown as 180.00, and −0.00 as 0.00, so the text keeps the interval's convention.
/// "1 turn", "2 turns".
fn plural(n: u32, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

pub fn show_deg(deg: f64) -> String {
    let s = format!("{deg:.2}");
    match s.as_str() {
        "-180.00" => "180.00°".to_string(),
        "-0.00" => "0.00°".to_string(),
        _ => s + "°",
    }
}

/// The outcome as `--json` prints it: `kind` plus the fields of that kind.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum OutcomeOut {
    /// At rest (in the slow sense) at the period-mean angle.
    Rest { angle_deg: f64 },
    /// Period-2 motion about `angle_deg`.
    Flutter { angle_deg: f64 },
    /// Period-`order` motion about `angle_deg`.
    Subharmonic { order: u32, angle_deg: f64 },
    /// Unidirectional rotation: `direction` +1 for increasing θ (counter-clockwise), −1 otherwise;
    /// the motion repeats every `periods` drive periods, making `turns` whole turns in them.
    Rotation {
        direction: i8,
        turns: u32,
        periods: u32,
    },
    /// Finite-time Lyapunov exponent in 1/s.
    Chaotic { lyapunov: f64 },
    /// Undamped bounded motion about `angle_deg`, half-range of the period means `amplitude_deg`.
    Oscillation { angle_deg: f64, amplitude_deg: f64 },
    /// No verdict: `reason` says why; `lyapunov` (1/s) when it was computed.
    Undecided {
        reason: String,
        lyapunov: Option<f64>,
    },
}

impl From<Outcome> for OutcomeOut {
    fn from(o: Outcome) -> Self {
        match o {
            Outcome::Rest { angle } => Self::Rest {
                angle_deg: deg(angle),
            },
            Outcome::Flutter { angle } => Self::Flutter {
                angle_deg: deg(angle),
            },
            Outcome::Subharmonic { order, angle } => Self::Subharmonic {
                order,
                angle_deg: deg(angle),
            },
            Outcome::Rotation {
                direction,
                turns,
                periods,
            } => Self::Rotation {
                direction,
                turns,
                periods,
            },
            Outcome::Chaotic { lyapunov } => Self::Chaotic { lyapunov },
            Outcome::Oscillation { angle, amplitude } => Self::Oscillation {
                angle_deg: deg(angle),
                amplitude_deg: math::to_deg(amplitude),
            },
            Outcome::Undecided { reason } => Self::Undecided {
                reason: reason.to_string(),
                lyapunov: match reason {
                    Undecided::NeitherPeriodicNorChaotic { lyapunov } => Some(lyapunov),
                    _ => None,
                },
            },
        }
    }
}

impl OutcomeOut {
    pub fn kind(&self) -> ExpectKind {
        match self {
            Self::Rest { .. } => ExpectKind::Rest,
            Self::Flutter { .. } => ExpectKind::Flutter,
            Self::Subharmonic { .. } => ExpectKind::Subharmonic,
            Self::Rotation { .. } => ExpectKind::Rotation,
            Self::Chaotic { .. } => ExpectKind::Chaotic,
            Self::Oscillation { .. } => ExpectKind::Oscillation,
            Self::Undecided { .. } => ExpectKind::Undecided,
        }
    }

    /// The angle the motion rests at or is centred on (degrees), if it has one.
    pub fn angle_deg(&self) -> Option<f64> {
        match *self {
            Self::Rest { angle_deg }
            | Self::Flutter { angle_deg }
            | Self::Subharmonic { angle_deg, .. }
            | Self::Oscillation { angle_deg, .. } => Some(angle_deg),
            _ => None,
        }
    }
}

impl fmt::Display for OutcomeOut {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Rest { angle_deg } => write!(f, "rest at {}", show_deg(*angle_deg)),
            Self::Flutter { angle_deg } => {
                write!(f, "flutter (period 2) about {}", show_deg(*angle_deg))
            }
            Self::Subharmonic { order, angle_deg } => {
                write!(
                    f,
                    "subharmonic of order {order} about {}",
                    show_deg(*angle_deg)
                )
            }
            Self::Rotation {
                direction,
                turns,
                periods,
            } => write!(
                f,
                "rotation {} (θ {}), {} every {}",
                if *direction > 0 {
                    "counter-clockwise"
                } else {
                    "clockwise"
                },
                if *direction > 0 {
                    "increasing"
                } else {
                    "decreasing"
                },
                plural(*turns, "turn"),
                plural(*periods, "drive period")
            ),
            Self::Chaotic { lyapunov } => {
                write!(f, "chaotic tumbling, Lyapunov exponent {lyapunov:.3} 1/s")
            }
            Self::Oscillation {
                angle_deg,
                amplitude_deg,
            } => write!(
                f,
                "undamped oscillation about {} (±{amplitude_deg:.2}°)",
                show_deg(*angle_deg)
            ),
            Self::Undecided { reason, .. } => write!(f, "undecided: {reason}"),
        }
    }
}

/// The outcome kinds a scene may expect.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExpectKind {
    Rest,
    Flutter,
    Subharmonic,
    Rotation,
    Chaotic,
    Oscillation,
    Undecided,
}

impl ExpectKind {
    pub fn name(self) -> &'static str {
        match self {
            Self::Rest => "rest",
            Self::Flutter => "flutter",
            Self::Subharmonic => "subharmonic",
            Self::Rotation => "rotation",
            Self::Chaotic => "chaotic",
            Self::Oscillation => "oscillation",
            Self::Undecided => "undecided",
        }
    }

    /// Whether outcomes of this kind carry an angle.
    pub fn has_angle(self) -> bool {
        matches!(
            self,
            Self::Rest | Self::Flutter | Self::Subharmonic | Self::Oscillation
        )
    }
}

/// A scene's `[expect]` table, checked.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Expect {
    pub kind: ExpectKind,
    /// The angle (degrees) for kinds that have one.
    pub angle_deg: Option<f64>,
    /// Largest accepted |wrap(got − expected)| in degrees.
    pub tolerance_deg: f64,
    /// Subharmonic order.
    pub order: Option<u32>,
    /// Rotation direction, +1 or −1.
    pub direction: Option<i8>,
}

/// An expectation and whether the run met it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Judged {
    #[serde(flatten)]
    pub expect: Expect,
    pub met: bool,
    /// Why not, when not met.
    pub why_not: Option<String>,
}

impl Expect {
    pub fn judge(&self, got: &OutcomeOut) -> Judged {
        let why_not = self.mismatch(got);
        Judged {
            expect: self.clone(),
            met: why_not.is_none(),
            why_not,
        }
    }

    fn mismatch(&self, got: &OutcomeOut) -> Option<String> {
        if got.kind() != self.kind {
            return Some(format!("expected {}, got {got}", self.kind.name()));
        }
        if let (Some(want), Some(have)) = (self.angle_deg, got.angle_deg()) {
            let off = math::wrap_deg(have - want);
            if off.abs() > self.tolerance_deg {
                return Some(format!(
                    "angle {have:.3}° is {:.3}° from the expected {want}° (tolerance {}°)",
                    off.abs(),
                    self.tolerance_deg
                ));
            }
        }
        match (got, self.order, self.direction) {
            (OutcomeOut::Subharmonic { order, .. }, Some(want), _) if *order != want => {
                Some(format!("order {order}, expected {want}"))
            }
            (OutcomeOut::Rotation { direction, .. }, _, Some(want)) if *direction != want => {
                Some(format!("direction {direction:+}, expected {want:+}"))
            }
            _ => None,
        }
    }
}

impl fmt::Display for Expect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind.name())?;
        if let Some(n) = self.order {
            write!(f, " of order {n}")?;
        }
        if let Some(a) = self.angle_deg {
            write!(f, " at {a}° ± {}°", self.tolerance_deg)?;
        }
        if let Some(d) = self.direction {
            write!(f, ", direction {d:+}")?;
        }
        Ok(())
    }
}
