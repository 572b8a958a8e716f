//! The monitor off a terminal: one JSON object per telemetry frame, and the CSV log. Both write
//! [`Readings`] as they are, so the JSON keys and the CSV columns are the same names.

use std::io::{self, Write};

use serde_json::Value;

use super::state::Readings;

/// One frame as one line of JSON.
pub fn json_line(r: &Readings, out: &mut dyn Write) -> io::Result<()> {
    serde_json::to_writer(&mut *out, r)?;
    writeln!(out)
}

/// Every frame as one CSV row under a header of the [`Readings`] field names; an empty field
/// for "not known".
pub struct Csv<W: Write> {
    w: W,
    columns: Option<Vec<String>>,
    header: bool,
}

impl<W: Write> Csv<W> {
    pub fn new(w: W) -> Self {
        Self {
            w,
            columns: None,
            header: true,
        }
    }

    /// Rows added to a log that has its header already (`--append`).
    pub fn continuing(w: W) -> Self {
        Self {
            header: false,
            ..Self::new(w)
        }
    }

    pub fn row(&mut self, r: &Readings) -> io::Result<()> {
        let Value::Object(fields) = serde_json::to_value(r)? else {
            return Err(io::Error::other("readings are not a record"));
        };
        let columns = match &self.columns {
            Some(c) => c,
            None => {
                let names: Vec<String> = fields.keys().cloned().collect();
                if self.header {
                    writeln!(self.w, "{}", names.join(","))?;
                }
                self.columns.insert(names)
            }
        };
        let cells: Vec<String> = columns
            .iter()
            .map(|k| match fields.get(k) {
                None | Some(Value::Null) => String::new(),
                Some(Value::String(s)) => s.clone(),
                Some(v) => v.to_string(),
            })
            .collect();
        writeln!(self.w, "{}", cells.join(","))
    }

    pub fn flush(&mut self) -> io::Result<()> {
        self.w.flush()
    }
}
