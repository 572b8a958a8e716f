//! Cost at a matched error, and the ratio of ours to the peer's.
//!
//! A method's work-precision curve is its points in order of evaluations. Its cost at a target
//! error is read where the curve first reaches the target, walking from the cheapest point:
//!
//! ```text
//! first point with error ≤ target is point j
//! j = 0 (the cheapest setting already meets it):  cost = cost_0                (an upper bound)
//! j > 0:  interpolate log cost linearly in log error between points j−1 and j:
//!         s = (ln target − ln e_{j−1}) / (ln e_j − ln e_{j−1}),
//!         cost = exp(ln c_{j−1} + s (ln c_j − ln c_{j−1}))
//! no point reaches it:  no cost
//! ```
//! Cost is the median wall time or the evaluation count; both are read at the same error. The
//! best of a side is the least cost over its methods (separately for time and evaluations, so
//! the two may name different methods); the ratio is ours over the peer's.

use serde::Serialize;

use super::measure::{Family, Point};
use kapitza_core::sim::Format;

/// What a cost is measured in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cost {
    /// Median wall time.
    Time,
    /// Median CPU time of the measuring thread.
    Cpu,
    Evals,
}

fn cost(p: &Point, c: Cost) -> f64 {
    match c {
        Cost::Time => p.wall_s,
        Cost::Cpu => p.cpu_s,
        Cost::Evals => p.rhs_evals as f64,
    }
}

/// A method's cost at a target error.
#[derive(Debug, Clone, Serialize)]
pub struct AtTarget {
    /// Family and format, e.g. "DOP853 f64".
    pub method: String,
    pub cost: f64,
    /// Read between two measured points (else the cheapest point already met the target and
    /// its cost is an upper bound).
    pub interpolated: bool,
}

/// The cost of one curve (points of one family and format, any order) at `target`.
pub fn cost_at(curve: &[&Point], target: f64, c: Cost) -> Option<(f64, bool)> {
    let mut pts: Vec<&Point> = curve.to_vec();
    pts.sort_by_key(|a| a.rhs_evals);
    let j = pts.iter().position(|p| p.error <= target)?;
    if j == 0 {
        return Some((cost(pts[0], c), false));
    }
    let (a, b) = (pts[j - 1], pts[j]);
    let (ea, eb) = (a.error.ln(), b.error.max(1e-300).ln());
    let (ca, cb) = (cost(a, c).ln(), cost(b, c).ln());
    if eb >= ea {
        return Some((cost(b, c), false));
    }
    let s = (target.ln() - ea) / (eb - ea);
    Some(((ca + s * (cb - ca)).exp(), true))
}

/// The curves of a scene: points grouped by (family, format).
pub fn curves<'p>(points: &'p [Point], scene: &str) -> Vec<((Family, Format), Vec<&'p Point>)> {
    let mut out: Vec<((Family, Format), Vec<&Point>)> = Vec::new();
    for p in points.iter().filter(|p| p.scene == scene) {
        let key = (p.family, p.format);
        match out.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(p),
            None => out.push((key, vec![p])),
        }
    }
    out
}

pub fn curve_label(family: Family, format: Format) -> String {
    if family.is_peer() {
        family.label().to_string()
    } else {
        format!("{} {format}", family.label())
    }
}

/// The least cost over the curves that `pick` selects.
pub fn best(
    points: &[Point],
    scene: &str,
    target: f64,
    c: Cost,
    pick: impl Fn(Family) -> bool,
) -> Option<AtTarget> {
    curves(points, scene)
        .into_iter()
        .filter(|((f, _), _)| pick(*f))
        .filter_map(|((f, fmt), pts)| {
            cost_at(&pts, target, c).map(|(cost, interpolated)| AtTarget {
                method: curve_label(f, fmt),
                cost,
                interpolated,
            })
        })
        .min_by(|a, b| a.cost.total_cmp(&b.cost))
}

