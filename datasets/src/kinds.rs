//! The scenario kinds as [`ScenarioConfig`]s: for each config struct its kind name, seed,
//! validation, laws, size and the worlds its runner builds first (the *build* stage,
//! [`crate::build`], [`crate::build_cell`]). A new kind adds its `impl` here.

use std::any::Any;

use crate::build::{arrangement, column, column_width, inclined_flow, rolling, shear_cell};
use crate::config::laws::LawNeed;
use crate::config::{
    ArrangementsConfig, BiaxialConfig, ColumnCollapseConfig, InclinedFlowConfig, JanssenConfig,
    RollingConfig, ShearCellConfig, SimpleShearConfig, StickSlipConfig,
};
use crate::error::Result;
use crate::generators::Arrangement;
use crate::scenario::ScenarioConfig;

/// The methods every kind writes the same way: `seed`, `check` (the struct's `validate`),
/// `as_any`.
macro_rules! common_methods {
    () => {
        fn seed(&self) -> u64 {
            self.seed
        }

        fn check(&self) -> Result<()> {
            self.validate()
        }

        fn as_any(&self) -> &dyn Any {
            self
        }
    };
}

impl ScenarioConfig for JanssenConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "janssen"
    }

    fn law_needs(&self) -> Vec<LawNeed> {
        vec![LawNeed {
            law: "janssen",
            formula: "σ_v(z) of Janssen 1895, K and μ_w jointly",
            key: "",
            needs: 4,
            have: None,
            why: "depth bins of the wall profile in the fit window",
            instead_of: None,
        }]
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> Result<()> {
        let w = column_width(&self.grain, self.grains, self.column_aspect);
        let dt = self.dt / self.deposit.substeps as f64;
        column(&self.grain, self.grains, w, &self.friction, self.seed, dt).map(drop)
    }
}

impl ScenarioConfig for RollingConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "rolling"
    }

    fn grains(&self) -> usize {
        1
    }

    fn build_first(&self) -> Result<()> {
        rolling(self).map(drop)
    }
}

impl ScenarioConfig for ArrangementsConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "arrangements"
    }

    fn grains(&self) -> usize {
        self.columns * self.rows.max(self.columns)
    }

    fn build_first(&self) -> Result<()> {
        for kind in Arrangement::ALL {
            arrangement(self, kind)?;
        }
        Ok(())
    }
}

impl ScenarioConfig for StickSlipConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "stick-slip"
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> Result<()> {
        let w = self.width_diameters * 2.0 * self.grain.radius_mean;
        let dt = self.dt / self.deposit.substeps as f64;
        for (_, f) in self.cases.list() {
            column(&self.grain, self.grains, w, &f, self.seed, dt)?;
        }
        Ok(())
    }
}

impl ScenarioConfig for InclinedFlowConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "inclined-flow"
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> Result<()> {
        inclined_flow(self).map(drop)
    }
}

impl ScenarioConfig for ShearCellConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "shear-cell"
    }

    fn law_needs(&self) -> Vec<LawNeed> {
        ShearCellConfig::law_needs(self)
    }

    fn leave_out(&self) -> &[String] {
        &self.leave_out
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> Result<()> {
        shear_cell(self).map(drop)
    }
}

impl ScenarioConfig for SimpleShearConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "simple-shear"
    }

    fn law_needs(&self) -> Vec<LawNeed> {
        SimpleShearConfig::law_needs(self)
    }

    fn leave_out(&self) -> &[String] {
        &self.leave_out
    }

    /// `plan: about N time steps (compression …; I = …: …), bound max_steps = …`.
    fn plan_note(&self) -> Option<String> {
        let (compression, runs) = self.planned_steps();
        let total = compression + runs.iter().sum::<u64>();
        Some(format!(
            "plan: about {total} time steps (compression {compression}; {}), bound max_steps = {}",
            self.inertial_numbers
                .iter()
                .zip(&runs)
                .map(|(i, n)| format!("I = {i}: {n}"))
                .collect::<Vec<_>>()
                .join(", "),
            self.max_steps
        ))
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> Result<()> {
        crate::build_cell::simple_shear(self).map(drop)
    }
}

impl ScenarioConfig for BiaxialConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "biaxial"
    }

    fn law_needs(&self) -> Vec<LawNeed> {
        BiaxialConfig::law_needs(self)
    }

    fn leave_out(&self) -> &[String] {
        &self.leave_out
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> Result<()> {
        crate::build_cell::biaxial(self).map(drop)
    }
}

impl ScenarioConfig for ColumnCollapseConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "column-collapse"
    }

    fn grains(&self) -> usize {
        self.poured_grains()
    }

    fn build_first(&self) -> Result<()> {
        crate::build::column_collapse_deposit(self).map(drop)
    }
}
