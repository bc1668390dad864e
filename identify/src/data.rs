//! User tables read from CSV.
//!
//! Format: comma-separated, one header line, one row per observation, blank lines ignored;
//! lines may end in `\n` or `\r\n`, and a UTF-8 byte-order mark at the start is skipped.
//! Column headers carry their unit as a suffix (`z_m`, `sigma_v_Pa`); they are matched
//! case-insensitively after trimming, except the scaled units, which are read only as spelt
//! here: a column asked for in Pa is also read from `_kPa` (×10³) or `_MPa` (×10⁶), one in m
//! from `_mm` (×10⁻³), one in m/s (`_m_s`) from `_mm_s` (×10⁻³), converted on reading
//! ([`Table::column`]). A header with the column's name and another unit (`z_cm`,
//! `sigma_v_psi`, `sigma_v_kpa`) is refused with the expected header. Columns a law does not
//! use may hold anything. A header that is one field holding `;` or a tab is refused with a
//! hint about the delimiter.
//!
//! Lines starting with `#` are comments, except metadata lines. Grammar of a metadata line
//! (anywhere in the file):
//!
//! ```text
//! metadata := '#' key '=' value        (spaces allowed around each part)
//! key      := [A-Za-z_][A-Za-z0-9_]*
//! value    := a number as Rust's f64 parses it (1600, 0.03, 2.5e-3, inf, NaN)
//! ```
//!
//! A `#` line `# key = text` whose key has that form but whose text is not a number is kept
//! aside ([`Table::text_metadata`]): `grainlaw fit` refuses it when the law reads that key
//! (`'wide' is not a number`) and otherwise ignores it as a comment. Every other `#` line
//! (`# Janssen column`, `# note: mu = tau/P`) is a comment. A key given twice is refused. Which
//! keys a law reads, and that unknown keys are refused, is [`crate::user_fit`]'s business.
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
    /// `# key = value` constants (the value may be non-finite: the law's reader checks it).
    pub metadata: BTreeMap<String, f64>,
    /// 1-based line of each metadata key.
    pub metadata_lines: BTreeMap<String, u64>,
    /// `# key = text` lines whose text is not a number: `(key, text, line)`.
    pub text_metadata: Vec<(String, String, u64)>,
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
        // A UTF-8 byte-order mark (spreadsheets write one) is not part of the first header.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut metadata = BTreeMap::new();
        let mut metadata_lines = BTreeMap::new();
        let mut text_metadata = Vec::new();
        let mut headers: Option<Vec<String>> = None;
        let mut cells = Vec::new();
        let mut lines = Vec::new();
        let csv_error = |line: u64, message: String| IdentifyError::Csv {
            file: source.to_string(),
            line,
            message,
        };
        for (idx, raw) in text.lines().enumerate() {
            let line_no = idx as u64 + 1;
            let line = raw.trim();
            if line.is_empty() {
                continue;
            }
            if let Some(comment) = line.strip_prefix('#') {
                match metadata_line(comment) {
                    Some((key, Ok(v))) => {
                        if let Some(first) = metadata_lines.insert(key.to_string(), line_no) {
                            return Err(IdentifyError::Metadata {
                                file: source.to_string(),
                                message: format!(
                                    "line {line_no}: metadata '{key}' is given twice (first on line {first})"
                                ),
                            });
                        }
                        metadata.insert(key.to_string(), v);
                    }
                    Some((key, Err(text))) => {
                        text_metadata.push((key.to_string(), text.to_string(), line_no))
                    }
                    None => {}
                }
                continue;
            }
            let record = parse_record(line, source, line_no)?;
            match &headers {
                None => {
                    if record.len() == 1 {
                        if let Some(hint) = delimiter_hint(line) {
                            return Err(csv_error(
                                line_no,
                                format!("the header is one field '{line}': {hint}"),
                            ));
                        }
                    }
                    headers = Some(record)
                }
                Some(h) => {
                    if record.len() != h.len() {
                        let hint = delimiter_hint(line)
                            .map(|h| format!(" ({h})"))
                            .unwrap_or_default();
                        return Err(csv_error(
                            line_no,
                            format!(
                                "{} fields, but the header has {}{hint}",
                                record.len(),
                                h.len()
                            ),
                        ));
                    }
                    cells.push(record);
                    lines.push(line_no);
                }
            }
        }
        let headers = headers.ok_or_else(|| csv_error(0, "no header line".into()))?;
        Ok(Table {
            source: source.to_string(),
            metadata,
            metadata_lines,
            text_metadata,
            headers,
            cells,
            lines,
        })
    }

    /// Number of data rows.
    pub fn rows(&self) -> usize {
        self.cells.len()
    }

    /// The table with only the rows `r` for which `keep[r]` is true (metadata and headers
    /// unchanged, file lines kept for error messages).
    ///
    /// # Panics
    /// If `keep.len() != self.rows()` (programming error).
    pub fn with_rows(&self, keep: &[bool]) -> Table {
        assert_eq!(keep.len(), self.rows(), "one flag per row");
        let mut t = self.clone();
        let mut k = keep.iter();
        t.cells.retain(|_| *k.next().unwrap_or(&false));
        let mut k = keep.iter();
        t.lines.retain(|_| *k.next().unwrap_or(&false));
        t
    }

    fn index_of(&self, header: &str) -> Option<usize> {
        self.headers
            .iter()
            .position(|h| h.eq_ignore_ascii_case(header.trim()))
    }

    /// The header that holds `header` and the factor to its unit: the header itself (factor 1)
    /// or a scaled spelling of [`SCALED_UNITS`].
    fn locate(&self, header: &str) -> Option<(usize, f64)> {
        if let Some(j) = self.index_of(header) {
            return Some((j, 1.0));
        }
        let (stem, unit) = split_unit(header)?;
        SCALED_UNITS
            .iter()
            .filter(|(base, _, _)| *base == unit)
            .find_map(|(_, scaled, factor)| {
                self.headers
                    .iter()
                    .position(|h| is_stem_with_unit(h, stem, scaled, true))
                    .map(|j| (j, *factor))
            })
    }

    /// True when the header has `header` (or a scaled spelling of it).
    pub fn has_column(&self, header: &str) -> bool {
        self.locate(header).is_some()
    }

    /// The numeric column `header`, in its unit (a scaled spelling, `sigma_v_kPa` for
    /// `sigma_v_Pa`, is converted). Errors: [`IdentifyError::MissingColumn`] (naming the expected
    /// header when the column is there in a unit that is not read),
    /// [`IdentifyError::NonNumericCell`], [`IdentifyError::NonFiniteCell`].
    pub fn column(&self, header: &str) -> Result<Vec<f64>> {
        let (j, factor) = self
            .locate(header)
            .ok_or_else(|| IdentifyError::MissingColumn {
                file: self.source.clone(),
                column: header.to_string(),
                available: self.headers.join(", "),
                hint: self.unit_hint(header),
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
                Ok(v * factor)
            })
            .collect()
    }

    /// Why `header` was not found when the file has its name in a unit that is not read.
    fn unit_hint(&self, header: &str) -> crate::error::Suggestion {
        let Some((stem, unit)) = split_unit(header) else {
            return crate::error::Suggestion::none();
        };
        let found = self.headers.iter().find(|h| {
            UNIT_SPELLINGS
                .iter()
                .any(|u| is_stem_with_unit(h, stem, u, false))
        });
        let scaled: Vec<String> = SCALED_UNITS
            .iter()
            .filter(|(base, _, _)| *base == unit)
            .map(|(_, s, _)| format!("{stem}_{s}"))
            .collect();
        match found {
            Some(h) => crate::error::Suggestion::of(&format!(
                "column '{h}' is in a unit grainlaw does not read: name it '{header}'{}",
                if scaled.is_empty() {
                    String::new()
                } else {
                    format!(" (or {}, converted)", scaled.join(", "))
                }
            )),
            None => crate::error::Suggestion::none(),
        }
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

/// Scaled spellings read for a base unit: `(base, spelling, factor to the base)`. The spelling
/// is matched exactly (`kPa`, not `kpa`: `mPa` would be millipascal).
pub const SCALED_UNITS: [(&str, &str, f64); 4] = [
    ("Pa", "kPa", 1e3),
    ("Pa", "MPa", 1e6),
    ("m", "mm", 1e-3),
    ("m_s", "mm_s", 1e-3),
];

/// Unit spellings recognised as a unit suffix (case-insensitively) when a column is missing, to
/// say that it is there in a unit that is not read.
const UNIT_SPELLINGS: [&str; 17] = [
    "Pa", "kPa", "MPa", "GPa", "hPa", "bar", "psi", "atm", "m", "mm", "cm", "um", "km", "in",
    "m_s", "mm_s", "cm_s",
];

/// `(stem, unit)` of a header with a dimensional unit suffix (`sigma_v_Pa` → `sigma_v`, `Pa`;
/// `slip_velocity_m_s` → `slip_velocity`, `m_s`); `None` for other headers.
fn split_unit(header: &str) -> Option<(&str, &str)> {
    ["_m_s", "_Pa", "_m"].iter().find_map(|u| {
        header
            .strip_suffix(u)
            .filter(|stem| !stem.is_empty())
            .map(|stem| (stem, &u[1..]))
    })
}

/// True when `header` is `stem_unit` (stem case-insensitive; unit exact, or case-insensitive
/// when `exact_unit` is false).
fn is_stem_with_unit(header: &str, stem: &str, unit: &str, exact_unit: bool) -> bool {
    let h = header.trim();
    let n = stem.len();
    if h.len() != n + 1 + unit.len() || !h.is_char_boundary(n) || !h.is_char_boundary(n + 1) {
        return false;
    }
    let (head, rest) = h.split_at(n);
    let Some(u) = rest.strip_prefix('_') else {
        return false;
    };
    head.eq_ignore_ascii_case(stem)
        && if exact_unit {
            u == unit
        } else {
            u.eq_ignore_ascii_case(unit)
        }
}

/// `Some((key, value))` when a `#` comment is a metadata line (grammar in the module
/// documentation): `Ok(number)`, or `Err(text)` when the value is not a number.
fn metadata_line(comment: &str) -> Option<(&str, std::result::Result<f64, &str>)> {
    let (key, value) = comment.split_once('=')?;
    let (key, value) = (key.trim(), value.trim());
    let mut chars = key.chars();
    let first = chars.next()?;
    if !(first.is_ascii_alphabetic() || first == '_')
        || !chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
    {
        return None;
    }
    Some((key, value.parse::<f64>().map_err(|_| value)))
}

/// A hint when `line` looks delimited by `;` or tabs rather than commas.
fn delimiter_hint(line: &str) -> Option<String> {
    let (name, sep) = if line.contains(';') {
        ("semicolon", "';'")
    } else if line.contains('\t') {
        ("tab", "tabs")
    } else {
        return None;
    };
    Some(format!(
        "the file looks {name}-delimited; grainlaw reads comma-separated files (replace {sep} by ',', and decimal commas by points)"
    ))
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
        let t = Table::parse_csv("# w = wide\nx\n1\n", "m.csv").unwrap();
        assert_eq!(t.text_metadata, vec![("w".into(), "wide".into(), 1)]);
        let e = Table::parse_csv("# w = 1\n# w = 2\nx\n1\n", "m.csv").unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
    }

    #[test]
    fn comments_with_equals_signs_are_comments() {
        let t = Table::parse_csv(
            "# steady shear (I, mu = |sigma_xy|/P)\n# K = 0.6 at the bottom\n# g = 9.81\nx\n1\n",
            "c.csv",
        )
        .unwrap();
        assert_eq!(t.metadata.len(), 1);
        assert_eq!(t.metadata["g"], 9.81);
        assert_eq!(t.text_metadata.len(), 1);
    }

    #[test]
    fn scaled_units_are_converted_and_other_units_named() {
        let t = Table::parse_csv(
            "z_mm,Sigma_V_kPa,sigma_h_MPa,u_mm_s,tau_kpa\n10,1.5,0.002,3,1\n",
            "u.csv",
        )
        .unwrap();
        assert_eq!(t.column("z_m").unwrap(), vec![0.01]);
        assert_eq!(t.column("sigma_v_Pa").unwrap(), vec![1500.0]);
        assert_eq!(t.column("sigma_h_Pa").unwrap(), vec![2000.0]);
        assert!((t.column("u_m_s").unwrap()[0] - 0.003).abs() < 1e-18);
        let e = t.column("tau_Pa").unwrap_err().to_string();
        assert!(e.contains("'tau_kpa' is in a unit grainlaw does not read: name it 'tau_Pa' (or tau_kPa, tau_MPa, converted)"), "{e}");
    }

    #[test]
    fn other_delimiters_get_a_hint() {
        let e = Table::parse_csv("I;mu\n0,1;0,3\n", "s.csv").unwrap_err();
        assert!(e.to_string().contains("semicolon-delimited"), "{e}");
        let e = Table::parse_csv("I\tmu\n0.1\t0.3\n", "t.csv").unwrap_err();
        assert!(e.to_string().contains("tab-delimited"), "{e}");
    }
}
