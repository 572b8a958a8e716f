//! CSV as every command writes it: a header line, then one row per record, numbers in Rust's
//! shortest round-trip form, an empty field for "not computed" or "none", text quoted only where
//! it holds a comma, a quote or a line break. Here too: the run's samples of `kapitza simulate`.

use anyhow::{Context, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::outcome::deg;
use crate::record::StrobeRow;

fn create(path: &Path) -> Result<BufWriter<File>> {
    let f = File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    Ok(BufWriter::new(f))
}

/// A number field: shortest round-trip form; empty when not finite.
pub fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        String::new()
    }
}

/// An optional number field: empty for none.
pub fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), num)
}

/// A text field, quoted (quotes doubled) where it holds a comma, a quote or a line break.
pub fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn finish(mut w: BufWriter<File>, path: &Path) -> Result<()> {
    w.flush()
        .with_context(|| format!("cannot write {}", path.display()))
}

/// `series.csv`: t (s), θ (rad, unwrapped), θ (degrees, wrapped to (−180, 180]), θ' (rad/s).
pub fn series(path: &Path, rows: &[[f64; 3]]) -> Result<()> {
    let mut w = create(path)?;
    writeln!(w, "t,theta_rad,theta_deg_wrapped,rate")?;
    for &[t, theta, rate] in rows {
        writeln!(
            w,
            "{},{},{},{}",
            num(t),
            num(theta),
            num(deg(theta)),
            num(rate)
        )?;
    }
    finish(w, path)
}

/// `strobes.csv`: drive period k, t (s), θ (rad, unwrapped), θ' (rad/s), period-mean θ (rad,
/// empty outside the classifier's analysis window).
pub fn strobes<'a>(path: &Path, rows: impl IntoIterator<Item = &'a StrobeRow>) -> Result<()> {
    let mut w = create(path)?;
    writeln!(w, "k,t,theta,rate,period_mean")?;
    for s in rows {
        writeln!(
            w,
            "{},{},{},{},{}",
            s.k,
            num(s.t),
            num(s.theta),
            num(s.rate),
            num(s.mean)
        )?;
    }
    finish(w, path)
}

/// `sensed.csv`: t (s), the angle the sensor reports (rad and degrees, in (−180°, 180°]).
pub fn sensed<'a>(path: &Path, rows: impl IntoIterator<Item = &'a (f64, f64)>) -> Result<()> {
    let mut w = create(path)?;
    writeln!(w, "t,angle_rad,angle_deg")?;
    for &(t, a) in rows {
        writeln!(w, "{},{},{}", num(t), num(a), num(deg(a)))?;
    }
    finish(w, path)
}
