//! The `arrangements` scenario (paper §4.1, Fig. 5): equal cylinders stacked in a box of two
//! vertical and two horizontal fixed walls, in rectangular, triangular and cannonball
//! arrangements. Each stack settles under gravity from a lattice with small gaps between rows;
//! at rest the load on the bottom wall is compared with the weight (with rubbing walls the
//! triangular stack puts part of its weight on the side walls).

pub mod build;
pub mod config;

use datasets::generators::Arrangement;
use serde::{Deserialize, Serialize};

use super::common::{grain_weight, solver_keys, Stop, VtkFrames};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::phases::{PhaseStats, RunUntilRest};
use super::rows::{self, serde_csv_table, table_row};
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::Result;
use crate::output::Summary;
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use build::arrangement;
use config::ArrangementsConfig;

/// One phase per arrangement (rectangular, triangular, cannonball), each settling its own
/// stack to rest.
struct Stacks<'a> {
    c: &'a ArrangementsConfig,
}

/// What the stacks' phases collect.
#[derive(Serialize, Deserialize)]
struct StacksState {
    /// Summary entries so far.
    s: Summary,
    /// One row per arrangement: `wall_loads.csv`.
    #[serde(with = "serde_csv_table")]
    table: Vec<WallLoadRow>,
    headline: Vec<String>,
    all: PhaseStats,
    /// VTK frames of the current arrangement.
    vtk: VtkFrames,
    /// Weight of the current stack (N).
    weight: f64,
}

impl PhasedRun for Stacks<'_> {
    type State = StacksState;

    fn phase_count(&self) -> usize {
        Arrangement::ALL.len()
    }

    fn enter(&self, st: &mut StacksState, at: Enter<'_>) -> Result<Option<PhasePlan>> {
        let (k, world) = (at.k, at.world);
        let c = self.c;
        let kind = Arrangement::ALL[k];
        *world = build::arrangement(c, kind)?;
        st.weight = grain_weight(world);
        st.vtk = VtkFrames::with_prefix(&format!("{}_", kind.name()), c.duration / 10.0, 11);
        let rest = RunUntilRest {
            min_time: 0.2 * c.duration,
            max_time: c.duration,
            rest_energy: 1e-12,
        };
        Ok(Some(PhasePlan::new(kind.name(), Stop::UntilRest(rest))))
    }

    fn step(&self, st: &mut StacksState, at: Step<'_>) -> Result<()> {
        let (out, w) = (at.out, at.world);
        st.vtk.maybe(out, w)
    }

    fn leave(&self, st: &mut StacksState, at: Leave<'_>) -> Result<()> {
        let (k, out, world, stats) = (at.k, at.out, at.world, at.stats);
        let name = Arrangement::ALL[k].name();
        st.all.merge(stats);
        std::mem::replace(&mut st.vtk, VtkFrames::new(f64::INFINITY, 1)).finish(out, world)?;
        let weight = st.weight;
        let snap = world.snapshot();
        let force = |wall: &str| {
            snap.walls
                .iter()
                .find(|w| w.name == wall)
                .map(|w| w.force)
                .unwrap_or_default()
        };
        let (bottom, left, right, top) =
            (force("bottom"), force("left"), force("right"), force("top"));
        // Force received by a wall: the grains push it; the bottom wall is pushed down.
        let bottom_load = -bottom.y;
        let ratio = bottom_load / weight;
        st.s.int(&format!("grains_{name}"), (snap.bodies.len() - 4) as u64)
            .num(&format!("weight_N_{name}"), weight)
            .num(&format!("bottom_load_over_weight_{name}"), ratio)
            .num(
                &format!("side_wall_load_over_weight_{name}"),
                -(left.y + right.y) / weight,
            )
            .num(
                &format!("side_wall_normal_force_N_{name}"),
                0.5 * (-left.x + right.x),
            )
            .flag(&format!("at_rest_{name}"), stats.at_rest);
        st.table.push(WallLoadRow {
            arrangement: k as f64,
            grains: (snap.bodies.len() - 4) as f64,
            weight,
            bottom_load,
            left_normal: -left.x,
            right_normal: right.x,
            left_friction_up: -left.y,
            right_friction_up: -right.y,
            top_load: top.y,
        });
        st.headline.push(format!(
            "{name:<12}: bottom load / weight = {ratio:.3}, side walls carry {:.3} of the weight",
            -(left.y + right.y) / weight
        ));
        draw_particles(
            out,
            &format!("normal_forces_{name}.png"),
            &ParticleView {
                snap: &snap,
                title: format!(
                    "{name} arrangement: normal forces (bottom load / weight = {ratio:.3})"
                ),
                fill: GrainFill::Plain,
                forces: true,
                axis_labels: ("x (m)".into(), "y (m)".into()),
                width_px: 560,
                overlays: Vec::new(),
            },
        )
    }
}

