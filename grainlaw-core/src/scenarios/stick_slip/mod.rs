//! The `stick-slip` scenario (paper §4.2, Fig. 6): grains deposited by gravity in an open
//! container of two vertical walls and a floor; then the floor is pushed up at constant speed
//! and the force it receives from the grains is recorded, for three friction cases:
//! μ = 0 everywhere (the force stays equal to the weight), friction at the walls only (chaotic
//! then regular), friction at the walls and between grains (load–unload cycles).

pub mod config;

use dem::math::Vector;
use serde::{Deserialize, Serialize};

use super::common::build::column;
use super::common::{grain_weight, solver_keys, Stop, VtkFrames};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::phases::PhaseStats;
use super::rows::{self, serde_csv_table, table_row};
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::Result;
use crate::output::Summary;
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use crate::plot::xy::{draw_column, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::verdict::WindowStats;
use config::StickSlipConfig;

/// Mean and standard deviation of a series.
pub fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n;
    (m, var.sqrt())
}

/// Two phases per friction case: deposit (a new column), then push the floor up.
struct Push<'a> {
    c: &'a StickSlipConfig,
}

/// What the phases collect.
#[derive(Serialize, Deserialize)]
struct PushState {
    /// Summary entries so far.
    s: Summary,
    /// Force on the moving wall per step and case: `wall_force.csv`.
    #[serde(with = "serde_csv_table")]
    table: Vec<WallForceRow>,
    headline: Vec<String>,
    all: PhaseStats,
    /// Weight of each case's grains (N).
    weights: Vec<f64>,
    /// Body index of the current floor.
    bottom: usize,
    /// Force on the moving wall in the current push, per step (N).
    #[serde(with = "crate::floats::vec")]
    force: Vec<f64>,
    /// VTK frames of the current push.
    vtk: VtkFrames,
    /// Numerics of the steps of the current push that feed its force statistics (the second
    /// half).
    #[serde(default)]
    window: WindowStats,
    /// Those of each finished push, in case order (the verdict judges them).
    #[serde(default)]
    windows: Vec<WindowStats>,
}

table_row! {
    /// One step of the pushes: a row of `wall_force.csv`, the force on the moving wall (N per
    /// metre of thickness) of each case (NaN until its push ran).
    struct WallForceRow {
        /// Time since the start of the push (s).
        t: "time_s",
        /// The frictionless case.
        frictionless: "force_frictionless_N",
        /// Friction at the walls only.
        walls_only: "force_walls_only_N",
        /// Friction at the walls and between the grains.
        walls_and_grains: "force_walls_and_grains_N",
    }
}

impl WallForceRow {
    /// The force of case `case` of `StickSlipCases::list` (its order: frictionless, walls
    /// only, walls and grains).
    fn case_mut(&mut self, case: usize) -> &mut f64 {
        match case {
            0 => &mut self.frictionless,
            1 => &mut self.walls_only,
            _ => &mut self.walls_and_grains,
        }
    }

    /// The same, read.
    fn case(mut self, case: usize) -> f64 {
        *self.case_mut(case)
    }
}

impl Push<'_> {
    fn steps(&self) -> u64 {
        (self.c.push_duration / self.c.dt).round().max(1.0) as u64
    }
}

