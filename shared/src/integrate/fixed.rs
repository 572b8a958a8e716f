//! The fixed-step loop shared by every fixed-step method: step times computed afresh, an
//! observer after every step.
//!
//! ```text
//! t_i = t0 + i·h,   i = 0, 1, …, n
//! ```
//! Each t_i is computed from i rather than by adding h n times: an accumulated clock carries a
//! rounding error that grows like √n·ulp(t) (or n·ulp(t) when h is not a binary fraction), and
//! over 10⁶ drive periods that is a visible drift of the drive phase.

/// What an observer of a fixed-step run wants next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// Take the next step.
    Continue,
    /// End the run here; the state just observed is the result.
    Stop,
}

/// Runs `n` steps of size `h` from (t0, y0). `step(t_i, t_{i+1}, &y_i)` returns y_{i+1};
/// `observer(t_{i+1}, &y_{i+1})` is called after each step (not at t0: the caller has y0).
/// Returns where the run ended.
pub(crate) fn run<Y>(
    t0: f64,
    h: f64,
    n: u64,
    y0: Y,
    mut step: impl FnMut(f64, f64, &Y) -> Y,
    mut observer: impl FnMut(f64, &Y) -> Control,
) -> (f64, Y) {
    let mut y = y0;
    let mut t = t0;
    for i in 0..n {
        // u64 → f64 is exact below 2⁵³ steps, far beyond any run we make.
        let t_next = t0 + (i + 1) as f64 * h;
        y = step(t, t_next, &y);
        t = t_next;
        if observer(t, &y) == Control::Stop {
            break;
        }
    }
    (t, y)
}
