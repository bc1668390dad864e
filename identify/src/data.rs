//! User tables read from CSV.
//!
//! Format: comma-separated, one header line, one row per observation. Lines starting with `#`
//! are comments; a comment of the form `# key = value` (anywhere in the file) is a numeric
//! set-up constant (metadata), e.g. `# width_m = 0.03`. Blank lines are ignored. Column headers
//! carry their unit as a suffix (`z_m`, `sigma_v_Pa`); they are matched case-insensitively after
//! trimming. Columns a law does not use may hold anything.
//!
//! Cells are parsed only when their column is asked for, so errors name the file, the 1-based
//! line and the column: [`IdentifyError::NonNumericCell`], [`IdentifyError::NonFiniteCell`],
//! [`IdentifyError::MissingColumn`], [`IdentifyError::Metadata`].

use std::collections::BTreeMap;
use std::path::Path;

use crate::error::{IdentifyError, Result};

/// A table of named columns read from a CSV file (data).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Name of the source (file path) for error messages.
    pub source: String,
    /// `# key = value` constants.
    pub metadata: BTreeMap<String, f64>,
    /// Headers, trimmed, in file order.
    pub headers: Vec<String>,
    /// Raw cells, `cells[row][column]`.
    cells: Vec<Vec<String>>,
    /// 1-based file line of each row.
    lines: Vec<u64>,
}

