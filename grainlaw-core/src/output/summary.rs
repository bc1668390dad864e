//! `summary.json`: the key results of a run as one flat JSON object, SI units, keys in the order
//! they were added. Non-finite numbers are written as `null`.

use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Flat, ordered key → value pairs (serialisable, for run checkpoints of summaries built step
/// by step).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Summary {
    entries: Vec<(String, Value)>,
}

impl Summary {
    /// An empty summary.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets a number (replaces an earlier value of the same key).
    pub fn num(&mut self, key: &str, v: f64) -> &mut Self {
        let v = serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number);
        self.set(key, v)
    }

    /// Sets an integer.
    pub fn int(&mut self, key: &str, v: u64) -> &mut Self {
        self.set(key, Value::from(v))
    }

    /// Sets a string.
    pub fn text(&mut self, key: &str, v: &str) -> &mut Self {
        self.set(key, Value::from(v))
    }

    /// Sets a boolean.
    pub fn flag(&mut self, key: &str, v: bool) -> &mut Self {
        self.set(key, Value::from(v))
    }

    /// Sets any JSON value.
    pub fn set(&mut self, key: &str, v: Value) -> &mut Self {
        if let Some(e) = self.entries.iter_mut().find(|(k, _)| k == key) {
            e.1 = v;
        } else {
            self.entries.push((key.to_string(), v));
        }
        self
    }

    /// The value of a key.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.entries.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    /// The number under a key.
    pub fn get_f64(&self, key: &str) -> Option<f64> {
        self.get(key).and_then(Value::as_f64)
    }

    /// The entries in order.
    pub fn entries(&self) -> &[(String, Value)] {
        &self.entries
    }

    /// Pretty JSON text, keys in insertion order.
    pub fn to_json(&self) -> String {
        let mut s = String::from("{\n");
        for (i, (k, v)) in self.entries.iter().enumerate() {
            s.push_str("  ");
            s.push_str(&Value::from(k.as_str()).to_string());
            s.push_str(": ");
            s.push_str(&v.to_string());
            if i + 1 < self.entries.len() {
                s.push(',');
            }
            s.push('\n');
        }
        s.push_str("}\n");
        s
    }
}
