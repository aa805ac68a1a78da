//! Time histories: named columns recorded during a run, written as CSV.

use std::io::Write;
use std::path::Path;

use crate::{Error, Result};

/// A table of time histories: one named column per quantity, one row per recorded time.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct History {
    /// Column names (the first is conventionally `time_s`).
    pub names: Vec<String>,
    /// Column data, `columns[k][row]`.
    pub columns: Vec<Vec<f64>>,
}

impl History {
    /// An empty history with these columns.
    pub fn new<S: AsRef<str>>(names: &[S]) -> Self {
        Self {
            names: names.iter().map(|s| s.as_ref().to_string()).collect(),
            columns: vec![Vec::new(); names.len()],
        }
    }

    /// Appends one row; `row` must have one value per column (extra values are ignored,
    /// missing ones recorded as NaN so that a bug shows in the output instead of shifting
    /// columns).
    pub fn push(&mut self, row: &[f64]) {
        for (k, col) in self.columns.iter_mut().enumerate() {
            col.push(row.get(k).copied().unwrap_or(f64::NAN));
        }
    }

    /// Keeps every other row (the first, third…): half the memory, twice the interval.
    pub fn decimate(&mut self) {
        for col in &mut self.columns {
            let kept: Vec<f64> = col.iter().step_by(2).copied().collect();
            *col = kept;
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// Whether no row has been recorded.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A column by name.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|k| self.columns[k].as_slice())
    }

    /// Writes the table as CSV with a header line.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        let file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
        let mut w = std::io::BufWriter::new(file);
        let io = |e| Error::io(path, e);
        // Names with a comma or a quote are quoted (RFC 4180).
        let names: Vec<String> = self
            .names
            .iter()
            .map(|n| {
                if n.contains([',', '"']) {
                    format!("\"{}\"", n.replace('"', "\"\""))
                } else {
                    n.clone()
                }
            })
            .collect();
        writeln!(w, "{}", names.join(",")).map_err(io)?;
        for row in 0..self.len() {
            let line: Vec<String> = self
                .columns
                .iter()
                .map(|c| format!("{:.9e}", c.get(row).copied().unwrap_or(f64::NAN)))
                .collect();
            writeln!(w, "{}", line.join(",")).map_err(io)?;
        }
        w.flush().map_err(io)
    }
}

/// Running maximum of |x| with the time at which it occurred.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PeakTracker {
    /// Largest |x| so far.
    pub value: f64,
    /// Time of that value.
    pub time: f64,
}

impl PeakTracker {
    /// Offers a new sample.
    pub fn offer(&mut self, t: f64, x: f64) {
        if x.abs() > self.value {
            self.value = x.abs();
            self.time = t;
        }
    }
}
