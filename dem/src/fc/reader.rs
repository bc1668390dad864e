//! Reader for fc-problem-v1 JSON files (plain or gzip-compressed).
//!
//! ```text
//! {"format": "fc-problem-v1", "dimension": 2, "nc": N, "mu": [N], "q": [2N],
//!  "W": {"storage": "coo", "shape": [2N, 2N], "row": [..], "col": [..], "val": [..]}
//!     | {"storage": "dense", "data": [[row 0], [row 1], ..]},
//!  "meta": {..}}
//! ```
//!
//! Every check names the key it fails on: missing keys, wrong types, lengths that do not match
//! `nc`, a non-square `W`, indices out of range, `μ < 0`, non-finite numbers (including the
//! `NaN` / `Infinity` literals some writers emit), truncated text. `dimension = 3` is refused with
//! [`FcError::Unsupported3D`].

use std::io::Read;
use std::path::Path;

use serde_json::{Map, Value};

use super::block_csr::BlockCsr2;
use super::error::FcError;
use super::problem::FcProblem;

/// Reads a problem from a file; gzip-compressed content (`.json.gz`) is recognised by its magic
/// bytes, whatever the extension.
///
/// Errors: [`FcError::Io`] (unreadable file, cut gzip stream) and, for a content error, the
/// error of [`parse_problem`] wrapped in [`FcError::InFile`], so that every message names the
/// file and then the key (`p.json: key mu[1]: friction coefficient -0.5 < 0`); use
/// [`FcError::kind`] to match on the inner error.
pub fn read_problem(path: impl AsRef<Path>) -> Result<FcProblem, FcError> {
    let path = path.as_ref();
    let io = |source| FcError::Io {
        path: path.display().to_string(),
        source,
    };
    let bytes = std::fs::read(path).map_err(io)?;
    let text = decompress_if_gzip(bytes).map_err(io)?;
    parse_problem(&text).map_err(|e| FcError::InFile {
        path: path.display().to_string(),
        source: Box::new(e),
    })
}

/// Returns the bytes unchanged, or their gzip-decompressed content if they start with the gzip
/// magic number `1f 8b`.
pub fn decompress_if_gzip(bytes: Vec<u8>) -> std::io::Result<Vec<u8>> {
    if bytes.len() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b {
        let mut out = Vec::with_capacity(bytes.len() * 4);
        flate2::read::MultiGzDecoder::new(&bytes[..]).read_to_end(&mut out)?;
        Ok(out)
    } else {
        Ok(bytes)
    }
}

/// Parses and validates the JSON text of one problem.
pub fn parse_problem(text: &[u8]) -> Result<FcProblem, FcError> {
    let value: Value = serde_json::from_slice(text).map_err(|e| json_error(text, &e))?;
    let obj = value.as_object().ok_or_else(|| FcError::InvalidValue {
        key: "(top level)".into(),
        reason: "expected a JSON object".into(),
    })?;
    if let Some(f) = obj.get("format") {
        if f.as_str() != Some("fc-problem-v1") {
            return Err(FcError::InvalidValue {
                key: "format".into(),
                reason: format!("{f} is not \"fc-problem-v1\""),
            });
        }
    }
    let dimension = get_usize(obj, "dimension", "dimension")?;
    match dimension {
        2 => {}
        3 => return Err(FcError::Unsupported3D { dimension }),
        d => {
            return Err(FcError::InvalidValue {
                key: "dimension".into(),
                reason: format!("{d} is neither 2 nor 3"),
            })
        }
    }
    let nc = get_usize(obj, "nc", "nc")?;
    let mu = f64_array(require(obj, "mu", "mu")?, "mu")?;
    if mu.len() != nc {
        return Err(FcError::SizeMismatch {
            key: "mu".into(),
            expected: nc,
            found: mu.len(),
        });
    }
    for (i, &m) in mu.iter().enumerate() {
        if m < 0.0 {
            return Err(FcError::NegativeFriction {
                contact: i,
                value: m,
            });
        }
    }
    let q = f64_array(require(obj, "q", "q")?, "q")?;
    if q.len() != 2 * nc {
        return Err(FcError::SizeMismatch {
            key: "q".into(),
            expected: 2 * nc,
            found: q.len(),
        });
    }
    let wv = require(obj, "W", "W")?;
    let w = wv.as_object().ok_or_else(|| FcError::InvalidValue {
        key: "W".into(),
        reason: "expected an object".into(),
    })?;
    let storage = match w.get("storage") {
        None => "coo",
        Some(s) => s.as_str().ok_or_else(|| FcError::InvalidValue {
            key: "W.storage".into(),
            reason: format!("{s} is not a string"),
        })?,
    };
    let matrix = match storage {
        "coo" => {
            let shape = usize_array(require(w, "shape", "W.shape")?, "W.shape")?;
            if shape.len() != 2 {
                return Err(FcError::SizeMismatch {
                    key: "W.shape".into(),
                    expected: 2,
                    found: shape.len(),
                });
            }
            if shape[0] != shape[1] {
                return Err(FcError::NotSquare {
                    key: "W.shape".into(),
                    rows: shape[0],
                    cols: shape[1],
                });
            }
            if shape[0] != 2 * nc {
                return Err(FcError::SizeMismatch {
                    key: "W.shape".into(),
                    expected: 2 * nc,
                    found: shape[0],
                });
            }
            let row = usize_array(require(w, "row", "W.row")?, "W.row")?;
            let col = usize_array(require(w, "col", "W.col")?, "W.col")?;
            let val = f64_array(require(w, "val", "W.val")?, "W.val")?;
            BlockCsr2::from_triplets(nc, &row, &col, &val)?
        }
        "dense" => {
            let data =
                require(w, "data", "W.data")?
                    .as_array()
                    .ok_or_else(|| FcError::InvalidValue {
                        key: "W.data".into(),
                        reason: "expected an array of rows".into(),
                    })?;
            let rows = data
                .iter()
                .enumerate()
                .map(|(i, r)| f64_array(r, &format!("W.data[{i}]")))
                .collect::<Result<Vec<_>, _>>()?;
            if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != rows.len()) {
                return Err(FcError::NotSquare {
                    key: format!("W.data[{i}]"),
                    rows: rows.len(),
                    cols: r.len(),
                });
            }
            if rows.len() != 2 * nc {
                return Err(FcError::SizeMismatch {
                    key: "W.data".into(),
                    expected: 2 * nc,
                    found: rows.len(),
                });
            }
            BlockCsr2::from_dense(&rows)?
        }
        other => {
            return Err(FcError::InvalidValue {
                key: "W.storage".into(),
                reason: format!("\"{other}\" is neither \"coo\" nor \"dense\""),
            })
        }
    };
    FcProblem::new(mu, q, matrix)
}

