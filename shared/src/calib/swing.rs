//! A free oscillation's half-swings, from samples (t, θ) at the telemetry rate.
//!
//! ```text
//! turning points: hysteresis h on the raw samples (a maximum is confirmed once θ falls h below
//!                 it), then refined by a least-squares parabola over ±1/12 of a period around
//!                 the highest sample (cos over ±30° differs from its parabola by < 3e-4 of the
//!                 swing, below the sensor's noise)
//! half-swing k:   from turning point e_k to e_{k+1}; its half-height h_k = |e_k − e_{k+1}|/2 and
//!                 midline m_k = (e_k + e_{k+1})/2; its crossing c_k: where θ crosses m_k, from a
//!                 least-squares line over ±1/16 of a period around the first sign change
//! ```
//! Why the half-swing's own midline: under Coulomb friction each half-swing is an exact
//! harmonic arc about a centre shifted by ±μ/ω0² against its velocity, so it crosses its own
//! midline exactly a quarter period after its turning point; under viscous damping the midline
//! sits the same fraction of the envelope off the centre in every half-swing, so the crossings
//! shift by a constant phase. Either way successive crossings are exactly half a damped period
//! apart, which crossings of one fixed level are not.
//!
//! Turning points whose refinement window runs past the record's ends (the release itself)
//! are dropped. At most [`MAX_TURNS`] are kept: 64 periods, far more than a ring-down needs.

/// Turning points kept.
pub const MAX_TURNS: usize = 128;

/// One refined turning point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Turn {
    pub t: f64,
    pub theta: f64,
    /// Index of the extreme sample.
    pub index: usize,
}

/// The turning points of a record.
#[derive(Debug, Clone, Copy)]
pub struct Turns {
    turns: [Turn; MAX_TURNS],
    len: usize,
}

impl Turns {
    pub fn as_slice(&self) -> &[Turn] {
        &self.turns[..self.len]
    }
}

/// Turning points of `x` (rad) at times `t` (s), with hysteresis `h` (rad); refined, the first
/// and last dropped when their window is cut by the record's ends.
pub fn turning_points(t: &[f64], x: &[f64], h: f64) -> Turns {
    let n = t.len().min(x.len());
    let mut raw = [0usize; MAX_TURNS + 2];
    let mut nraw = 0;
    // +1: looking for a maximum, −1: a minimum, 0: not yet known.
    let mut dir = 0i8;
    let (mut hi, mut lo) = (0usize, 0usize);
    for i in 0..n {
        if x[i] > x[hi] {
            hi = i;
        }
        if x[i] < x[lo] {
            lo = i;
        }
        let found = match dir {
            1 if x[i] < x[hi] - h => Some(hi),
            -1 if x[i] > x[lo] + h => Some(lo),
            0 if x[i] < x[hi] - h => Some(hi),
            0 if x[i] > x[lo] + h => Some(lo),
            _ => None,
        };
        if let Some(k) = found {
            if nraw == raw.len() {
                break;
            }
            raw[nraw] = k;
            nraw += 1;
            dir = if x[k] >= x[i] { -1 } else { 1 };
            (hi, lo) = (i, i);
        }
    }
    let mut out = Turns {
        turns: [Turn::default(); MAX_TURNS],
        len: 0,
    };
    if nraw < 2 {
        return out;
    }
    // Half a period from the raw turning points' spacing (their median is not needed: the
    // window only has to be roughly right).
    let half = (t[raw[nraw - 1]] - t[raw[0]]) / (nraw - 1) as f64;
    let win = half / 6.0;
    for &k in &raw[..nraw] {
        if out.len == MAX_TURNS {
            break;
        }
        if t[k] - t[0] < win || t[n - 1] - t[k] < win {
            continue;
        }
        if let Some(turn) = refine(t, x, k, win) {
            out.turns[out.len] = turn;
            out.len += 1;
        }
    }
    out
}

