//! What the pendulum ends up doing, from stroboscopic samples (once per drive period).
//!
//! ```text
//! strobe k: (θ_k, θ'_k) at drive phase 2πk, and m_k = the mean of θ over the period ending there
//! F: the final half of the analysis window (≥ 32 strobes)
//! rest:        over F, range of θ_k ≤ TOL and range of θ'_k/ω ≤ TOL; angle = mean of the m_k
//! d(j, k):     max(|wrap(θ_j − θ_k)|, |θ'_j − θ'_k|/ω), the distance of two strobed states
//! period p:    over F, d(k, k−p) ≤ TOL
//!   turning (θ_k − θ_{k−p} = 2πq, q ≠ 0) → rotation (sign of q)
//!   p = 2, the two points apart (d(k, k−1) > TOL) → flutter
//!   p ≥ 3, the p points distinct (some d(k, k−1) > 5·TOL) → subharmonic of order p
//! otherwise:   still contracting → undecided (run longer); finite-time Lyapunov exponent with
//!   growth e^{λ T_F} > e^5 → chaotic; undamped and bounded → oscillation: centre and half the
//!   range of the period means (the middle of the range, not their mean)
//! ```
//! TOL = 2e-3 rad (0.11°) is the resolution of the physical question (a resting angle to 0.1°).
//! F spans many drive periods, so a slow oscillation is seen whole rather than at a turning
//! point; the distinct-points rule keeps a decaying slow oscillation whose period is close to p
//! drive periods from passing for a subharmonic.
//!
//! Distances are taken on the whole strobed state, not on θ alone: with a purely sinusoidal
//! drive, θd and θd + 180° are the same shaking line half a drive period apart, so the same
//! period-2 orbit is strobed at the other half of its cycle, where its two points may share
//! their angle and differ only in rate. Flutter's threshold is the rest threshold TOL: a period-2
//! motion that is not rest is flutter, however small, so a run at the flutter onset cannot fall
//! between the two verdicts.
//! The classifier judges the true state, never the sensor's view of it.

use crate::math;

/// Strobes kept for analysis.
pub const WINDOW: usize = 1024;
/// Fewest strobes from which a verdict is given.
pub const MIN_STROBES: usize = 64;
/// Longest period (in drive periods) looked for.
pub const MAX_ORDER: usize = 16;
/// Rest and periodicity tolerance on θ (rad) and on θ'/ω.
pub const TOL: f64 = 2e-3;

/// One stroboscopic sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Strobe {
    /// θ at drive phase 2πk, unwrapped (as integrated).
    pub theta: f64,
    pub rate: f64,
    /// Mean of θ over the drive period ending here (unwrapped).
    pub mean: f64,
}

/// The verdict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// At rest in the slow sense: the period-mean angle (rad, in (−π, π]).
    Rest {
        angle: f64,
    },
    /// Period-2 motion about a centre angle.
    Flutter {
        angle: f64,
    },
    /// Period-n motion about a centre angle.
    Subharmonic {
        order: u32,
        angle: f64,
    },
    /// Unidirectional rotation: +1 counter-clockwise (θ increasing), −1 otherwise; the motion
    /// repeats every `periods` drive periods, in which it makes `turns` whole turns (a period-2
    /// orbit may turn once or twice in its two periods).
    Rotation {
        direction: i8,
        turns: u32,
        periods: u32,
    },
    /// Positive finite-time Lyapunov exponent (1/s).
    Chaotic {
        lyapunov: f64,
    },
    /// Undamped bounded motion about a centre (rad), with half its range of period means (rad).
    Oscillation {
        angle: f64,
        amplitude: f64,
    },
    Undecided {
        reason: Undecided,
    },
}

/// Why no verdict was given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Undecided {
    TooShort {
        strobes: usize,
    },
    StillSettling,
    NeitherPeriodicNorChaotic {
        lyapunov: f64,
    },
    /// The run was asked not to classify (`Options::classify = false`).
    NotClassified,
}

impl core::fmt::Display for Undecided {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Undecided::TooShort { strobes } => {
                write!(f, "run too short: {strobes} drive periods, at least {MIN_STROBES} needed")
            }
            Undecided::StillSettling => f.write_str("still settling at the end of the run: run longer"),
            Undecided::NotClassified => f.write_str("not classified (the run was asked only to integrate)"),
            Undecided::NeitherPeriodicNorChaotic { lyapunov } => write!(
                f,
                "neither periodic (to {TOL} rad) nor clearly chaotic (λ = {lyapunov:.3e} 1/s) over the analysis window"
            ),
        }
    }
}