fn require<'a>(obj: &'a Map<String, Value>, key: &str, path: &str) -> Result<&'a Value, FcError> {
    obj.get(key)
        .ok_or_else(|| FcError::MissingKey { key: path.into() })
}

fn get_usize(obj: &Map<String, Value>, key: &str, path: &str) -> Result<usize, FcError> {
    let v = require(obj, key, path)?;
    as_usize(v).ok_or_else(|| FcError::InvalidValue {
        key: path.into(),
        reason: format!("{v} is not a non-negative integer"),
    })
}

fn as_usize(v: &Value) -> Option<usize> {
    v.as_u64().and_then(|x| usize::try_from(x).ok())
}

fn f64_array(v: &Value, key: &str) -> Result<Vec<f64>, FcError> {
    let a = v.as_array().ok_or_else(|| FcError::InvalidValue {
        key: key.into(),
        reason: "expected an array of numbers".into(),
    })?;
    a.iter()
        .enumerate()
        .map(|(i, x)| match x.as_f64() {
            Some(f) if f.is_finite() => Ok(f),
            Some(_) => Err(FcError::NonFinite {
                key: format!("{key}[{i}]"),
            }),
            None => Err(FcError::InvalidValue {
                key: format!("{key}[{i}]"),
                reason: format!("{x} is not a number"),
            }),
        })
        .collect()
}

fn usize_array(v: &Value, key: &str) -> Result<Vec<usize>, FcError> {
    let a = v.as_array().ok_or_else(|| FcError::InvalidValue {
        key: key.into(),
        reason: "expected an array of non-negative integers".into(),
    })?;
    a.iter()
        .enumerate()
        .map(|(i, x)| {
            as_usize(x).ok_or_else(|| FcError::InvalidValue {
                key: format!("{key}[{i}]"),
                reason: format!("{x} is not a non-negative integer"),
            })
        })
        .collect()
}

/// Turns a serde_json syntax error into [`FcError::Json`] with the enclosing key, or into
/// [`FcError::NonFinite`] when the offending token is a `NaN` / `Infinity` literal or a number
/// beyond the range of f64.
fn json_error(text: &[u8], e: &serde_json::Error) -> FcError {
    let offset = byte_offset(text, e.line(), e.column());
    let key = last_key_before(text, offset);
    // serde_json points at (or just after) the start of the token it could not read.
    let lo = offset.saturating_sub(2);
    let window = &text[lo..text.len().min(offset + 10)];
    let non_finite = [&b"NaN"[..], b"Infinity"]
        .iter()
        .any(|lit| window.windows(lit.len()).any(|w| w == *lit));
    if non_finite || e.to_string().starts_with("number out of range") {
        return FcError::NonFinite {
            key: key.unwrap_or_else(|| "(unknown)".into()),
        };
    }
    FcError::Json {
        line: e.line(),
        column: e.column(),
        near: key
            .map(|k| format!(" (in key \"{k}\")"))
            .unwrap_or_default(),
        message: e.to_string(),
    }
}

/// Byte offset of a 1-based (line, column) position, clamped to the text.
fn byte_offset(text: &[u8], line: usize, column: usize) -> usize {
    let mut start = 0;
    let mut l = 1;
    while l < line {
        match text[start..].iter().position(|&b| b == b'\n') {
            Some(p) => start += p + 1,
            None => break,
        }
        l += 1;
    }
    (start + column.saturating_sub(1)).min(text.len())
}

/// The last object key (`"name":`) that starts before `offset`.
fn last_key_before(text: &[u8], offset: usize) -> Option<String> {
    let t = &text[..offset.min(text.len())];
    let mut i = t.len();
    while i > 0 {
        i -= 1;
        if t[i] != b':' {
            continue;
        }
        // Skip whitespace back to the closing quote of the key.
        let mut j = i;
        while j > 0 && t[j - 1].is_ascii_whitespace() {
            j -= 1;
        }
        if j == 0 || t[j - 1] != b'"' {
            continue;
        }
        let end = j - 1;
        let start = t[..end].iter().rposition(|&b| b == b'"')? + 1;
        return Some(String::from_utf8_lossy(&t[start..end]).into_owned());
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_is_found_before_an_error_position() {
        let t = br#"{"nc": 2, "q": [1, 2, "#;
        assert_eq!(last_key_before(t, t.len()).as_deref(), Some("q"));
        assert_eq!(byte_offset(b"ab\ncd", 2, 2), 4);
    }
}