/// The vertex of the least-squares parabola through the samples within `win` of sample `k`.
fn refine(t: &[f64], x: &[f64], k: usize, win: f64) -> Option<Turn> {
    let t0 = t[k];
    // Normal equations of x ≈ a + bτ + cτ², τ = t − t0.
    let mut s = [0.0f64; 5];
    let mut r = [0.0f64; 3];
    for (ti, xi) in t.iter().zip(x) {
        let tau = ti - t0;
        if tau.abs() > win {
            continue;
        }
        let mut p = 1.0;
        for (j, sj) in s.iter_mut().enumerate() {
            *sj += p;
            if j < 3 {
                r[j] += p * xi;
            }
            p *= tau;
        }
    }
    if s[0] < 3.0 {
        return Some(Turn {
            t: t0,
            theta: x[k],
            index: k,
        });
    }
    let m = [[s[0], s[1], s[2]], [s[1], s[2], s[3]], [s[2], s[3], s[4]]];
    let [a, b, c] = solve3(m, r)?;
    if c == 0.0 {
        return None;
    }
    let tau = (-b / (2.0 * c)).clamp(-win, win);
    Some(Turn {
        t: t0 + tau,
        theta: a + b * tau + c * tau * tau,
        index: k,
    })
}

/// Solves a 3×3 system by Cramer's rule; `None` when singular.
pub(crate) fn solve3(m: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    let mut out = [0.0; 3];
    for (j, o) in out.iter_mut().enumerate() {
        let mut mj = m;
        for (row, ri) in mj.iter_mut().zip(r) {
            row[j] = ri;
        }
        *o = det(&mj) / d;
    }
    Some(out)
}

/// Where the half-swing from turning point `a` to `b` crosses its own midline (s): a
/// least-squares line through the samples within `win` of the first sample past the midline.
pub fn midline_crossing(t: &[f64], x: &[f64], a: &Turn, b: &Turn, win: f64) -> Option<f64> {
    let mid = (a.theta + b.theta) / 2.0;
    let down = b.theta < a.theta;
    let past = |v: f64| if down { v < mid } else { v > mid };
    let k = (a.index..=b.index).find(|&i| past(x[i]))?;
    let t0 = t[k];
    let (mut n, mut st, mut sx, mut stt, mut stx) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in a.index..=b.index {
        let tau = t[i] - t0;
        if tau.abs() > win {
            continue;
        }
        let v = x[i] - mid;
        n += 1.0;
        st += tau;
        sx += v;
        stt += tau * tau;
        stx += tau * v;
    }
    let den = n * stt - st * st;
    if n < 2.0 || den == 0.0 {
        return None;
    }
    let slope = (n * stx - st * sx) / den;
    let icpt = (sx - slope * st) / n;
    (slope != 0.0).then(|| t0 - icpt / slope)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;

    #[test]
    fn finds_and_refines_the_turning_points_of_a_damped_sine() {
        // x = e^{−σt} cos(ωt) at 50 Hz: the turning points are where tan(ωt) = −σ/ω, i.e. at
        // t_k = (kπ − atan(σ/ω))/ω, values (−1)^k e^{−σ t_k} cos(atan(σ/ω)) (closed form).
        let (w, sigma) = (7.0, 0.3);
        let t: [f64; 500] = core::array::from_fn(|i| i as f64 * 0.02);
        let x: [f64; 500] = core::array::from_fn(|i| {
            let ti = t[i];
            math::exp(-sigma * ti) * math::cos(w * ti)
        });
        let turns = turning_points(&t, &x, 0.01);
        let got = turns.as_slice();
        assert!(got.len() >= 19, "{}", got.len());
        let phi = math::atan2(sigma, w);
        for tp in got {
            let k = ((tp.t * w + phi) / math::PI).round();
            let tk = (k * math::PI - phi) / w;
            let xk = (-1f64).powi(k as i32) * math::exp(-sigma * tk) * math::cos(phi);
            // Parabola over ±30° of phase: within 3e-4 of the unit swing; time within 1 ms.
            assert!((tp.theta - xk).abs() < 3e-4, "{tp:?} vs {xk}");
            assert!((tp.t - tk).abs() < 1e-3, "{tp:?} vs {tk}");
        }
        // Successive midline crossings are π/ω apart (module doc), to 0.1 ms here.
        for p in got.windows(3) {
            let c0 = midline_crossing(&t, &x, &p[0], &p[1], 0.05).unwrap();
            let c1 = midline_crossing(&t, &x, &p[1], &p[2], 0.05).unwrap();
            assert!((c1 - c0 - math::PI / w).abs() < 1e-4, "{}", c1 - c0);
        }
    }

    #[test]
    fn a_flat_record_has_no_turning_points() {
        let t = [0.0, 0.02, 0.04, 0.06];
        assert_eq!(turning_points(&t, &[0.1; 4], 0.01).as_slice().len(), 0);
    }
}
