//! The one list of scenarios. Each entry is a [`Scenario`]: its name and one-line description,
//! its built-in TOML (`datasets/scenarios/NAME.toml`, embedded), its typed configuration
//! (`scenarios/NAME/config.rs`, loaded with `--set` overrides through [`load`]) and its runner
//! (`scenarios/NAME/mod.rs`). The command line (`run`, `scenarios`, `campaign`, `bench`), the
//! library API ([`crate::api`]), the Python bindings and the tests find scenarios here and
//! nowhere else; [`run_controlled`] runs a loaded one through its entry.
//!
//! A new scenario is one more [`Runner`] in [`SCENARIOS`] (its config struct implements
//! [`ScenarioConfig`] in its folder's `mod.rs`).

use std::sync::Arc;

use datasets::DatasetError;
use serde::de::DeserializeOwned;
use toml::Table;

use super::phased::RunControl;
use super::{
    arrangements, biaxial, column_collapse, inclined_flow, janssen, rolling, shear_cell,
    simple_shear, stick_slip, RunContext, RunOutcome,
};
use crate::error::{CliError, Result};
use crate::output::Summary;
use crate::scenarios::arrangements::config::ArrangementsConfig;
use crate::scenarios::biaxial::config::BiaxialConfig;
use crate::scenarios::column_collapse::config::ColumnCollapseConfig;
use crate::scenarios::inclined_flow::config::InclinedFlowConfig;
use crate::scenarios::janssen::config::JanssenConfig;
use crate::scenarios::loader::{typed_config, Catalogue, LoadedScenario, ScenarioConfig};
use crate::scenarios::rolling::config::RollingConfig;
use crate::scenarios::shear_cell::config::ShearCellConfig;
use crate::scenarios::simple_shear::config::SimpleShearConfig;
use crate::scenarios::stick_slip::config::StickSlipConfig;

/// A scenario: what the registry knows of one kind.
pub trait Scenario: Sync {
    /// Its name on the command line, also the value of its TOML's `scenario` key.
    fn name(&self) -> &'static str;

    /// One line saying what it runs and measures.
    fn description(&self) -> &'static str;

    /// Its built-in TOML, every key with its unit (`grainlaw scenarios --show NAME`).
    fn builtin_toml(&self) -> &'static str;

    /// Its typed, validated configuration from a TOML table (errors name `source` and the key).
    fn config(&self, table: Table, source: &str) -> datasets::Result<Arc<dyn ScenarioConfig>>;

    /// Runs it: build, run, measure, fit, report (the stages of its runner), returning the
    /// summary, the headline lines and the verdict. `config` must be of its kind.
    fn run(
        &self,
        config: &dyn ScenarioConfig,
        ctx: &mut RunContext,
        ctl: &mut RunControl,
    ) -> Result<RunOutcome>;
}

/// A registry entry: a config type `C` and its runner.
pub struct Runner<C> {
    /// [`Scenario::name`].
    pub name: &'static str,
    /// [`Scenario::description`].
    pub description: &'static str,
    /// [`Scenario::builtin_toml`].
    pub toml: &'static str,
    /// The runner (`grainlaw-core/src/scenarios/NAME/mod.rs`'s `run`).
    pub run: fn(&C, &mut RunContext, &mut RunControl) -> Result<RunOutcome>,
}

impl<C: ScenarioConfig + DeserializeOwned> Scenario for Runner<C> {
    fn name(&self) -> &'static str {
        self.name
    }

    fn description(&self) -> &'static str {
        self.description
    }

    fn builtin_toml(&self) -> &'static str {
        self.toml
    }

    fn config(&self, table: Table, source: &str) -> datasets::Result<Arc<dyn ScenarioConfig>> {
        typed_config::<C>(table, source)
    }

    fn run(
        &self,
        config: &dyn ScenarioConfig,
        ctx: &mut RunContext,
        ctl: &mut RunControl,
    ) -> Result<RunOutcome> {
        let c = config.downcast_ref::<C>().ok_or_else(|| {
            CliError::Usage(format!(
                "the `{}` runner was given a `{}` configuration",
                self.name,
                config.kind()
            ))
        })?;
        (self.run)(c, ctx, ctl)
    }
}

