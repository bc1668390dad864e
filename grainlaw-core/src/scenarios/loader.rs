//! Loading a scenario: a built-in name or a TOML path, `--set` overrides applied on the TOML
//! table, then typed deserialisation (`deny_unknown_fields`) and validation.

use std::any::Any;
use std::path::Path;
use std::sync::Arc;

use serde::de::DeserializeOwned;
use toml::{Table, Value};

use datasets::error::{DatasetError, Result};
use datasets::overrides::{apply_override, parse_override};

/// A typed, validated scenario configuration: what every scenario kind's config struct
/// (`janssen::config::JanssenConfig`, …) tells the loader and the runners, whatever its keys.
/// Each kind implements it beside its runner (`scenarios/NAME/mod.rs`); the list of
/// kinds, with their built-in TOML and their runners, is the registry
/// ([`crate::scenarios::registry`]), which the loader reads through [`Catalogue`].
pub trait ScenarioConfig: std::fmt::Debug + Send + Sync + Any {
    /// The scenario kind (`janssen`, `rolling`, ...), the value of its `scenario` key.
    fn kind(&self) -> &'static str;

    /// The seed.
    fn seed(&self) -> u64;

    /// Checks every value, naming the key at fault (the struct's `validate`).
    fn check(&self) -> Result<()>;

    /// The laws it fits and the data each needs (`common::laws`); none by default.
    fn law_needs(&self) -> Vec<crate::scenarios::common::laws::LawNeed> {
        Vec::new()
    }

    /// The laws the plan leaves out (`leave_out`; empty for a scenario without the key).
    fn leave_out(&self) -> &[String] {
        &[]
    }

    /// A line said at the start of a run about the plan's length, if the kind has one.
    fn plan_note(&self) -> Option<String> {
        None
    }

    /// How many grains its largest world holds (before it is built).
    fn grains(&self) -> usize;

    /// Builds every world its runner builds first (the *build* stage, without running it):
    /// everything the generators and the engine would refuse is refused here.
    fn build_first(&self) -> Result<()>;

    /// The config as `Any`, for the runner of its kind to take its own type back.
    fn as_any(&self) -> &dyn Any;
}

/// The methods every kind writes the same way: `seed`, `check` (the struct's `validate`),
/// `as_any`; used by each kind's implementation (`scenarios/NAME/mod.rs`).
macro_rules! common_methods {
    () => {
        fn seed(&self) -> u64 {
            self.seed
        }

        fn check(&self) -> datasets::Result<()> {
            self.validate()
        }

        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
    };
}
pub(crate) use common_methods;

impl dyn ScenarioConfig {
    /// Whether the plan leaves the law `law` out.
    pub fn leaves_out(&self, law: &str) -> bool {
        self.leave_out().iter().any(|l| l == law)
    }

    /// The config as its own type, if it is of that type.
    pub fn downcast_ref<C: ScenarioConfig>(&self) -> Option<&C> {
        self.as_any().downcast_ref::<C>()
    }
}

/// The scenario kinds the loader knows: their built-in TOML texts and their typed
/// configurations. Implemented by the registry ([`crate::scenarios::registry`]), the one list of
/// scenarios.
pub trait Catalogue {
    /// The full TOML text of the built-in scenario `name`, if there is one.
    fn builtin_toml(&self, name: &str) -> Option<&'static str>;

    /// The built-in names, comma separated (for messages).
    fn names(&self) -> String;

    /// The typed, validated configuration of kind `kind` from its TOML table (`None` for a kind
    /// it does not know). [`typed_config`] is the usual implementation for one kind.
    fn config(
        &self,
        kind: &str,
        table: Table,
        source: &str,
    ) -> Option<Result<Arc<dyn ScenarioConfig>>>;
}

/// The typed configuration `C` of `table` (unknown keys refused, [`typed`]), validated
/// ([`ScenarioConfig::check`]), errors naming `source`.
pub fn typed_config<C: ScenarioConfig + DeserializeOwned>(
    table: Table,
    source: &str,
) -> Result<Arc<dyn ScenarioConfig>> {
    let c: C = typed(table, source)?;
    c.check().map_err(|e| e.in_source(source))?;
    Ok(Arc::new(c))
}

/// A loaded scenario with where it came from and its effective TOML (overrides applied).
#[derive(Debug, Clone)]
pub struct LoadedScenario {
    /// Name: the built-in's, or the file stem.
    pub name: String,
    /// `builtin:NAME` or the file path.
    pub source: String,
    /// The TOML actually run, overrides included (written next to the results).
    pub effective_toml: String,
    /// The typed scenario configuration.
    pub config: Arc<dyn ScenarioConfig>,
}

/// Position (1-based line, column) of byte `offset` in `text`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before
        .rfind('\n')
        .map_or(before.len(), |p| before.len() - p - 1)
        + 1;
    (line, col)
}

/// Parses TOML text into a table with a one-line error naming the line.
pub fn parse_table(text: &str, source: &str) -> Result<Table> {
    text.parse::<Table>().map_err(|e| {
        let (line, column) = e.span().map_or((1, 1), |s| line_col(text, s.start));
        DatasetError::Syntax {
            source_name: source.to_string(),
            line,
            column,
            message: e.message().lines().next().unwrap_or("").trim().to_string(),
        }
    })
}

