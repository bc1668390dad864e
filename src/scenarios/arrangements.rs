//! The `arrangements` scenario (paper §4.1, Fig. 5): equal cylinders stacked in a box of two
//! vertical and two horizontal fixed walls, in rectangular, triangular and cannonball
//! arrangements. Each stack settles under gravity from a lattice with small gaps between rows;
//! at rest the load on the bottom wall is compared with the weight (with rubbing walls the
//! triangular stack puts part of its weight on the side walls).

use datasets::config::ArrangementsConfig;
use datasets::generators::Arrangement;
use datasets::phases::RunUntilRest;

use super::common::{grain_weight, run_phase, solver_keys, Stop, VtkFrames};
use super::{RunContext, RunOutcome};
use crate::error::Result;
use crate::output::{CsvTable, Summary};
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};

/// Runs the scenario.
pub fn run(c: &ArrangementsConfig, ctx: &mut RunContext) -> Result<RunOutcome> {
    let mut s = Summary::new();
    s.num("radius", c.radius)
        .int("columns", c.columns as u64)
        .int("rows", c.rows as u64)
        .num("grain_friction", c.friction.grain_grain)
        .num("wall_friction", c.friction.grain_wall);
    let mut table = CsvTable::new(&[
        "arrangement_0rect_1tri_2cannon",
        "grains",
        "weight_N",
        "bottom_load_N",
        "left_wall_normal_N",
        "right_wall_normal_N",
        "left_wall_friction_up_N",
        "right_wall_friction_up_N",
        "top_load_N",
    ]);
    let mut headline = vec![format!("report: {}/", ctx.out.path().display())];
    let mut all = datasets::phases::PhaseStats::default();
    let env = ctx.env();
    for (k, kind) in Arrangement::ALL.iter().enumerate() {
        let name = kind.name();
        let mut world = datasets::build::arrangement(c, *kind)?;
        let weight = grain_weight(&world);
        let mut vtk = VtkFrames::with_prefix(&format!("{name}_"), c.duration / 10.0, 11);
        let out = &mut ctx.out;
        let stats = run_phase(
            &env,
            name,
            &mut world,
            Stop::UntilRest(RunUntilRest {
                min_time: 0.2 * c.duration,
                max_time: c.duration,
                rest_energy: 1e-12,
            }),
            |w, _| vtk.maybe(out, w),
        )?;
        all.merge(&stats);
        vtk.finish(&mut ctx.out, &world)?;
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
        s.int(&format!("grains_{name}"), (snap.bodies.len() - 4) as u64)
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
        table.push(vec![
            k as f64,
            (snap.bodies.len() - 4) as f64,
            weight,
            bottom_load,
            -left.x,
            right.x,
            -left.y,
            -right.y,
            top.y,
        ]);
        headline.push(format!(
            "{name:<12}: bottom load / weight = {ratio:.3}, side walls carry {:.3} of the weight",
            -(left.y + right.y) / weight
        ));
        draw_particles(
            &mut ctx.out,
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
            },
        )?;
    }
    solver_keys(&mut s, &all);
    table.comments.push("one row per arrangement; forces of the grains on the walls at rest (N per metre of thickness)".into());
    table.write(&mut ctx.out, "wall_loads.csv")?;
    Ok(RunOutcome {
        summary: s,
        headline,
    })
}