/// Every scenario, the default ([`DEFAULT`], `janssen`) first.
pub static SCENARIOS: [&dyn Scenario; 9] = [
    &Runner::<JanssenConfig> {
        name: "janssen",
        description: "350 grains deposited in a column, relaxed, released: wall stress vs depth, Janssen fit (Fig. 7)",
        toml: include_str!("../../../datasets/scenarios/janssen.toml"),
        run: janssen::run,
    },
    &Runner::<RollingConfig> {
        name: "rolling",
        description: "one disk rolling down a slope: exact mean stress with inertia (eq. 13-14)",
        toml: include_str!("../../../datasets/scenarios/rolling.toml"),
        run: rolling::run,
    },
    &Runner::<ArrangementsConfig> {
        name: "arrangements",
        description: "rectangular, triangular, cannonball stacks in a box: load on the walls (Fig. 5)",
        toml: include_str!("../../../datasets/scenarios/arrangements.toml"),
        run: arrangements::run,
    },
    &Runner::<StickSlipConfig> {
        name: "stick-slip",
        description: "bottom wall pushed up under a deposit, three friction cases (Fig. 6)",
        toml: include_str!("../../../datasets/scenarios/stick-slip.toml"),
        run: stick_slip::run,
    },
    &Runner::<InclinedFlowConfig> {
        name: "inclined-flow",
        description: "480 grains flowing down a rough 26° slope: inertia-ratio map (Fig. 4), velocity profile",
        toml: include_str!("../../../datasets/scenarios/inclined-flow.toml"),
        run: inclined_flow::run,
    },
    &Runner::<ShearCellConfig> {
        name: "shear-cell",
        description: "plane shear at imposed pressure over several inertial numbers: mu(I), phi(I), wall law",
        toml: include_str!("../../../datasets/scenarios/shear-cell.toml"),
        run: shear_cell::run,
    },
    &Runner::<SimpleShearConfig> {
        name: "simple-shear",
        description: "Lees-Edwards shear of a biperiodic cell at imposed normal stress over several inertial numbers: mu(I), phi(I)",
        toml: include_str!("../../../datasets/scenarios/simple-shear.toml"),
        run: simple_shear::run,
    },
    &Runner::<BiaxialConfig> {
        name: "biaxial",
        description: "biaxial compression of a biperiodic cell at constant lateral stress over several confining pressures: peak and critical friction, dilatancy, Mohr-Coulomb",
        toml: include_str!("../../../datasets/scenarios/biaxial.toml"),
        run: biaxial::run,
    },
    &Runner::<ColumnCollapseConfig> {
        name: "column-collapse",
        description: "a 2D column of about 2500 grains (a = 6.26) collapsing onto a rough floor: front x_f(t), profiles, runout, against contact dynamics",
        toml: include_str!("../../../datasets/scenarios/column-collapse.toml"),
        run: column_collapse::run,
    },
];

/// The scenario run when none is named.
pub const DEFAULT: &str = "janssen";

/// The scenario named `name`.
pub fn find(name: &str) -> Option<&'static dyn Scenario> {
    SCENARIOS.iter().copied().find(|s| s.name() == name)
}

/// The scenario named `name`, or [`DatasetError::UnknownScenario`] listing the known ones.
pub fn get(name: &str) -> datasets::Result<&'static dyn Scenario> {
    find(name).ok_or_else(|| DatasetError::UnknownScenario {
        name: name.to_string(),
        known: names(),
    })
}

