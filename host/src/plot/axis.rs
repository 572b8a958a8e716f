//! Angle axes that fit the motion: the unwrapped angle, moved by whole turns so the end of the
//! run sits in (−90°, 270°] (a rest near 180° is never cut at ±180°), the range taken from the
//! data, and ticks at round numbers of degrees.

/// Whole turns (in degrees) to add to every unwrapped angle so that `settled_deg` lands in
/// (−90°, 270°]: hanging tilts read as −90°…90°, inverted ones as 90°…270°.
pub fn turn_shift(settled_deg: f64) -> f64 {
    if !settled_deg.is_finite() {
        return 0.0;
    }
    -360.0 * ((settled_deg - 270.0) / 360.0).ceil()
}

/// Range of `xs`, padded by 5 % and at least `min_span` wide.
pub fn padded(xs: impl Iterator<Item = f64>, min_span: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in xs.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if lo > hi {
        return (-0.5 * min_span.max(1e-9), 0.5 * min_span.max(1e-9));
    }
    let pad = (0.05 * (hi - lo)).max(0.5 * (min_span - (hi - lo)).max(0.0));
    (lo - pad, hi + pad)
}

/// Tick positions in [lo, hi] (degrees): multiples of a round step chosen for at most 8 ticks.
pub fn degree_ticks(lo: f64, hi: f64) -> Vec<f64> {
    const STEPS: [f64; 14] = [
        0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 15.0, 30.0, 45.0, 90.0,
    ];
    let span = (hi - lo).max(1e-12);
    let step = STEPS
        .iter()
        .copied()
        .chain((0..).map(|i| 180.0 * f64::from(1u32 << i.min(30))))
        .find(|s| span / s <= 8.0)
        .unwrap_or(span);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

/// Tick positions in [lo, hi] at multiples of 1, 2 or 5 times a power of ten, at most 8.
pub fn decimal_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let mut step = 10f64.powf((span / 8.0).log10().floor());
    for m in [1.0, 2.0, 5.0, 10.0] {
        if span / (m * step) <= 8.0 {
            step *= m;
            break;
        }
    }
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

/// Angle ranges wider than this (degrees) are drawn in turns, without the equilibria (one line
/// a turn would hide the motion).
pub const TURNS_ABOVE: f64 = 4.0 * 360.0;

/// Digits after the point that tick labels need: the fewest that write every tick exactly.
pub fn decimals(ticks: &[f64]) -> usize {
    (0..6)
        .find(|&d| {
            let scale = 10f64.powi(d as i32);
            ticks
                .iter()
                .all(|t| ((t * scale) - (t * scale).round()).abs() < 1e-6 * scale.max(1.0))
        })
        .unwrap_or(6)
}

/// Where a phase portrait cuts the angle: `None` when the angles drawn span less than a turn
/// (drawn unwrapped), else the lower end of the turn centred on `centre_deg` they are wrapped
/// into.
pub fn phase_cut(xs: impl Iterator<Item = f64>, centre_deg: f64) -> Option<f64> {
    let (lo, hi) = padded(xs, 0.0);
    (hi - lo > 360.0).then_some(centre_deg - 180.0)
}

/// `deg` wrapped into [cut, cut + 360°).
pub fn wrap_from(deg: f64, cut: f64) -> f64 {
    cut + (deg - cut).rem_euclid(360.0)
}

/// Splits points into runs that do not jump more than half a turn in x (a wrap).
pub fn unbroken(points: impl Iterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut prev: Option<f64> = None;
    for (a, b) in points {
        match (prev, runs.last_mut()) {
            (Some(p), Some(run)) if (a - p).abs() <= 180.0 => run.push((a, b)),
            _ => runs.push(vec![(a, b)]),
        }
        prev = Some(a);
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rest_at_the_top_is_not_cut_at_the_wrap() {
        // The same rest reached from either side (179° or −179° = 181°), or after turns: one
        // continuous axis around 180°.
        for (settled, expect) in [
            (179.0, 179.0),
            (-179.0, 181.0),
            (179.0 + 720.0, 179.0),
            (-179.0 - 3600.0, 181.0),
        ] {
            let shifted = settled + turn_shift(settled);
            assert!((shifted - expect).abs() < 1e-9, "{settled}: {shifted}");
        }
        // A wiggle about the top across ±180° stays one range once shifted.
        let wiggle = [178.0_f64, -178.0 + 360.0, 179.5, 180.5];
        let s = turn_shift(179.0);
        let (lo, hi) = padded(wiggle.iter().map(|x| x + s), 1.0);
        assert!(lo > 170.0 && hi < 190.0, "{lo}..{hi}");
    }

    #[test]
    fn hanging_and_tilted_rests_keep_their_usual_angles() {
        for a in [0.0, 45.0, -60.0, 89.0, 91.0, 135.0, 269.0, -91.0] {
            let shifted = a + turn_shift(a);
            assert!(shifted > -90.0 && shifted <= 270.0, "{a} → {shifted}");
            assert_eq!((shifted - a).rem_euclid(360.0), 0.0);
        }
        assert_eq!(turn_shift(45.0), 0.0);
        assert_eq!(turn_shift(-91.0), 360.0);
    }

    #[test]
    fn ticks_are_round_and_few() {
        assert_eq!(
            degree_ticks(150.0, 210.0),
            [150.0, 160.0, 170.0, 180.0, 190.0, 200.0, 210.0]
        );
        assert_eq!(
            degree_ticks(-10.0, 350.0),
            [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]
        );
        let many = degree_ticks(0.0, 7200.0);
        assert!(many.len() <= 8 && many.iter().all(|t| t % 180.0 == 0.0));
        let fine = degree_ticks(179.93, 180.07);
        assert!(fine.len() >= 3 && fine.len() <= 8, "{fine:?}");
        assert_eq!(decimals(&fine), 2);
        assert_eq!(
            decimal_ticks(-2.4, 11.0),
            [-2.0, 0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
        );
        assert_eq!(
            decimal_ticks(2690.0, 2945.0),
            [2700.0, 2750.0, 2800.0, 2850.0, 2900.0]
        );
    }

    #[test]
    fn a_rotation_is_wrapped_and_a_rest_is_not() {
        let turns = (0..100).map(|i| f64::from(i) * 36.0);
        assert_eq!(phase_cut(turns, 180.0), Some(0.0));
        let rest = [170.0, 190.0, 185.0].into_iter();
        assert_eq!(phase_cut(rest, 180.0), None);
        assert_eq!(wrap_from(-179.0, 0.0), 181.0);
        // A wrapped rotation splits where it passes the cut.
        let runs = unbroken([(350.0, 1.0), (355.0, 1.0), (1.0, 1.0), (6.0, 1.0)].into_iter());
        assert_eq!(runs.len(), 2);
    }
}