/// Ours over the peer's at one scene and target error.
#[derive(Debug, Clone, Serialize)]
pub struct PeerRatio {
    pub scene: String,
    pub target_error: f64,
    /// Our best full-model time over the peer's best time; `null` if either side never reached
    /// the target.
    pub time_ratio: Option<f64>,
    /// The same for evaluations.
    pub evals_ratio: Option<f64>,
    /// The same for the measuring thread's CPU time (steadier than wall time on a busy machine).
    pub cpu_ratio: Option<f64>,
    pub ours_time: Option<AtTarget>,
    pub peer_time: Option<AtTarget>,
    pub ours_evals: Option<AtTarget>,
    pub peer_evals: Option<AtTarget>,
    pub ours_cpu: Option<AtTarget>,
    pub peer_cpu: Option<AtTarget>,
    /// Beside the ratio, not in it: the averaged model's cost when it reaches the target (its
    /// error against the full model's reference is the model error).
    pub averaged_time: Option<AtTarget>,
}

/// Ours over the peer's best at `target`. `workaround`: whether the peer's Dop853 in autonomous
/// form counts (the strict comparison); without it, the peer as published.
pub fn peer_ratio(points: &[Point], scene: &str, target: f64, workaround: bool) -> PeerRatio {
    let ours = |f: Family| f.is_full_model() && !f.is_peer();
    let peer = |f: Family| f.is_peer() && (workaround || f != Family::PeerDop853Autonomous);
    let ours_time = best(points, scene, target, Cost::Time, ours);
    let peer_time = best(points, scene, target, Cost::Time, peer);
    let ours_evals = best(points, scene, target, Cost::Evals, ours);
    let peer_evals = best(points, scene, target, Cost::Evals, peer);
    let ours_cpu = best(points, scene, target, Cost::Cpu, ours);
    let peer_cpu = best(points, scene, target, Cost::Cpu, peer);
    let ratio = |a: &Option<AtTarget>, b: &Option<AtTarget>| {
        a.as_ref().zip(b.as_ref()).map(|(a, b)| a.cost / b.cost)
    };
    PeerRatio {
        scene: scene.to_string(),
        target_error: target,
        time_ratio: ratio(&ours_time, &peer_time),
        evals_ratio: ratio(&ours_evals, &peer_evals),
        cpu_ratio: ratio(&ours_cpu, &peer_cpu),
        averaged_time: best(points, scene, target, Cost::Time, |f| !f.is_full_model()),
        ours_time,
        peer_time,
        ours_evals,
        peer_evals,
        ours_cpu,
        peer_cpu,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::measure::{SettingName, Who};
    use kapitza_core::sim::scene::Fidelity;

    fn pt(evals: u64, error: f64, wall_s: f64) -> Point {
        Point {
            scene: "s".into(),
            family: Family::Rk4,
            who: Who::Ours,
            fidelity: Fidelity::Full,
            format: Format::F64,
            setting_name: SettingName::StepsPerPeriod,
            setting: 1.0,
            error,
            wall_s,
            cpu_s: wall_s,
            rhs_evals: evals,
            steps: evals / 4,
            rejected: 0,
        }
    }

    #[test]
    fn interpolates_in_log_log() {
        // Error 1e-4 at 100 evaluations, 1e-8 at 10 000: a straight line in log-log (slope −2)
        // puts 1e-6 at 1000 evaluations exactly.
        let (a, b) = (pt(100, 1e-4, 1e-3), pt(10_000, 1e-8, 1e-1));
        let (c, interp) = cost_at(&[&b, &a], 1e-6, Cost::Evals).unwrap();
        assert!(interp);
        assert!((c - 1000.0).abs() < 1e-9 * 1000.0, "{c}");
        let (t, _) = cost_at(&[&a, &b], 1e-6, Cost::Time).unwrap();
        assert!((t - 1e-2).abs() < 1e-12, "{t}");
        // Met by the cheapest point: its cost, not interpolated; never met: none.
        assert_eq!(cost_at(&[&a, &b], 1e-3, Cost::Evals), Some((100.0, false)));
        assert_eq!(cost_at(&[&a, &b], 1e-9, Cost::Evals), None);
    }
}
