//! `--set KEY=VALUE` overrides applied to a scenario's TOML table before it is deserialised.
//!
//! `KEY` is a dotted path (`grain.radius_mean`); it must already exist in the scenario (built-in
//! scenarios list every key), so a typo is an error rather than a silently ignored setting.
//! `VALUE` is read as a TOML value (`2000`, `1.5e-3`, `true`, `"text"`, `[1, 2]`); a bare word that
//! is not valid TOML is taken as a string. An integer given for a float key becomes a float; any
//! other type change is refused here with the expected type named.

use toml::{Table, Value};

use crate::error::{DatasetError, Result};

/// One parsed override.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// Dotted key path.
    pub key: Vec<String>,
    /// New value.
    pub value: Value,
    /// The argument as given, for messages.
    pub arg: String,
}

/// Parses `KEY=VALUE`.
pub fn parse_override(arg: &str) -> Result<Override> {
    let bad = |reason: &str| DatasetError::BadOverride {
        arg: arg.to_string(),
        reason: reason.to_string(),
    };
    let (k, v) = arg
        .split_once('=')
        .ok_or_else(|| bad("expected KEY=VALUE"))?;
    let k = k.trim();
    if k.is_empty() {
        return Err(bad("empty key"));
    }
    let key: Vec<String> = k.split('.').map(|s| s.trim().to_string()).collect();
    if key.iter().any(|s| s.is_empty()) {
        return Err(bad("empty part in the dotted key"));
    }
    let v = v.trim();
    if v.is_empty() {
        return Err(bad("empty value"));
    }
    let value = match format!("v = {v}").parse::<Table>() {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or_else(|| Value::String(v.to_string())),
        Err(_) => Value::String(v.to_string()),
    };
    Ok(Override {
        key,
        value,
        arg: arg.to_string(),
    })
}

fn type_name(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a number",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a date",
        Value::Array(_) => "an array",
        Value::Table(_) => "a table",
    }
}

/// Applies one override to `table` (see the module documentation). `source` names the scenario
/// in messages.
pub fn apply_override(table: &mut Table, o: &Override, source: &str) -> Result<()> {
    let mut t = table;
    let n = o.key.len();
    for (i, part) in o.key.iter().enumerate() {
        let dotted = o.key[..=i].join(".");
        let known = || {
            let mut k: Vec<&str> = t.keys().map(String::as_str).collect();
            k.sort_unstable();
            k.join(", ")
        };
        if !t.contains_key(part) {
            return Err(DatasetError::UnknownKey {
                source_name: source.to_string(),
                key: dotted,
                known: known(),
            });
        }
        if i + 1 < n {
            match t.get_mut(part) {
                Some(Value::Table(sub)) => t = sub,
                _ => {
                    return Err(DatasetError::BadOverride {
                        arg: o.arg.clone(),
                        reason: format!("`{dotted}` is not a table"),
                    })
                }
            }
        } else {
            let old = t.get(part).cloned().unwrap_or(Value::Boolean(false));
            let new = match (&old, &o.value) {
                (Value::Float(_), Value::Integer(i)) => Value::Float(*i as f64),
                (Value::String(_), Value::String(_)) => o.value.clone(),
                (Value::String(_), other) => Value::String(other.to_string()),
                (Value::Table(_), _) => {
                    return Err(DatasetError::BadOverride {
                        arg: o.arg.clone(),
                        reason: format!(
                            "`{dotted}` is a table; set one of its keys ({dotted}.KEY=VALUE)"
                        ),
                    })
                }
                (a, b) if std::mem::discriminant(a) == std::mem::discriminant(b) => o.value.clone(),
                (a, b) => {
                    return Err(DatasetError::Type {
                        source_name: source.to_string(),
                        key: dotted,
                        reason: format!("expects {}, got {} ({})", type_name(a), type_name(b), b),
                    })
                }
            };
            t.insert(part.clone(), new);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> Table {
        "seed = 1\ngrains = 350\n[grain]\nradius_mean = 1.5e-3\nname = \"a\"\n"
            .parse()
            .unwrap()
    }

    #[test]
    fn dotted_keys_and_integer_to_float() {
        let mut t = table();
        apply_override(&mut t, &parse_override("grain.radius_mean=2").unwrap(), "x").unwrap();
        assert_eq!(t["grain"]["radius_mean"].as_float(), Some(2.0));
        apply_override(&mut t, &parse_override("grains=2000").unwrap(), "x").unwrap();
        assert_eq!(t["grains"].as_integer(), Some(2000));
        apply_override(&mut t, &parse_override("grain.name=word").unwrap(), "x").unwrap();
        assert_eq!(t["grain"]["name"].as_str(), Some("word"));
    }

    #[test]
    fn unknown_key_and_wrong_type_are_refused() {
        let mut t = table();
        let e =
            apply_override(&mut t, &parse_override("grain.radius=2").unwrap(), "x").unwrap_err();
        assert!(e.to_string().contains("unknown key `grain.radius`"), "{e}");
        let e = apply_override(&mut t, &parse_override("grains=1.5").unwrap(), "x").unwrap_err();
        assert!(e.to_string().contains("expects an integer"), "{e}");
        let e = apply_override(&mut t, &parse_override("grain=1").unwrap(), "x").unwrap_err();
        assert!(e.to_string().contains("is a table"), "{e}");
        assert!(parse_override("grains").is_err());
        assert!(parse_override("=3").is_err());
    }
}