impl Table {
    /// Reads a CSV file.
    pub fn read_csv(path: &Path) -> Result<Table> {
        let text = std::fs::read_to_string(path).map_err(|source| IdentifyError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Table::parse_csv(&text, &path.display().to_string())
    }

    /// Parses CSV text; `source` names it in errors.
    pub fn parse_csv(text: &str, source: &str) -> Result<Table> {
        let mut metadata = BTreeMap::new();
        let mut headers: Option<Vec<String>> = None;
        let mut cells = Vec::new();
        let mut lines = Vec::new();
        for (idx, raw) in text.lines().enumerate() {
            let line_no = idx as u64 + 1;
            let line = raw.trim();
            if line.is_empty() {
                continue;
            }
            if let Some(comment) = line.strip_prefix('#') {
                if let Some((key, value)) = comment.split_once('=') {
                    let key = key.trim().to_string();
                    let value = value.trim();
                    let v: f64 = value.parse().map_err(|_| IdentifyError::Metadata {
                        file: source.to_string(),
                        message: format!(
                            "line {line_no}: metadata '{key}' = '{value}' is not a number"
                        ),
                    })?;
                    if !v.is_finite() {
                        return Err(IdentifyError::Metadata {
                            file: source.to_string(),
                            message: format!("line {line_no}: metadata '{key}' is not finite"),
                        });
                    }
                    metadata.insert(key, v);
                }
                continue;
            }
            let record = parse_record(line, source, line_no)?;
            match &headers {
                None => headers = Some(record),
                Some(h) => {
                    if record.len() != h.len() {
                        return Err(IdentifyError::Csv {
                            file: source.to_string(),
                            line: line_no,
                            message: format!(
                                "{} fields, but the header has {}",
                                record.len(),
                                h.len()
                            ),
                        });
                    }
                    cells.push(record);
                    lines.push(line_no);
                }
            }
        }
        let headers = headers.ok_or_else(|| IdentifyError::Csv {
            file: source.to_string(),
            line: 0,
            message: "no header line".into(),
        })?;
        Ok(Table {
            source: source.to_string(),
            metadata,
            headers,
            cells,
            lines,
        })
    }

    /// Number of data rows.
    pub fn rows(&self) -> usize {
        self.cells.len()
    }

    fn index_of(&self, header: &str) -> Option<usize> {
        self.headers
            .iter()
            .position(|h| h.eq_ignore_ascii_case(header.trim()))
    }

    /// True when the header has `header`.
    pub fn has_column(&self, header: &str) -> bool {
        self.index_of(header).is_some()
    }

    /// The numeric column `header`. Errors: [`IdentifyError::MissingColumn`],
    /// [`IdentifyError::NonNumericCell`], [`IdentifyError::NonFiniteCell`].
    pub fn column(&self, header: &str) -> Result<Vec<f64>> {
        let j = self
            .index_of(header)
            .ok_or_else(|| IdentifyError::MissingColumn {
                file: self.source.clone(),
                column: header.to_string(),
                available: self.headers.join(", "),
            })?;
        self.cells
            .iter()
            .zip(&self.lines)
            .map(|(row, &line)| {
                let cell = row[j].as_str();
                let v: f64 = cell.parse().map_err(|_| IdentifyError::NonNumericCell {
                    file: self.source.clone(),
                    line,
                    column: self.headers[j].clone(),
                    value: cell.to_string(),
                })?;
                if !v.is_finite() {
                    return Err(IdentifyError::NonFiniteCell {
                        file: self.source.clone(),
                        line,
                        column: self.headers[j].clone(),
                        value: v,
                    });
                }
                Ok(v)
            })
            .collect()
    }

    /// The column if present (errors as [`Table::column`] when present but malformed).
    pub fn optional_column(&self, header: &str) -> Result<Option<Vec<f64>>> {
        if self.has_column(header) {
            self.column(header).map(Some)
        } else {
            Ok(None)
        }
    }

    /// A required metadata constant.
    pub fn metadata_value(&self, key: &str) -> Result<f64> {
        self.metadata
            .get(key)
            .copied()
            .ok_or_else(|| IdentifyError::Metadata {
                file: self.source.clone(),
                message: format!("missing metadata line '# {key} = <value>'"),
            })
    }

    /// An optional metadata constant.
    pub fn metadata_or(&self, key: &str, default: f64) -> f64 {
        self.metadata.get(key).copied().unwrap_or(default)
    }
}

/// Splits one CSV line with the `csv` crate (quotes allowed), trimming fields.
fn parse_record(line: &str, source: &str, line_no: u64) -> Result<Vec<String>> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .trim(csv::Trim::All)
        .from_reader(line.as_bytes());
    let mut record = csv::StringRecord::new();
    match reader.read_record(&mut record) {
        Ok(true) => Ok(record.iter().map(|s| s.to_string()).collect()),
        Ok(false) => Ok(Vec::new()),
        Err(e) => Err(IdentifyError::Csv {
            file: source.to_string(),
            line: line_no,
            message: e.to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "# a Janssen profile\n# width_m = 0.03\n\nz_m, sigma_v_Pa ,label\n0.01,150.0,top\n0.02,290.5,\"mid, quoted\"\n0.03,abc,bottom\n";

    #[test]
    fn metadata_headers_and_columns() {
        let t = Table::parse_csv(TEXT, "p.csv").unwrap();
        assert_eq!(t.metadata["width_m"], 0.03);
        assert_eq!(t.headers, vec!["z_m", "sigma_v_Pa", "label"]);
        assert_eq!(t.rows(), 3);
        assert_eq!(t.column("Z_M").unwrap(), vec![0.01, 0.02, 0.03]);
    }

    #[test]
    fn non_numeric_cell_names_line_and_column() {
        let t = Table::parse_csv(TEXT, "p.csv").unwrap();
        let e = t.column("sigma_v_Pa").unwrap_err();
        match &e {
            IdentifyError::NonNumericCell {
                line,
                column,
                value,
                ..
            } => {
                assert_eq!(*line, 7);
                assert_eq!(column, "sigma_v_Pa");
                assert_eq!(value, "abc");
            }
            other => panic!("{other}"),
        }
        assert!(e.to_string().starts_with("p.csv:7:"));
    }

    #[test]
    fn missing_column_lists_header() {
        let t = Table::parse_csv(TEXT, "p.csv").unwrap();
        let e = t.column("sigma_h_Pa").unwrap_err();
        assert!(matches!(e, IdentifyError::MissingColumn { .. }));
        assert!(e.to_string().contains("sigma_h_Pa"));
        assert!(e.to_string().contains("z_m, sigma_v_Pa, label"));
    }

    #[test]
    fn ragged_row_and_nan_are_errors() {
        let e = Table::parse_csv("x,y\n1,2\n3\n", "r.csv").unwrap_err();
        assert!(matches!(e, IdentifyError::Csv { line: 3, .. }));
        let t = Table::parse_csv("x,y\n1,NaN\n", "n.csv").unwrap();
        assert!(matches!(
            t.column("y").unwrap_err(),
            IdentifyError::NonFiniteCell { line: 2, .. }
        ));
        let e = Table::parse_csv("# w = wide\nx\n1\n", "m.csv").unwrap_err();
        assert!(e.to_string().contains("line 1"));
    }
}
