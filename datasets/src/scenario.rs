//! Loading a scenario: a built-in name or a TOML path, `--set` overrides applied on the TOML
//! table, then typed deserialisation (`deny_unknown_fields`) and validation.

use std::path::Path;

use serde::de::DeserializeOwned;
use toml::{Table, Value};

use crate::builtin::{builtin, builtin_names};
use crate::config::{
    ArrangementsConfig, BiaxialConfig, ColumnCollapseConfig, InclinedFlowConfig, JanssenConfig,
    RollingConfig, ShearCellConfig, SimpleShearConfig, StickSlipConfig,
};
use crate::error::{DatasetError, Result};
use crate::overrides::{apply_override, parse_override};

/// A typed, validated scenario.
#[derive(Debug, Clone, PartialEq)]
pub enum Scenario {
    /// Janssen column.
    Janssen(JanssenConfig),
    /// One disk rolling on a slope.
    Rolling(RollingConfig),
    /// Stacks in a box.
    Arrangements(ArrangementsConfig),
    /// Bottom wall pushed up under a deposit.
    StickSlip(StickSlipConfig),
    /// Flow down a rough slope.
    InclinedFlow(InclinedFlowConfig),
    /// Plane shear at imposed pressure.
    ShearCell(ShearCellConfig),
    /// Lees–Edwards shear of a biperiodic cell at imposed normal stress.
    SimpleShear(SimpleShearConfig),
    /// Biaxial compression of a biperiodic cell at constant lateral stress.
    Biaxial(BiaxialConfig),
    /// Collapse of a granular column onto a rough floor.
    ColumnCollapse(ColumnCollapseConfig),
}

impl Scenario {
    /// The scenario kind (`janssen`, `rolling`, ...).
    pub fn kind(&self) -> &'static str {
        match self {
            Scenario::Janssen(_) => "janssen",
            Scenario::Rolling(_) => "rolling",
            Scenario::Arrangements(_) => "arrangements",
            Scenario::StickSlip(_) => "stick-slip",
            Scenario::InclinedFlow(_) => "inclined-flow",
            Scenario::ShearCell(_) => "shear-cell",
            Scenario::SimpleShear(_) => "simple-shear",
            Scenario::Biaxial(_) => "biaxial",
            Scenario::ColumnCollapse(_) => "column-collapse",
        }
    }

    /// The laws it fits and the data each needs (`config::laws`).
    pub fn law_needs(&self) -> Vec<crate::config::laws::LawNeed> {
        match self {
            Scenario::Janssen(_) => vec![crate::config::laws::LawNeed {
                law: "janssen",
                formula: "σ_v(z) of Janssen 1895, K and μ_w jointly",
                key: "",
                needs: 4,
                have: None,
                why: "depth bins of the wall profile in the fit window",
                instead_of: None,
            }],
            Scenario::ShearCell(c) => c.law_needs(),
            Scenario::SimpleShear(c) => c.law_needs(),
            Scenario::Biaxial(c) => c.law_needs(),
            _ => Vec::new(),
        }
    }

    /// The laws the plan leaves out (`leave_out`; empty for a scenario without the key).
    pub fn leave_out(&self) -> &[String] {
        match self {
            Scenario::ShearCell(c) => &c.leave_out,
            Scenario::SimpleShear(c) => &c.leave_out,
            Scenario::Biaxial(c) => &c.leave_out,
            _ => &[],
        }
    }

    /// Whether the plan leaves the law `law` out.
    pub fn leaves_out(&self, law: &str) -> bool {
        self.leave_out().iter().any(|l| l == law)
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        match self {
            Scenario::Janssen(c) => c.seed,
            Scenario::Rolling(c) => c.seed,
            Scenario::Arrangements(c) => c.seed,
            Scenario::StickSlip(c) => c.seed,
            Scenario::InclinedFlow(c) => c.seed,
            Scenario::ShearCell(c) => c.seed,
            Scenario::SimpleShear(c) => c.seed,
            Scenario::Biaxial(c) => c.seed,
            Scenario::ColumnCollapse(c) => c.seed,
        }
    }
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
    /// The typed scenario.
    pub scenario: Scenario,
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

/// Loads `spec` (a built-in name or a TOML file path), applies `sets` (`KEY=VALUE`), then
/// deserialises and validates it.
pub fn load(spec: &str, sets: &[String]) -> Result<LoadedScenario> {
    let (name, source, text) = if let Some(b) = builtin(spec) {
        (
            b.name.to_string(),
            format!("builtin:{}", b.name),
            b.toml.to_string(),
        )
    } else {
        let path = Path::new(spec);
        let looks_like_file = spec.ends_with(".toml") || spec.contains('/') || path.exists();
        if !looks_like_file {
            return Err(DatasetError::UnknownScenario {
                name: spec.to_string(),
                known: builtin_names(),
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
    from_text(&name, &source, &text, sets)
}

/// Like [`load`] from TOML text already read; `source` names it in messages.
pub fn from_text(name: &str, source: &str, text: &str, sets: &[String]) -> Result<LoadedScenario> {
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
                reason: format!("missing: name the scenario kind ({})", builtin_names()),
            })
        }
    };
    let scenario = match kind.as_str() {
        "janssen" => {
            let c: JanssenConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::Janssen(c)
        }
        "rolling" => {
            let c: RollingConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::Rolling(c)
        }
        "arrangements" => {
            let c: ArrangementsConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::Arrangements(c)
        }
        "stick-slip" => {
            let c: StickSlipConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::StickSlip(c)
        }
        "inclined-flow" => {
            let c: InclinedFlowConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::InclinedFlow(c)
        }
        "shear-cell" => {
            let c: ShearCellConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::ShearCell(c)
        }
        "simple-shear" => {
            let c: SimpleShearConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::SimpleShear(c)
        }
        "biaxial" => {
            let c: BiaxialConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::Biaxial(c)
        }
        "column-collapse" => {
            let c: ColumnCollapseConfig = typed(table, source)?;
            c.validate().map_err(|e| e.in_source(source))?;
            Scenario::ColumnCollapse(c)
        }
        other => {
            return Err(DatasetError::invalid(
                "scenario",
                format!(
                    "unknown scenario kind `{other}` (known: {})",
                    builtin_names()
                ),
            )
            .in_source(source))
        }
    };
    // before the run, not after: a plan that cannot identify a law it fits is refused here
    crate::config::laws::check(&scenario.law_needs(), scenario.leave_out())
        .map_err(|e| e.in_source(source))?;
    Ok(LoadedScenario {
        name: name.to_string(),
        source: source.to_string(),
        effective_toml,
        scenario,
    })
}
