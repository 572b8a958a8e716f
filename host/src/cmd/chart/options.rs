//! Command-line pieces every chart shares: ranges, grid sizes, drive strengths, the output
//! directory.

use anyhow::{Context, Result};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One finite number `x`, a part of the argument `s`.
fn finite(x: &str, s: &str) -> Result<f64, String> {
    x.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("`{x}` in `{s}` is not a finite number"))
}

/// A closed range FROM..TO of a real parameter; negative ends allowed (`-2.5..0.5`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    pub from: f64,
    pub to: f64,
}

impl std::str::FromStr for Range {
    type Err = String;
    fn from_str(s: &str) -> Result<Range, String> {
        let (a, b) = s
            .split_once("..")
            .ok_or_else(|| format!("`{s}` is not a range: expected FROM..TO, e.g. -2.5..0.5"))?;
        let (from, to) = (finite(a, s)?, finite(b, s)?);
        if from >= to {
            return Err(format!("`{s}`: FROM must be below TO"));
        }
        Ok(Range { from, to })
    }
}

/// A grid size NxM (samples along x and y, both ends included), each 2…4000.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Size {
    pub nx: usize,
    pub ny: usize,
}

impl std::str::FromStr for Size {
    type Err = String;
    fn from_str(s: &str) -> Result<Size, String> {
        let (a, b) = s
            .split_once(['x', 'X', '×'])
            .ok_or_else(|| format!("`{s}` is not a size: expected NxM, e.g. 400x300"))?;
        let num = |x: &str| {
            x.trim()
                .parse::<usize>()
                .ok()
                .filter(|v| (2..=4000).contains(v))
                .ok_or_else(|| format!("`{x}` in `{s}`: expected an integer in 2..=4000"))
        };
        Ok(Size {
            nx: num(a)?,
            ny: num(b)?,
        })
    }
}

/// A point k,m (or ω,A) to mark.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    pub x: f64,
    pub y: f64,
}

impl std::str::FromStr for Point {
    type Err = String;
    fn from_str(s: &str) -> Result<Point, String> {
        let (a, b) = s
            .split_once(',')
            .ok_or_else(|| format!("`{s}` is not a point: expected X,Y, e.g. -0.3,0.9"))?;
        Ok(Point {
            x: finite(a, s)?,
            y: finite(b, s)?,
        })
    }
}

/// The drive strengths of `--r R,…`, each checked: a negative or non-finite one is refused
/// naming `--r` (exit status 1, like every out-of-range value).
pub fn drive_strengths(rs: &[f64]) -> Result<Vec<f64>> {
    for &r in rs {
        crate::input::non_negative("--r", r)?;
    }
    Ok(rs.to_vec())
}

/// Where the files go and whether JSON goes to stdout.
#[derive(Debug, Clone, clap::Args)]
pub struct Output {
    /// Directory for the PNG, SVG and CSV files (created if missing; checked before any work).
    #[arg(long, value_name = "DIR", default_value = "charts")]
    pub out: PathBuf,
    /// Print the chart's data as JSON on stdout instead of a summary.
    #[arg(long)]
    pub json: bool,
}

impl Output {
    pub fn prepare(&self) -> Result<&Path> {
        crate::chart::draw::prepare_dir(&self.out)?;
        Ok(&self.out)
    }

    /// Prints `data` as JSON, or the list of files written.
    pub fn finish<T: Serialize>(
        &self,
        data: &T,
        files: &[PathBuf],
        out: &mut dyn Write,
    ) -> Result<()> {
        if self.json {
            serde_json::to_writer_pretty(&mut *out, data)?;
            writeln!(out)?;
        } else {
            for f in files {
                writeln!(out, "wrote {}", f.display())?;
            }
        }
        Ok(())
    }
}

/// Writes a CSV file: a header line and rows.
pub fn write_csv(
    path: &Path,
    header: &str,
    rows: impl IntoIterator<Item = String>,
) -> Result<PathBuf> {
    let mut text = String::from(header);
    text.push('\n');
    for r in rows {
        text.push_str(&r);
        text.push('\n');
    }
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path.to_path_buf())
}

/// A number for CSV: empty when missing.
pub fn csv_num(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| format!("{v}"))
}