/// The scenario names, comma separated.
pub fn names() -> String {
    SCENARIOS
        .iter()
        .map(|s| s.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The registry as the loader's [`Catalogue`].
pub struct Registry;

impl Catalogue for Registry {
    fn builtin_toml(&self, name: &str) -> Option<&'static str> {
        find(name).map(|s| s.builtin_toml())
    }

    fn names(&self) -> String {
        names()
    }

    fn config(
        &self,
        kind: &str,
        table: Table,
        source: &str,
    ) -> Option<datasets::Result<Arc<dyn ScenarioConfig>>> {
        find(kind).map(|s| s.config(table, source))
    }
}

/// Loads `spec` (a scenario name or a TOML file path) with the overrides `sets` (`KEY=VALUE`),
/// typed and validated ([`crate::scenarios::loader::load`] over the registry).
pub fn load(spec: &str, sets: &[String]) -> datasets::Result<LoadedScenario> {
    crate::scenarios::loader::load(&Registry, spec, sets)
}

/// Like [`load`] from TOML text already read; `name` and `source` name it.
pub fn from_text(
    name: &str,
    source: &str,
    text: &str,
    sets: &[String],
) -> datasets::Result<LoadedScenario> {
    crate::scenarios::loader::from_text(&Registry, name, source, text, sets)
}

/// The configuration of `loaded` as the type `C` of its kind, or a [`DatasetError::Type`] on
/// its `scenario` key when it is of another kind.
pub fn config_of<C: ScenarioConfig + Clone>(loaded: &LoadedScenario) -> datasets::Result<C> {
    loaded
        .config
        .downcast_ref::<C>()
        .cloned()
        .ok_or_else(|| DatasetError::Type {
            source_name: loaded.source.clone(),
            key: "scenario".into(),
            reason: format!(
                "`{}` is not the scenario kind asked for here",
                loaded.config.kind()
            ),
        })
}

/// One line per law the plan leaves out (`leave_out`, `crate::scenarios::common::laws`): its name,
/// and the data the plan has against what it needs.
pub fn left_out_lines(config: &dyn ScenarioConfig) -> Vec<String> {
    let needs = config.law_needs();
    config
        .leave_out()
        .iter()
        .map(|law| {
            let why = needs
                .iter()
                .find(|n| n.law == law)
                .and_then(|n| {
                    n.have.map(|h| {
                        format!(
                            " (this plan has {h} {}; it needs at least {})",
                            n.key, n.needs
                        )
                    })
                })
                .unwrap_or_default();
            format!("{law} left out by the plan (leave_out): it is not fitted, no law file{why}")
        })
        .collect()
}

/// Runs the loaded scenario, writes every output and `summary.json` last, with the default
/// checkpoint policy ([`run_controlled`] with [`RunControl::default`]).
pub fn run(ctx: &mut RunContext) -> Result<RunOutcome> {
    run_controlled(ctx, &mut RunControl::default())
}

/// Runs the loaded scenario through its registry entry under `ctl`: a new run removes a stale
/// checkpoint directory first; with `ctl.resume` the run continues from the checkpoint in the
/// output directory. Checkpoints are written as `ctl.policy` says and when the user stops the
/// run; `summary.json` is written last, then the checkpoint directory is removed.
pub fn run_controlled(ctx: &mut RunContext, ctl: &mut RunControl) -> Result<RunOutcome> {
    let config = ctx.loaded.config.clone();
    let scenario = get(config.kind())?;
    if !ctl.resume && crate::checkpoint::file_of(ctx.out.path()).exists() {
        crate::progress::warn(&format!(
            "{}: removed the checkpoint of an earlier, interrupted run (a new run starts here; `--resume` continues one)",
            ctx.out.path().display()
        ));
    }
    if !ctl.resume {
        crate::checkpoint::remove(ctx.out.path())?;
        ctl.origin = crate::provenance::RunOrigin::now(&ctx.loaded);
    }
    ctx.out
        .write("scenario.toml", ctx.loaded.effective_toml.as_bytes())?;
    // said at the start: what the plan leaves out, and why it could not have had it
    for line in left_out_lines(&*config) {
        crate::progress::note(&line);
    }
    // said at the start: how long the plan is, in steps
    if let Some(line) = config.plan_note() {
        crate::progress::note(&line);
    }
    let mut outcome = scenario.run(&*config, ctx, ctl)?;
    let mut head = Summary::new();
    head.text("scenario", config.kind())
        .text("source", &ctx.loaded.source)
        .int("seed", config.seed());
    let mut summary = head;
    for (k, v) in outcome.summary.entries() {
        summary.set(k, v.clone());
    }
    outcome.verdict.allow_suspect = ctl.allow_suspect;
    outcome.verdict.keys(&mut summary);
    summary.set(
        "laws_left_out",
        serde_json::Value::from(config.leave_out().to_vec()),
    );
    summary.num("wall_seconds", ctl.wall_seconds());
    summary.text("grainlaw_version", env!("CARGO_PKG_VERSION"));
    ctx.out
        .write("summary.json", summary.to_json().as_bytes())?;
    crate::checkpoint::remove(ctx.out.path())?;
    outcome.summary = summary;
    Ok(outcome)
}
