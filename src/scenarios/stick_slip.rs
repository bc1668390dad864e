//! The `stick-slip` scenario (paper §4.2, Fig. 6): grains deposited by gravity in an open
//! container of two vertical walls and a floor; then the floor is pushed up at constant speed
//! and the force it receives from the grains is recorded, for three friction cases:
//! μ = 0 everywhere (the force stays equal to the weight), friction at the walls only (chaotic
//! then regular), friction at the walls and between grains (load–unload cycles).

use datasets::config::StickSlipConfig;
use datasets::phases::RunUntilRest;
use nalgebra::Vector2;

use super::common::{grain_weight, run_phase, solver_keys, Stop, VtkFrames};
use super::{RunContext, RunOutcome};
use crate::error::Result;
use crate::output::{CsvTable, Summary};
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use crate::plot::xy::{draw_column, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;

/// Mean and standard deviation of a series.
pub fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n;
    (m, var.sqrt())
}

/// Runs the scenario.
pub fn run(c: &StickSlipConfig, ctx: &mut RunContext) -> Result<RunOutcome> {
    let width = c.width_diameters * 2.0 * c.grain.radius_mean;
    let steps = (c.push_duration / c.dt).round().max(1.0) as u64;
    let mut s = Summary::new();
    s.int("grains", c.grains as u64)
        .num("box_width_m", width)
        .num("push_velocity", c.push_velocity)
        .num("push_duration", c.push_duration);
    let mut table = CsvTable::new(&[
        "time_s",
        "force_frictionless_N",
        "force_walls_only_N",
        "force_walls_and_grains_N",
    ]);
    for k in 0..steps {
        table.push(vec![(k + 1) as f64 * c.dt, f64::NAN, f64::NAN, f64::NAN]);
    }
    let mut plots = Vec::new();
    let mut headline = vec![format!("report: {}/", ctx.out.path().display())];
    let mut all = datasets::phases::PhaseStats::default();
    let env = ctx.env();
    for (k, (name, friction)) in c.cases.list().iter().enumerate() {
        let mut col = datasets::build::column(
            &c.grain,
            c.grains,
            width,
            friction,
            c.seed,
            c.dt / c.deposit.substeps as f64,
        )?;
        let world = &mut col.world;
        world.params.solver = c.deposit.solver.params();
        let weight = grain_weight(world);
        let dep = run_phase(
            &env,
            &format!("deposit {k}"),
            world,
            Stop::UntilRest(RunUntilRest {
                min_time: 0.0,
                max_time: c.deposit.max_time,
                rest_energy: c.deposit.rest_energy,
            }),
            |_, _| Ok(()),
        )?;
        all.merge(&dep);
        world.params.dt = c.dt;
        world.params.solver = c.solver.params();
        world.bodies[col.bottom].velocity = Vector2::new(0.0, c.push_velocity);
        let t0 = world.time;
        let mut force = Vec::with_capacity(steps as usize);
        let mut vtk = VtkFrames::with_prefix(&format!("{name}_"), c.push_duration / 20.0, 21);
        let out = &mut ctx.out;
        let bottom = col.bottom;
        let push = run_phase(
            &env,
            &format!("push {k}"),
            world,
            Stop::Steps(steps),
            |w, _| {
                force.push(-w.contact_force(bottom).0.y);
                vtk.maybe(out, w)
            },
        )?;
        all.merge(&push);
        vtk.finish(&mut ctx.out, world)?;
        for (i, f) in force.iter().enumerate() {
            table.rows[i][k + 1] = *f;
        }
        // Statistics over the second half (after the start-up transient).
        let half = &force[force.len() / 2..];
        let (m, sd) = mean_std(half);
        let (fmin, fmax) = half
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        s.num(
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
        headline.push(format!(
            "{name:<17}: force on the moving wall {m:.3} N ± {sd:.3} N (weight {weight:.3} N; relative fluctuation {:.3})",
            sd / m.abs().max(1e-300)
        ));
        let mut p = XyPlot::new(
            &format!(
                "{}: μ grain–grain = {}, μ grain–wall = {}",
                name.replace('_', " "),
                friction.grain_grain,
                friction.grain_wall
            ),
            Axis::new("time since the start of the push t (s)"),
            Axis::new("force on the moving wall (N)"),
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
            force
                .iter()
                .enumerate()
                .map(|(i, f)| ((i + 1) as f64 * c.dt, *f))
                .collect(),
        ));
        p.legend = LegendAt::UpperRight;
        plots.push(p);
        let _ = t0;
        let snap = world.snapshot();
        draw_particles(
            &mut ctx.out,
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
            },
        )?;
    }
    solver_keys(&mut s, &all);
    table.comments.push(
        "force received by the moving bottom wall from the grains, per metre of thickness".into(),
    );
    table.write(&mut ctx.out, "wall_force.csv")?;
    draw_column(&mut ctx.out, "wall_force.png", &plots, (1200, 1350))?;
    Ok(RunOutcome {
        summary: s,
        headline,
    })
}
