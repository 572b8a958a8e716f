//! The stability-criteria ladder (physics §4): for a sweep of k about the inverted (k < 0) and the
//! hanging (k > 0) position, undamped, each cheaper criterion's window ends against Floquet's,
//! with the cost of one evaluation of the window; and Floquet's own error against its cost as
//! the RK4 steps per period grow, measured against a finer Floquet reference.
//!
//! ```text
//! criterion error  = max over the window's ends of |end − Floquet end|   (ends both give)
//! missing          = Floquet gives an end the criterion does not (averaging's upper end)
//! Floquet error(N) = max over ends of |end(N steps) − end(reference steps)|
//! ```
//! Costs are the median of five batches ([`seconds_per_eval`]).

use anyhow::Result;
use serde::Serialize;
use std::time::Duration;

use crate::timing::seconds_per_eval;
use kapitza_core::stability::{
    averaging, floquet::Floquet, harmonic_balance, mathieu, Criterion, Position, Window,
};

/// Bisection tolerance in m of the Floquet reference for the criteria (their errors are ≥ 1e-8).
pub const CRITERIA_TOL: f64 = 1e-11;
/// Bisection tolerance in m for Floquet's own convergence (errors down to ~1e-13).
pub const CONVERGENCE_TOL: f64 = 1e-14;

/// One criterion at one k.
#[derive(Debug, Clone, Serialize)]
pub struct CriterionRow {
    pub k: f64,
    pub position: Position,
    pub criterion: Criterion,
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    pub floquet_lower: Option<f64>,
    pub floquet_upper: Option<f64>,
    /// |lower − Floquet lower|, |upper − Floquet upper| where both exist.
    pub lower_error: Option<f64>,
    pub upper_error: Option<f64>,
    /// The larger of the two; `null` when neither end can be compared.
    pub error: Option<f64>,
    /// An end Floquet gives that this criterion does not.
    pub missing_end: bool,
    /// Median wall time of one evaluation of the window (s).
    pub seconds_per_eval: f64,
}

/// Floquet at one step count against the reference step count.
#[derive(Debug, Clone, Serialize)]
pub struct FloquetRow {
    pub k: f64,
    pub steps_per_period: u32,
    pub reference_steps: u32,
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    pub error: Option<f64>,
    pub seconds_per_eval: f64,
    pub monodromies: u64,
    pub rhs_evals: u64,
}

/// What to sweep.
#[derive(Debug, Clone)]
pub struct LadderPlan {
    pub ks: Vec<f64>,
    pub floquet_ks: Vec<f64>,
    pub floquet_steps: Vec<u32>,
    pub reference_steps: u32,
    pub batch: Duration,
}

fn abs_diff(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    a.zip(b).map(|(a, b)| (a - b).abs())
}

fn row(
    k: f64,
    criterion: Criterion,
    w: &Window,
    reference: &Window,
    seconds_per_eval: f64,
) -> CriterionRow {
    let (lower, upper) = (w.lower.value(), w.upper.value());
    let (fl, fu) = (reference.lower.value(), reference.upper.value());
    let lower_error = abs_diff(lower, fl);
    let upper_error = abs_diff(upper, fu);
    let error = match (lower_error, upper_error) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    CriterionRow {
        k,
        position: Position::of_k(k),
        criterion,
        lower,
        upper,
        floquet_lower: fl,
        floquet_upper: fu,
        lower_error,
        upper_error,
        error,
        missing_end: (fl.is_some() && lower.is_none()) || (fu.is_some() && upper.is_none()),
        seconds_per_eval,
    }
}

/// Each criterion at each k against Floquet (default step count, bisected to
/// [`CRITERIA_TOL`]); `tick` is called once per k.
pub fn criteria(plan: &LadderPlan, mut tick: impl FnMut()) -> Result<Vec<CriterionRow>> {
    let fl = Floquet::default();
    let mut rows = Vec::new();
    for &k in &plan.ks {
        let reference = fl.window(k, 0.0, CRITERIA_TOL)?.value;
        let b = plan.batch;
        let cost_f = seconds_per_eval(b, || fl.window(k, 0.0, CRITERIA_TOL));
        rows.push(row(
            k,
            Criterion::Averaging,
            &averaging::window(k)?,
            &reference,
            seconds_per_eval(b, || averaging::window(k)),
        ));
        rows.push(row(
            k,
            Criterion::Mathieu,
            &mathieu::window(k)?,
            &reference,
            seconds_per_eval(b, || mathieu::window(k)),
        ));
        rows.push(row(
            k,
            Criterion::HarmonicBalance,
            &harmonic_balance::window(k)?,
            &reference,
            seconds_per_eval(b, || harmonic_balance::window(k)),
        ));
        rows.push(row(k, Criterion::Floquet, &reference, &reference, cost_f));
        tick();
    }
    Ok(rows)
}

/// Floquet's window at each step count against the reference step count.
pub fn floquet_convergence(plan: &LadderPlan, mut tick: impl FnMut()) -> Result<Vec<FloquetRow>> {
    let mut rows = Vec::new();
    for &k in &plan.floquet_ks {
        let reference = Floquet::new(plan.reference_steps)?
            .window(k, 0.0, CONVERGENCE_TOL)?
            .value;
        for &n in &plan.floquet_steps {
            let fl = Floquet::new(n)?;
            let w = fl.window(k, 0.0, CONVERGENCE_TOL)?;
            let r = row(k, Criterion::Floquet, &w.value, &reference, 0.0);
            rows.push(FloquetRow {
                k,
                steps_per_period: n,
                reference_steps: plan.reference_steps,
                lower: r.lower,
                upper: r.upper,
                error: r.error,
                seconds_per_eval: seconds_per_eval(plan.batch, || {
                    fl.window(k, 0.0, CONVERGENCE_TOL)
                }),
                monodromies: w.monodromies,
                rhs_evals: w.stats.rhs_evals,
            });
            tick();
        }
    }
    Ok(rows)
}
