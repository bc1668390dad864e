//! Typed rows of the scenarios' CSV tables: one struct per table with a named field per column
//! (`table_row!`), so that no runner reads a column by its position. The CSV text is still
//! written by [`CsvTable`] (the same headers, `{:e}` numbers, NaN as an empty cell), so a
//! table of typed rows is byte for byte the table of `Vec<f64>` rows it replaces; in a run
//! checkpoint a `Vec` of rows is stored as the `Vec<Vec<f64>>` it was ([`serde_rows`]).

use crate::output::CsvTable;

/// A row of a CSV table: its columns in order, with their headers.
pub trait TableRow: Sized {
    /// The headers, one per column, in the order of the CSV file.
    const HEADERS: &'static [&'static str];
    /// The values in the order of [`Self::HEADERS`].
    fn to_values(&self) -> Vec<f64>;
    /// The row from values in the order of [`Self::HEADERS`] (missing values NaN).
    fn from_values(values: &[f64]) -> Self;
}

/// Declares a struct of `f64` columns and its [`TableRow`] implementation:
///
/// ```ignore
/// table_row! {
///     /// One step.
///     pub struct StepRow {
///         /// Time (s).
///         t: "t_s",
///         /// Shear stress (Pa).
///         tau: "tau_Pa",
///     }
/// }
/// ```
macro_rules! table_row {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$fmeta:meta])* $field:ident : $header:literal ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        $vis struct $name {
            $( $(#[$fmeta])* pub $field: f64, )*
        }

        impl $crate::scenarios::rows::TableRow for $name {
            const HEADERS: &'static [&'static str] = &[$($header),*];

            fn to_values(&self) -> Vec<f64> {
                vec![$(self.$field),*]
            }

            fn from_values(values: &[f64]) -> Self {
                let mut it = values.iter().copied();
                Self {
                    $( $field: it.next().unwrap_or(f64::NAN), )*
                }
            }
        }
    };
}
pub(crate) use table_row;

/// The table of `rows` under their headers, without comments or metadata.
pub fn table<R: TableRow>(rows: &[R]) -> CsvTable {
    let mut t = CsvTable::new(R::HEADERS);
    for r in rows {
        t.push(r.to_values());
    }
    t
}

/// The rows of a table whose headers are `R`'s (in a checkpoint or read back).
pub fn rows_of<R: TableRow>(t: &CsvTable) -> Vec<R> {
    debug_assert_eq!(t.headers, R::HEADERS);
    t.rows.iter().map(|v| R::from_values(v)).collect()
}

/// Serde for `Vec<R>` of typed rows as the `Vec<Vec<f64>>` of their values
/// ([`crate::floats::table`], non-finite values included): the run checkpoints keep their
/// format. Use with `#[serde(with = "crate::scenarios::rows::serde_rows")]`.
pub mod serde_rows {
    use serde::{Deserializer, Serializer};

    use super::TableRow;

    /// Serialise.
    pub fn serialize<R: TableRow, S: Serializer>(v: &[R], s: S) -> Result<S::Ok, S::Error> {
        let t: Vec<Vec<f64>> = v.iter().map(R::to_values).collect();
        crate::floats::table::serialize(&t, s)
    }

    /// Deserialise.
    pub fn deserialize<'de, R: TableRow, D: Deserializer<'de>>(d: D) -> Result<Vec<R>, D::Error> {
        Ok(crate::floats::table::deserialize(d)?
            .iter()
            .map(|v| R::from_values(v))
            .collect())
    }
}

/// Serde for `Vec<R>` of typed rows as the [`CsvTable`] of [`table`] (no comments or metadata),
/// for a state that kept the table itself: its run checkpoints keep their format. Use with
/// `#[serde(with = "crate::scenarios::rows::serde_csv_table")]`.
pub mod serde_csv_table {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use super::{rows_of, table, TableRow};
    use crate::output::CsvTable;

    /// Serialise.
    pub fn serialize<R: TableRow, S: Serializer>(v: &[R], s: S) -> Result<S::Ok, S::Error> {
        table(v).serialize(s)
    }

    /// Deserialise.
    pub fn deserialize<'de, R: TableRow, D: Deserializer<'de>>(d: D) -> Result<Vec<R>, D::Error> {
        Ok(rows_of(&CsvTable::deserialize(d)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    table_row! {
        /// A test row.
        struct Two {
            /// First.
            a: "a_s",
            /// Second.
            b: "b_Pa",
        }
    }

    #[test]
    fn typed_rows_write_the_same_text_as_value_rows() {
        let rows = [
            Two {
                a: 1.5,
                b: f64::NAN,
            },
            Two { a: -2e-7, b: 3.0 },
        ];
        let mut plain = CsvTable::new(&["a_s", "b_Pa"]);
        plain.push(vec![1.5, f64::NAN]);
        plain.push(vec![-2e-7, 3.0]);
        assert_eq!(table(&rows).to_text(), plain.to_text());
        assert_eq!(table(&rows).to_text(), "a_s,b_Pa\n1.5e0,\n-2e-7,3e0\n");
        let back: Vec<Two> = rows_of(&plain);
        assert_eq!(back[1], rows[1]);
        assert!(back[0].b.is_nan());
    }

    #[test]
    fn rows_keep_the_checkpoint_format() {
        #[derive(serde::Serialize, serde::Deserialize)]
        struct Typed {
            #[serde(with = "serde_rows")]
            rows: Vec<Two>,
        }
        #[derive(serde::Serialize)]
        struct Plain {
            #[serde(with = "crate::floats::table")]
            rows: Vec<Vec<f64>>,
        }
        let typed = Typed {
            rows: vec![Two {
                a: 0.1,
                b: f64::INFINITY,
            }],
        };
        let plain = Plain {
            rows: vec![vec![0.1, f64::INFINITY]],
        };
        let json = serde_json::to_string(&typed).unwrap();
        assert_eq!(json, serde_json::to_string(&plain).unwrap());
        let back: Typed = serde_json::from_str(&json).unwrap();
        assert_eq!(back.rows, typed.rows);
        #[derive(serde::Serialize, serde::Deserialize)]
        struct AsTable {
            #[serde(with = "serde_csv_table")]
            rows: Vec<Two>,
        }
        #[derive(serde::Serialize)]
        struct Kept {
            rows: CsvTable,
        }
        let mut kept = CsvTable::new(&["a_s", "b_Pa"]);
        kept.push(vec![0.1, f64::INFINITY]);
        let json = serde_json::to_string(&AsTable { rows: typed.rows }).unwrap();
        assert_eq!(json, serde_json::to_string(&Kept { rows: kept }).unwrap());
        let back: AsTable = serde_json::from_str(&json).unwrap();
        assert_eq!(back.rows[0].a, 0.1);
    }
}