impl PhasedRun for Push<'_> {
    type State = PushState;

    fn phase_count(&self) -> usize {
        2 * self.c.cases.list().len()
    }

    fn enter(&self, st: &mut PushState, at: Enter<'_>) -> Result<Option<PhasePlan>> {
        let (k, world) = (at.k, at.world);
        let c = self.c;
        let case = k / 2;
        let (name, friction) = &c.cases.list()[case];
        let width = c.width_diameters * 2.0 * c.grain.radius_mean;
        if k.is_multiple_of(2) {
            let col = crate::scenarios::common::build::column(
                &c.grain,
                c.grains,
                width,
                friction,
                c.seed,
                c.dt / c.deposit.substeps as f64,
            )?;
            *world = col.world;
            c.deposit.solver.apply(&mut world.params);
            st.bottom = col.bottom;
            st.weights.push(grain_weight(world));
            Ok(Some(PhasePlan::new(
                format!("deposit {case}"),
                Stop::UntilRest(c.deposit.until_rest()),
            )))
        } else {
            world.params.dt = c.dt;
            c.solver.apply(&mut world.params);
            world.bodies[st.bottom].velocity = Vector::new(0.0, c.push_velocity);
            st.force = Vec::with_capacity(self.steps() as usize);
            st.window.reset();
            st.vtk = VtkFrames::with_prefix(&format!("{name}_"), c.push_duration / 20.0, 21);
            Ok(Some(PhasePlan::new(
                format!("push {case}"),
                Stop::Steps(self.steps()),
            )))
        }
    }

    fn step(&self, st: &mut PushState, at: Step<'_>) -> Result<()> {
        let (k, out, w, r, p) = (at.k, at.out, at.world, at.report, at.progress);
        if !k.is_multiple_of(2) {
            st.force.push(-w.contact_force(st.bottom).0.y);
            // The force statistics are over the second half of the push (`leave`).
            let in_window = st.force.len() as u64 > self.steps() / 2;
            st.window.step(in_window, w, r, &p.stats);
            st.vtk.maybe(out, w)?;
        }
        Ok(())
    }

    fn leave(&self, st: &mut PushState, at: Leave<'_>) -> Result<()> {
        let (k, out, world, stats) = (at.k, at.out, at.world, at.stats);
        st.all.merge(stats);
        if k.is_multiple_of(2) {
            return Ok(());
        }
        let case = k / 2;
        let (name, friction) = &self.c.cases.list()[case];
        let weight = st.weights[case];
        std::mem::replace(&mut st.vtk, VtkFrames::new(f64::INFINITY, 1)).finish(out, world)?;
        st.window.keys(&mut st.s, &format!("push_window_{name}"));
        st.windows.push(st.window);
        let force = std::mem::take(&mut st.force);
        for (i, f) in force.iter().enumerate() {
            *st.table[i].case_mut(case) = *f;
        }
        // Statistics over the second half (after the start-up transient).
        let half = &force[force.len() / 2..];
        let (m, sd) = mean_std(half);
        let (fmin, fmax) = half
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        st.s.num(
            &format!("friction_grain_grain_{name}"),
            friction.grain_grain,
        )
        .num(&format!("friction_grain_wall_{name}"), friction.grain_wall)
        .num(&format!("weight_N_{name}"), weight)
        .num(&format!("force_mean_N_{name}"), m)
        .num(&format!("force_std_N_{name}"), sd)
        .num(
            &format!("force_fluctuation_{name}"),
            sd / m.abs().max(1e-300),
        )
        .num(&format!("force_min_N_{name}"), fmin)
        .num(&format!("force_max_N_{name}"), fmax)
        .num(&format!("force_mean_over_weight_{name}"), m / weight);
        st.headline.push(format!(
            "{name:<17}: force on the moving wall {m:.3} N ± {sd:.3} N (weight {weight:.3} N; relative fluctuation {:.3})",
            sd / m.abs().max(1e-300)
        ));
        let snap = world.snapshot();
        draw_particles(
            out,
            &format!("force_chains_{name}.png"),
            &ParticleView {
                snap: &snap,
                title: format!(
                    "{}: normal forces at the end of the push",
                    name.replace('_', " ")
                ),
                fill: GrainFill::Plain,
                forces: true,
                axis_labels: ("x (m)".into(), "y (m)".into()),
                width_px: 420,
                overlays: Vec::new(),
            },
        )
    }
}