/// A ring buffer of the last [`WINDOW`] strobes.
#[derive(Debug, Clone)]
pub struct Strobes {
    buf: [Strobe; WINDOW],
    head: usize,
    len: usize,
}

impl Default for Strobes {
    fn default() -> Self {
        Self {
            buf: [Strobe::default(); WINDOW],
            head: 0,
            len: 0,
        }
    }
}

impl Strobes {
    pub fn push(&mut self, s: Strobe) {
        self.buf[self.head] = s;
        self.head = (self.head + 1) % WINDOW;
        self.len = (self.len + 1).min(WINDOW);
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The i-th kept strobe, oldest first.
    pub fn get(&self, i: usize) -> Strobe {
        self.buf[(self.head + WINDOW - self.len + i) % WINDOW]
    }

    fn last(&self, back: usize) -> Strobe {
        self.get(self.len - 1 - back)
    }
}

/// Classifies the kept strobes. `omega` is the drive frequency at the end of the run (to scale
/// rates); `undamped` says whether bounded non-periodic motion may persist; `lyapunov` computes
/// the finite-time Lyapunov exponent on demand (it costs a second run).
pub fn classify(
    strobes: &Strobes,
    omega: f64,
    undamped: bool,
    lyapunov: impl FnOnce() -> f64,
) -> Outcome {
    let n = strobes.len();
    if n < MIN_STROBES {
        return Outcome::Undecided {
            reason: Undecided::TooShort { strobes: n },
        };
    }
    let half = n / 2;
    let range = |f: &dyn Fn(Strobe) -> f64| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for back in 0..half {
            let x = f(strobes.last(back));
            lo = lo.min(x);
            hi = hi.max(x);
        }
        hi - lo
    };
    let reference = strobes.last(0).theta;
    let centre =
        |p: usize| math::wrap_pi((0..p).map(|i| strobes.last(i).mean).sum::<f64>() / p as f64);
    // Unwrapped: a rotation of exactly one turn per period has equal *wrapped* strobes.
    if range(&|s| s.theta - reference) <= TOL && range(&|s| s.rate / omega) <= TOL {
        return Outcome::Rest {
            angle: centre(half.min(64)),
        };
    }
    if let Some(p) = (1..=MAX_ORDER).find(|&p| periodic(strobes, p, half, omega)) {
        let turn = strobes.last(0).theta - strobes.last(p).theta;
        if turn.abs() > math::PI {
            return Outcome::Rotation {
                direction: if turn > 0.0 { 1 } else { -1 },
                turns: libm::round(turn.abs() / math::TAU) as u32,
                periods: p as u32,
            };
        }
        let threshold = if p == 2 { TOL } else { 5.0 * TOL };
        let distinct =
            (0..p).any(|i| distance(strobes.last(i), strobes.last(i + 1), omega) > threshold);
        if p >= 2 && distinct {
            return match p {
                2 => Outcome::Flutter { angle: centre(2) },
                _ => Outcome::Subharmonic {
                    order: p as u32,
                    angle: centre(p),
                },
            };
        }
    }
    // Spread of the strobe states in each half of the window: contracting means transient.
    let spread = |from: usize, to: usize| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in from..to {
            let s = strobes.get(i);
            lo = lo.min(s.theta);
            hi = hi.max(s.theta);
        }
        hi - lo
    };
    let drifting = (strobes.last(0).mean - strobes.get(0).mean).abs() > math::TAU;
    if !undamped && !drifting && spread(half, n) < 0.5 * spread(0, half) {
        return Outcome::Undecided {
            reason: Undecided::StillSettling,
        };
    }
    let lambda = lyapunov();
    // Chaotic when a perturbation grows by at least e^5 over the window.
    let window_time = n as f64 * math::TAU / omega;
    if lambda * window_time > 5.0 {
        return Outcome::Chaotic { lyapunov: lambda };
    }
    if undamped && !drifting {
        // The centre is the middle of the range: the mean over a window that does not hold a
        // whole number of slow oscillations is biased by the part-cycle at its end.
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..n {
            let m = strobes.get(i).mean;
            lo = lo.min(m);
            hi = hi.max(m);
        }
        return Outcome::Oscillation {
            angle: math::wrap_pi(0.5 * (lo + hi)),
            amplitude: 0.5 * (hi - lo),
        };
    }
    Outcome::Undecided {
        reason: Undecided::NeitherPeriodicNorChaotic { lyapunov: lambda },
    }
}

