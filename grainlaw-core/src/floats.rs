//! Serde for `f64` collections that may hold non-finite values (a CSV cell not measured yet is
//! NaN, an interval may be infinite), used by the run checkpoints: finite values as JSON numbers
//! (read back exactly), `nan`, `inf`, `-inf` as strings ([`dem::serde_float`]). serde_json alone
//! writes a non-finite number as `null` and cannot read it back.
//!
//! Use with `#[serde(with = "crate::floats::vec")]` (`Vec<f64>`), `crate::floats::table`
//! (`Vec<Vec<f64>>`) or `crate::floats::pairs` (`Vec<(String, f64)>`).

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// One `f64` that survives a JSON round trip, non-finite included.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Exact(#[serde(with = "dem::serde_float")] pub f64);

/// `Vec<f64>`.
pub mod vec {
    use super::*;

    /// Serialise.
    pub fn serialize<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(v.iter().map(|x| Exact(*x)))
    }

    /// Deserialise.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        Ok(Vec::<Exact>::deserialize(d)?
            .into_iter()
            .map(|x| x.0)
            .collect())
    }
}

/// `Vec<Vec<f64>>`.
pub mod table {
    use super::*;

    /// Serialise.
    pub fn serialize<S: Serializer>(v: &[Vec<f64>], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(
            v.iter()
                .map(|row| row.iter().map(|x| Exact(*x)).collect::<Vec<_>>()),
        )
    }

    /// Deserialise.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vec<f64>>, D::Error> {
        Ok(Vec::<Vec<Exact>>::deserialize(d)?
            .into_iter()
            .map(|row| row.into_iter().map(|x| x.0).collect())
            .collect())
    }
}

/// `Vec<(String, f64)>`.
pub mod pairs {
    use super::*;

    /// Serialise.
    pub fn serialize<S: Serializer>(v: &[(String, f64)], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(v.iter().map(|(k, x)| (k, Exact(*x))))
    }

    /// Deserialise.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<(String, f64)>, D::Error> {
        Ok(Vec::<(String, Exact)>::deserialize(d)?
            .into_iter()
            .map(|(k, x)| (k, x.0))
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct T {
        #[serde(with = "table")]
        rows: Vec<Vec<f64>>,
        #[serde(with = "pairs")]
        meta: Vec<(String, f64)>,
    }

    /// Every value comes back bit for bit, NaN and infinities included.
    #[test]
    fn round_trip_is_exact() {
        let rows = vec![
            vec![0.1 + 0.2, f64::NAN, 1e-300, -0.0],
            vec![
                f64::INFINITY,
                f64::NEG_INFINITY,
                std::f64::consts::PI,
                5e-324,
            ],
        ];
        let t = T {
            rows: rows.clone(),
            meta: vec![("a".into(), 1.0 / 3.0)],
        };
        let text = serde_json::to_string(&t).unwrap();
        let back: T = serde_json::from_str(&text).unwrap();
        for (a, b) in rows.iter().flatten().zip(back.rows.iter().flatten()) {
            assert_eq!(a.to_bits(), b.to_bits(), "{a} != {b} after {text}");
        }
        assert_eq!(back.meta[0].1.to_bits(), (1.0f64 / 3.0).to_bits());
    }
}