/// Runs the scenario.
pub fn run(c: &StickSlipConfig, ctx: &mut RunContext, ctl: &mut RunControl) -> Result<RunOutcome> {
    let width = c.width_diameters * 2.0 * c.grain.radius_mean;
    let steps = (c.push_duration / c.dt).round().max(1.0) as u64;
    let mut s = Summary::new();
    s.int("grains", c.grains as u64)
        .num("box_width_m", width)
        .num("push_velocity", c.push_velocity)
        .num("push_duration", c.push_duration);
    let table: Vec<WallForceRow> = (0..steps)
        .map(|k| WallForceRow {
            t: (k + 1) as f64 * c.dt,
            frictionless: f64::NAN,
            walls_only: f64::NAN,
            walls_and_grains: f64::NAN,
        })
        .collect();
    let state = PushState {
        s,
        table,
        headline: vec![format!("report: {}/", ctx.out.path().display())],
        all: PhaseStats::default(),
        weights: Vec::new(),
        bottom: 0,
        force: Vec::new(),
        vtk: VtkFrames::new(f64::INFINITY, 1),
        window: WindowStats::default(),
        windows: Vec::new(),
    };
    // Each deposit phase builds its own column; the initial world is a placeholder.
    let empty = dem::World::new(dem::WorldParams::default(), dem::ContactLaws::new(&[], 0.0));
    let (_, st) = drive(ctx, ctl, &Push { c }, || Ok((empty, state)))?;
    let PushState {
        mut s,
        table,
        headline,
        all,
        weights,
        windows,
        ..
    } = st;
    let mut plots = Vec::new();
    for (k, (name, friction)) in c.cases.list().iter().enumerate() {
        let weight = weights.get(k).copied().unwrap_or(f64::NAN);
        let mut p = XyPlot::new(
            &format!(
                "{}: μ grain–grain = {}, μ grain–wall = {}",
                name.replace('_', " "),
                friction.grain_grain,
                friction.grain_wall
            ),
            Axis::new("time since the start of the push t (s)"),
            Axis::new("force on the moving wall (N/m)"),
        );
        p.series.push(Series::new(
            "weight",
            Style::Dashed,
            PALETTE[6],
            vec![(0.0, weight), (c.push_duration, weight)],
        ));
        p.series.push(Series::new(
            "",
            Style::Thin,
            PALETTE[k],
            table
                .iter()
                .enumerate()
                .map(|(i, r)| ((i + 1) as f64 * c.dt, r.case(k)))
                .collect(),
        ));
        p.legend = LegendAt::UpperRight;
        plots.push(p);
    }
    solver_keys(&mut s, &all);
    let mut table = rows::table(&table);
    table.comments.push(
        "force received by the moving bottom wall from the grains, per metre of thickness".into(),
    );
    table.write(&mut ctx.out, "wall_force.csv")?;
    draw_column(&mut ctx.out, "wall_force.png", &plots, (1200, 1350))?;
    // Verdict: without friction the floor pushes exactly the weight (crate::verdict).
    let mut checks = crate::verdict::Checks::new();
    let r = s
        .get_f64("force_mean_over_weight_frictionless")
        .unwrap_or(f64::NAN);
    checks.at_most(
        "stick_slip.frictionless_force_over_weight",
        (r - 1.0).abs(),
        super::arrangements::BALANCE_SUSPECT,
        Some(super::arrangements::BALANCE_REFUSED),
        |t| {
            format!(
                "without friction the floor should push the weight exactly; mean force / weight = {r:.4} (limit ±{:.0} %)",
                100.0 * t
            )
        },
    );
    // The forces of each case stand on the steps of the second half of its push: their
    // solves must have converged (with μ = 0.8 on grains and walls most do not: the column
    // wedges and such a step may have no solution, so its forces are not measurements).
    for (w, (name, _)) in windows.iter().zip(c.cases.list()) {
        checks.window(&format!("{name}, second half of the push"), w);
    }
    Ok(RunOutcome::without_laws(s, headline, checks))
}

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for StickSlipConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "stick-slip"
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> datasets::Result<()> {
        let w = self.width_diameters * 2.0 * self.grain.radius_mean;
        let dt = self.dt / self.deposit.substeps as f64;
        for (_, f) in self.cases.list() {
            column(&self.grain, self.grains, w, &f, self.seed, dt)?;
        }
        Ok(())
    }
}