table_row! {
    /// One arrangement at rest: a row of `wall_loads.csv`, the forces of the grains on the
    /// walls (N per metre of thickness).
    struct WallLoadRow {
        /// The arrangement: 0 rectangular, 1 triangular, 2 cannonball.
        arrangement: "arrangement_0rect_1tri_2cannon",
        /// Grains of the stack.
        grains: "grains",
        /// Their weight (N).
        weight: "weight_N",
        /// Load on the floor, downward (N).
        bottom_load: "bottom_load_N",
        /// Normal force on the left wall (N).
        left_normal: "left_wall_normal_N",
        /// Normal force on the right wall (N).
        right_normal: "right_wall_normal_N",
        /// Friction carried up by the left wall (N).
        left_friction_up: "left_wall_friction_up_N",
        /// Friction carried up by the right wall (N).
        right_friction_up: "right_wall_friction_up_N",
        /// Load on the top wall (N).
        top_load: "top_load_N",
    }
}

/// Runs the scenario.
pub fn run(
    c: &ArrangementsConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
) -> Result<RunOutcome> {
    let mut s = Summary::new();
    s.num("radius", c.radius)
        .int("columns", c.columns as u64)
        .int("rows", c.rows as u64)
        .num("grain_friction", c.friction.grain_grain)
        .num("wall_friction", c.friction.grain_wall);
    let state = StacksState {
        s,
        table: Vec::new(),
        headline: vec![format!("report: {}/", ctx.out.path().display())],
        all: PhaseStats::default(),
        vtk: VtkFrames::new(f64::INFINITY, 1),
        weight: f64::NAN,
    };
    // Each phase builds its own stack; the initial world is a placeholder.
    let empty = dem::World::new(dem::WorldParams::default(), dem::ContactLaws::new(&[], 0.0));
    let (_, st) = drive(ctx, ctl, &Stacks { c }, || Ok((empty, state)))?;
    let StacksState {
        mut s,
        table,
        headline,
        all,
        ..
    } = st;
    solver_keys(&mut s, &all);
    // Verdict: each stack at rest carries its weight exactly: floor + side-wall friction − top
    // load = weight (crate::verdict).
    let mut checks = crate::verdict::Checks::new();
    for (k, r) in table.iter().enumerate() {
        let name = Arrangement::ALL[k].name();
        let balance = (r.bottom_load + r.left_friction_up + r.right_friction_up - r.top_load)
            / r.weight
            - 1.0;
        checks.at_most(
            &format!("arrangements.force_balance_{name}"),
            balance.abs(),
            BALANCE_SUSPECT,
            Some(BALANCE_REFUSED),
            |t| {
                format!(
                    "{name}: the walls carry {:.2} % of the weight (limit ±{:.0} %)",
                    100.0 * (1.0 + balance),
                    100.0 * t
                )
            },
        );
        if s.get(&format!("at_rest_{name}")) == Some(&serde_json::Value::Bool(false)) {
            checks.fail(
                &format!("arrangements.at_rest_{name}"),
                crate::verdict::Verdict::Suspect,
                0.0,
                1.0,
                format!("{name}: the stack did not come to rest within `duration`"),
            );
        }
    }
    let mut table = rows::table(&table);
    table.comments.push("one row per arrangement; forces of the grains on the walls at rest (N per metre of thickness)".into());
    table.write(&mut ctx.out, "wall_loads.csv")?;
    Ok(RunOutcome::without_laws(s, headline, checks))
}

/// Relative imbalance between the loads on the walls and the weight of a stack at rest above
/// which the run is suspect (1).
pub const BALANCE_SUSPECT: f64 = 0.01;
/// The same, above which it is refused (1).
pub const BALANCE_REFUSED: f64 = 0.05;

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for ArrangementsConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "arrangements"
    }

    fn grains(&self) -> usize {
        self.columns * self.rows.max(self.columns)
    }

    fn build_first(&self) -> datasets::Result<()> {
        for kind in Arrangement::ALL {
            arrangement(self, kind)?;
        }
        Ok(())
    }
}