/// Deserialises a table into `T` (unknown keys refused), naming the key of a type error.
pub fn typed<T: DeserializeOwned>(table: Table, source: &str) -> Result<T> {
    let value = Value::Table(table);
    serde_path_to_error::deserialize::<_, T>(value).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        let msg = inner
            .message()
            .lines()
            .next()
            .unwrap_or("")
            .trim()
            .to_string();
        if let Some(rest) = msg.strip_prefix("unknown field `") {
            let (field, tail) = rest.split_once('`').unwrap_or((rest, ""));
            let key = if path == "." || path.is_empty() {
                field.to_string()
            } else if path == field || path.ends_with(&format!(".{field}")) {
                path.clone()
            } else {
                format!("{path}.{field}")
            };
            let known = tail
                .trim_start_matches(", expected one of ")
                .trim_start_matches(", expected ")
                .replace('`', "");
            DatasetError::UnknownKey {
                source_name: source.to_string(),
                key,
                known,
            }
        } else if let Some(rest) = msg.strip_prefix("missing field `") {
            let field = rest.split('`').next().unwrap_or(rest);
            let key = if path == "." || path.is_empty() {
                field.to_string()
            } else {
                format!("{path}.{field}")
            };
            DatasetError::Type {
                source_name: source.to_string(),
                key,
                reason: "missing (every key of the scenario must be given)".into(),
            }
        } else {
            DatasetError::Type {
                source_name: source.to_string(),
                key: if path.is_empty() { ".".into() } else { path },
                reason: msg,
            }
        }
    })
}

/// Loads `spec` (a built-in name of `catalogue` or a TOML file path), applies `sets`
/// (`KEY=VALUE`), then deserialises and validates it as its kind in `catalogue`.
pub fn load(catalogue: &dyn Catalogue, spec: &str, sets: &[String]) -> Result<LoadedScenario> {
    let (name, source, text) = if let Some(toml) = catalogue.builtin_toml(spec) {
        (
            spec.to_string(),
            format!("builtin:{spec}"),
            toml.to_string(),
        )
    } else {
        let path = Path::new(spec);
        let looks_like_file = spec.ends_with(".toml") || spec.contains('/') || path.exists();
        if !looks_like_file {
            return Err(DatasetError::UnknownScenario {
                name: spec.to_string(),
                known: catalogue.names(),
            });
        }
        let text = std::fs::read_to_string(path).map_err(|e| DatasetError::Io {
            path: spec.to_string(),
            reason: e.to_string(),
        })?;
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scenario")
            .to_string();
        (stem, spec.to_string(), text)
    };
    from_text(catalogue, &name, &source, &text, sets)
}

/// Like [`load`] from TOML text already read; `source` names it in messages.
pub fn from_text(
    catalogue: &dyn Catalogue,
    name: &str,
    source: &str,
    text: &str,
    sets: &[String],
) -> Result<LoadedScenario> {
    let mut table = parse_table(text, source)?;
    let kind_before = table.get("scenario").cloned();
    for s in sets {
        let o = parse_override(s)?;
        apply_override(&mut table, &o, source)?;
    }
    if kind_before.is_some() && table.get("scenario") != kind_before.as_ref() {
        return Err(DatasetError::BadOverride {
            arg: sets
                .iter()
                .find(|s| s.trim_start().starts_with("scenario"))
                .cloned()
                .unwrap_or_default(),
            reason: "the scenario kind cannot be changed with --set (its keys differ); \
                     name the built-in or TOML file of that kind instead"
                .into(),
        });
    }
    let effective_toml = if sets.is_empty() {
        text.to_string()
    } else {
        let mut t = format!("# {source} with --set {}\n", sets.join(" --set "));
        t.push_str(&toml::to_string(&table).unwrap_or_default());
        t
    };
    let kind = match table.get("scenario") {
        Some(Value::String(s)) => s.clone(),
        Some(other) => {
            return Err(DatasetError::Type {
                source_name: source.to_string(),
                key: "scenario".into(),
                reason: format!("expects a string, got {other}"),
            })
        }
        None => {
            return Err(DatasetError::Type {
                source_name: source.to_string(),
                key: "scenario".into(),
                reason: format!("missing: name the scenario kind ({})", catalogue.names()),
            })
        }
    };
    let config = catalogue.config(&kind, table, source).unwrap_or_else(|| {
        Err(DatasetError::invalid(
            "scenario",
            format!(
                "unknown scenario kind `{kind}` (known: {})",
                catalogue.names()
            ),
        )
        .in_source(source))
    })?;
    // before the run, not after: a plan that cannot identify a law it fits is refused here
    crate::scenarios::common::laws::check(&config.law_needs(), config.leave_out())
        .map_err(|e| e.in_source(source))?;
    Ok(LoadedScenario {
        name: name.to_string(),
        source: source.to_string(),
        effective_toml,
        config,
    })
}
