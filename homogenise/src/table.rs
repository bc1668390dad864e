//! A history table: named columns with units, one row per sample, stored as `f64` and handed out
//! as `ndarray` arrays; written to CSV with the units in the header (`name [unit]`), atomically
//! (a temporary file in the same directory, synced, then renamed over the target).
//!
//! A missing value (a quantity undefined at that sample, e.g. the stress ratio at zero pressure)
//! is stored as NaN and written as an empty CSV field; reading gives NaN back.

use std::path::Path;

use ndarray::{Array1, Array2};
use serde::{Deserialize, Serialize};

use crate::averaging::{window_average, TimeAverage};
use crate::error::{HomogeniseError, Result};

/// A column: its name and its unit (`-` for dimensionless).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Column {
    /// Name (letters, digits, `_`, `.`, `-`).
    pub name: String,
    /// Unit, SI (`s`, `Pa`, `1/s`, `N`, `-`, ...).
    pub unit: String,
}

impl Column {
    /// A column named `name` in `unit`.
    pub fn new(name: impl Into<String>, unit: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: unit.into(),
        }
    }

    /// Header field `name [unit]`.
    pub fn header(&self) -> String {
        format!("{} [{}]", self.name, self.unit)
    }

    fn parse_header(field: &str) -> Option<Self> {
        let field = field.trim();
        let open = field.rfind(" [")?;
        let unit = field[open + 2..].strip_suffix(']')?;
        Some(Self::new(&field[..open], unit))
    }
}

/// Rows of samples under named columns (row-major `f64`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Table {
    columns: Vec<Column>,
    data: Vec<f64>,
    rows: usize,
}

fn valid_name(s: &str) -> bool {
    !s.is_empty()
        && s.chars()
            .all(|c| c.is_alphanumeric() || matches!(c, '_' | '.' | '-'))
}

fn valid_unit(s: &str) -> bool {
    !s.is_empty()
        && !s
            .chars()
            .any(|c| matches!(c, ',' | '"' | '[' | ']' | '\n' | '\r'))
}

impl Table {
    /// An empty table with these columns; names must be unique and made of letters, digits,
    /// `_`, `.`, `-`; units non-empty without `,` `"` `[` `]` or line breaks.
    pub fn new(columns: Vec<Column>) -> Result<Self> {
        if columns.is_empty() {
            return Err(HomogeniseError::Table(
                "a table needs at least one column".into(),
            ));
        }
        for (i, c) in columns.iter().enumerate() {
            if !valid_name(&c.name) || !valid_unit(&c.unit) {
                return Err(HomogeniseError::Table(format!(
                    "bad column `{}` (unit `{}`)",
                    c.name, c.unit
                )));
            }
            if columns[..i].iter().any(|d| d.name == c.name) {
                return Err(HomogeniseError::Table(format!(
                    "duplicate column `{}`",
                    c.name
                )));
            }
        }
        Ok(Self {
            columns,
            data: Vec::new(),
            rows: 0,
        })
    }

    /// The columns.
    pub fn columns(&self) -> &[Column] {
        &self.columns
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Appends a row; its length must be the number of columns. NaN means missing; infinities
    /// are refused.
    pub fn push_row(&mut self, row: &[f64]) -> Result<()> {
        if row.len() != self.columns.len() {
            return Err(HomogeniseError::Table(format!(
                "row of {} values for {} columns",
                row.len(),
                self.columns.len()
            )));
        }
        if let Some(i) = row.iter().position(|v| v.is_infinite()) {
            return Err(HomogeniseError::Table(format!(
                "infinite value in column `{}`",
                self.columns[i].name
            )));
        }
        self.data.extend_from_slice(row);
        self.rows += 1;
        Ok(())
    }

    /// The whole table as an array `rows × columns`.
    pub fn to_array(&self) -> Array2<f64> {
        Array2::from_shape_vec((self.rows, self.columns.len()), self.data.clone())
            .unwrap_or_else(|_| Array2::zeros((0, self.columns.len())))
    }

    /// Index of the named column.
    pub fn index_of(&self, name: &str) -> Result<usize> {
        self.columns
            .iter()
            .position(|c| c.name == name)
            .ok_or_else(|| HomogeniseError::Table(format!("no column `{name}`")))
    }

    /// One column as an array.
    pub fn column(&self, name: &str) -> Result<Array1<f64>> {
        let j = self.index_of(name)?;
        let k = self.columns.len();
        Ok((0..self.rows).map(|i| self.data[i * k + j]).collect())
    }

    /// Time average of column `value` over the rows whose `time` column lies in
    /// `[t_start, t_end]`, with its block-averaging standard error (missing values skipped).
    pub fn window_average(
        &self,
        time: &str,
        value: &str,
        t_start: f64,
        t_end: f64,
        min_blocks: usize,
    ) -> Result<TimeAverage> {
        let t = self.column(time)?;
        let v = self.column(value)?;
        window_average(
            t.as_slice().unwrap_or(&[]),
            v.as_slice().unwrap_or(&[]),
            t_start,
            t_end,
            min_blocks,
        )
    }

    /// Writes the table as CSV (header `name [unit]`, values in shortest round-trip form,
    /// missing values empty), atomically: `path` either keeps its old content or gets the whole
    /// new table.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        let k = self.columns.len();
        dem::atomic::write_atomic(path, |file| {
            let mut w = csv::Writer::from_writer(file);
            w.write_record(self.columns.iter().map(Column::header))?;
            for i in 0..self.rows {
                w.write_record(self.data[i * k..(i + 1) * k].iter().map(|v| {
                    if v.is_nan() {
                        String::new()
                    } else {
                        format!("{v}")
                    }
                }))?;
            }
            w.flush()
        })
        .map_err(|source| HomogeniseError::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads a table written by [`Table::write_csv`] (header fields `name [unit]`).
    pub fn read_csv(path: &Path) -> Result<Self> {
        let csv_err = |source| HomogeniseError::Csv {
            path: path.to_path_buf(),
            source,
        };
        let mut r = csv::Reader::from_path(path).map_err(csv_err)?;
        let columns = r
            .headers()
            .map_err(csv_err)?
            .iter()
            .map(|h| {
                Column::parse_header(h).ok_or_else(|| {
                    HomogeniseError::Table(format!(
                        "{}: header field `{h}` is not `name [unit]`",
                        path.display()
                    ))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut table = Table::new(columns)?;
        for (line, rec) in r.records().enumerate() {
            let rec = rec.map_err(csv_err)?;
            let row = rec
                .iter()
                .map(|f| {
                    let f = f.trim();
                    if f.is_empty() {
                        Ok(f64::NAN)
                    } else {
                        f.parse::<f64>()
                            .ok()
                            .filter(|v| v.is_finite())
                            .ok_or_else(|| {
                                HomogeniseError::Table(format!(
                                    "{} line {}: `{f}` is not a finite number",
                                    path.display(),
                                    line + 2
                                ))
                            })
                    }
                })
                .collect::<Result<Vec<_>>>()?;
            table.push_row(&row).map_err(|e| {
                HomogeniseError::Table(format!("{} line {}: {e}", path.display(), line + 2))
            })?;
        }
        Ok(table)
    }
}