/// Whether the strobes repeat with period p over the last `span` of them.
fn periodic(strobes: &Strobes, p: usize, span: usize, omega: f64) -> bool {
    if span <= p {
        return false;
    }
    (0..span - p).all(|back| distance(strobes.last(back), strobes.last(back + p), omega) <= TOL)
}

/// max(|wrap(Δθ)|, |Δθ'|/ω): how far apart two strobed states are.
fn distance(a: Strobe, b: Strobe, omega: f64) -> f64 {
    math::wrap_pi(a.theta - b.theta)
        .abs()
        .max((a.rate - b.rate).abs() / omega)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fill(f: impl Fn(usize) -> Strobe, n: usize) -> Strobes {
        let mut s = Strobes::default();
        for k in 0..n {
            s.push(f(k));
        }
        s
    }

    const W: f64 = 100.0;
    fn no_lyapunov() -> f64 {
        panic!("periodic cases must not need the Lyapunov exponent")
    }

    #[test]
    fn synthetic_outcomes() {
        let at = |o: Outcome| match o {
            Outcome::Rest { angle } | Outcome::Flutter { angle } => angle,
            other => panic!("{other:?}"),
        };
        // Centres are means of 64 period means: equal to the input up to rounding (1e-12).
        let rest = fill(
            |_| Strobe {
                theta: 1.0,
                rate: 0.0,
                mean: 0.96,
            },
            200,
        );
        assert!((at(classify(&rest, W, false, no_lyapunov)) - 0.96).abs() < 1e-12);
        let flutter = fill(
            |k| Strobe {
                theta: 3.0 + 0.1 * (-1f64).powi(k as i32),
                rate: 0.0,
                mean: 3.1,
            },
            200,
        );
        // A tiny residual wobble below TOL is rest, not flutter.
        let calm = fill(
            |k| Strobe {
                theta: 3.0 + 1e-4 * (-1f64).powi(k as i32),
                rate: 0.0,
                mean: 3.1,
            },
            200,
        );
        assert!(matches!(
            classify(&calm, W, false, no_lyapunov),
            Outcome::Rest { .. }
        ));
        assert!(matches!(
            classify(&flutter, W, false, no_lyapunov),
            Outcome::Flutter { .. }
        ));
        assert!((at(classify(&flutter, W, false, no_lyapunov)) - 3.1).abs() < 1e-12);
        let sub = fill(
            |k| Strobe {
                theta: (k % 5) as f64 * 0.05,
                rate: 0.0,
                mean: 0.02,
            },
            200,
        );
        assert!(matches!(
            classify(&sub, W, false, no_lyapunov),
            Outcome::Subharmonic { order: 5, .. }
        ));
        // One turn per period is rotation, not rest (its wrapped strobes are all equal).
        let spin = fill(
            |k| Strobe {
                theta: 0.3 + k as f64 * math::TAU,
                rate: 15.0,
                mean: 0.0,
            },
            200,
        );
        assert_eq!(
            classify(&spin, W, false, no_lyapunov),
            Outcome::Rotation {
                direction: 1,
                turns: 1,
                periods: 1
            }
        );
        // Two turns in two periods, the second faster: period 2, not 1.
        let uneven = fill(
            |k| Strobe {
                theta: k as f64 * math::TAU + if k % 2 == 0 { 0.0 } else { 0.5 },
                rate: 15.0 + (k % 2) as f64,
                mean: 0.0,
            },
            200,
        );
        assert_eq!(
            classify(&uneven, W, false, no_lyapunov),
            Outcome::Rotation {
                direction: 1,
                turns: 2,
                periods: 2
            }
        );
        // One turn clockwise every 2 periods.
        let rot = fill(
            |k| Strobe {
                theta: -(k as f64) * math::PI,
                rate: -3.0,
                mean: 0.0,
            },
            200,
        );
        assert_eq!(
            classify(&rot, W, false, no_lyapunov),
            Outcome::Rotation {
                direction: -1,
                turns: 1,
                periods: 2
            }
        );
    }

    #[test]
    fn oscillation_centre_is_the_middle_of_its_range() {
        // 2.3 slow cycles of 1 ± 0.3 rad in the window: the centre is 1 and the half-range 0.3
        // (closed form), up to the sampling of the extremes, 0.3 (1 − cos(π·2.3/1000)) < 1e-5;
        // the mean of the samples would be off by the part-cycle, 0.3 sin(2π·2.3)/(2π·2.3) ≈ 0.02.
        let n = 1000;
        let slow = |k: usize| 1.0 + 0.3 * (math::TAU * 2.3 * k as f64 / n as f64).cos();
        let s = fill(
            |k| Strobe {
                theta: slow(k),
                rate: 0.0,
                mean: slow(k),
            },
            n,
        );
        match classify(&s, W, true, || 0.0) {
            Outcome::Oscillation { angle, amplitude } => {
                assert!((angle - 1.0).abs() < 1e-5, "{angle}");
                assert!((amplitude - 0.3).abs() < 1e-5, "{amplitude}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn flutter_seen_in_either_phase() {
        // The flutter scene's orbit strobed half a drive period later (θd = 0 instead of 180°,
        // `kapitza simulate scenes/flutter.toml --set drive.angle_deg=0 --out DIR`, strobes.csv):
        // its two points differ by 2.5e-3 rad in angle but by 78 rad/s in rate (0.26 at ω = 300);
        // the centre (the mean of the period means, here 3.0) is placed away from ±π.
        let w = 300.0;
        let shifted = fill(
            |k| {
                let s = (-1f64).powi(k as i32);
                Strobe {
                    theta: 3.0 + 1.26e-3 * s,
                    rate: 39.19 * s,
                    mean: 3.0 - 0.227 * s,
                }
            },
            200,
        );
        match classify(&shifted, w, false, no_lyapunov) {
            Outcome::Flutter { angle } => assert!((angle - 3.0).abs() < 1e-12, "{angle}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn no_gap_between_rest_and_flutter() {
        // Period-2 strobes whose spread grows through the rest tolerance: every one is rest
        // (spread ≤ TOL) or flutter (spread > TOL), never undecided.
        for spread in [0.5, 0.99, 1.01, 1.5, 3.0, 4.9, 5.1, 10.0].map(|f| f * TOL) {
            let s = fill(
                |k| Strobe {
                    theta: 3.0 + 0.5 * spread * (-1f64).powi(k as i32),
                    rate: 0.0,
                    mean: 3.0,
                },
                200,
            );
            let got = classify(&s, W, false, no_lyapunov);
            let want_rest = spread <= TOL;
            assert!(
                matches!(got, Outcome::Rest { .. }) == want_rest
                    && matches!(got, Outcome::Flutter { .. }) != want_rest,
                "spread {spread}: {got:?}"
            );
        }
    }

    #[test]
    fn undecided_when_short_or_settling() {
        let short = fill(|_| Strobe::default(), 10);
        assert!(matches!(
            classify(&short, W, false, no_lyapunov),
            Outcome::Undecided { .. }
        ));
        // A decaying spiral that has not converged to TOL.
        let settling = fill(
            |k| {
                let a = 0.5 * (-(k as f64) / 40.0).exp();
                Strobe {
                    theta: a * (0.3 * k as f64).cos(),
                    rate: 0.0,
                    mean: 0.0,
                }
            },
            300,
        );
        assert_eq!(
            classify(&settling, W, false, no_lyapunov),
            Outcome::Undecided {
                reason: Undecided::StillSettling
            }
        );
    }

    #[test]
    fn chaos_needs_growth() {
        let noisy = fill(
            |k| Strobe {
                theta: ((k * 7919) % 101) as f64 * 0.05,
                rate: 0.0,
                mean: 0.0,
            },
            500,
        );
        let window = 500.0 * math::TAU / W;
        assert!(matches!(
            classify(&noisy, W, false, || 10.0 / window),
            Outcome::Chaotic { .. }
        ));
        assert!(matches!(
            classify(&noisy, W, false, || 1.0 / window),
            Outcome::Undecided { .. }
        ));
        assert!(matches!(
            classify(&noisy, W, true, || 0.0),
            Outcome::Oscillation { .. }
        ));
    }
}
