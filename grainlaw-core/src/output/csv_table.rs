//! Small CSV tables with the unit in each header (`time_s`, `force_N`), optional `# key = value`
//! metadata lines (readable by `grainlaw fit`), written through [`super::OutputDir`].

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::output::OutputDir;

/// Columns of numbers with headers that carry their unit. Serialisable exactly (NaN cells
/// included) so that a table filled step by step can be saved in a run checkpoint.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct CsvTable {
    /// `# key = value` lines written before the header.
    #[serde(with = "crate::floats::pairs")]
    pub metadata: Vec<(String, f64)>,
    /// `# text` comment lines written first.
    pub comments: Vec<String>,
    /// Headers, e.g. `z_m`, `sigma_v_Pa`.
    pub headers: Vec<String>,
    /// Rows of values (NaN written as an empty cell).
    #[serde(with = "crate::floats::table")]
    pub rows: Vec<Vec<f64>>,
}

impl CsvTable {
    /// A table with these headers.
    pub fn new(headers: &[&str]) -> Self {
        Self {
            headers: headers.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        }
    }

    /// Appends a row (must have one value per header).
    pub fn push(&mut self, row: Vec<f64>) {
        debug_assert_eq!(row.len(), self.headers.len());
        self.rows.push(row);
    }

    /// The CSV text.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        for c in &self.comments {
            s.push_str(&format!("# {c}\n"));
        }
        for (k, v) in &self.metadata {
            s.push_str(&format!("# {k} = {v:e}\n"));
        }
        s.push_str(&self.headers.join(","));
        s.push('\n');
        for r in &self.rows {
            let cells: Vec<String> = r
                .iter()
                .map(|v| {
                    if v.is_finite() {
                        format!("{v:e}")
                    } else {
                        String::new()
                    }
                })
                .collect();
            s.push_str(&cells.join(","));
            s.push('\n');
        }
        s
    }

    /// Writes the table as `name` in `out`, atomically.
    pub fn write(&self, out: &mut OutputDir, name: &str) -> Result<()> {
        out.write(name, self.to_text().as_bytes()).map(|_| ())
    }
}
