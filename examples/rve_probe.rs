//! Probe of the simple-shear RVE's cost per step (experiment tool, not part of the product).
//!
//! `rve_probe compress GRAINS OUT.json [dt tol overlap_rate steps]`
//! `rve_probe shear IN.json I STRAIN [tol overlap_rate travel resolve_every]`
use std::time::Instant;

use dem::cell::{Imposed, Mat};
use grainlaw::scenarios::common::{implicit_cell_control, mean_diameter};
use homogenise::cell::cell_state;

fn arg(a: &[String], i: usize, d: f64) -> f64 {
    a.get(i).map_or(d, |s| s.parse().unwrap())
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let p = 1000.0;
    let rho = 2500.0;
    match a[1].as_str() {
        "compress" => {
            let n: usize = a[2].parse().unwrap();
            let loaded = datasets::scenario::load(
                "simple-shear",
                &[format!("grains={n}"), "inertial_numbers=[0.01, 0.02, 0.03, 0.04, 0.05]".into()],
            )
            .unwrap();
            let datasets::Scenario::SimpleShear(c) = loaded.scenario else {
                panic!()
            };
            let dt = arg(&a, 4, 5e-4);
            let mut w = datasets::build_cell::simple_shear(&c).unwrap();
            w.params.dt = dt;
            w.params.solver.tolerance = arg(&a, 5, 1e-4);
            w.params.overlap_rate = arg(&a, 6, 1e-4);
            let steps = arg(&a, 7, 300.0) as usize;
            w.params.solver.method = dem::solver::SolverMethod::Nlgs;
            w.params.solver.max_iterations = arg(&a, 8, 300.0) as usize;
            let d = mean_diameter(&w);
            let cap = c.control_inertial_number * (p / rho as f64).sqrt() / d;
            w.cell_control = Some(implicit_cell_control(
                Imposed::Stress(-p),
                Imposed::Stress(-p),
                Imposed::Rate(0.0),
                cap,
                p,
                true,
            ));
            w.validate(1e-9).unwrap();
            let t0 = Instant::now();
            let mut sweeps = 0;
            for k in 0..steps {
                let r = w.step().unwrap();
                sweeps += r.solver.iterations;
                if k % 10 == 9 || k + 1 == steps {
                    let cs = cell_state(&w.snapshot()).unwrap();
                    println!(
                        "{k} t={:.3} sw={} err={:.2e} conv={} p={:.1} phi={:.4} Z={:.2} wall={:.1}",
                        w.time,
                        r.solver.iterations,
                        r.solver.error,
                        r.solver.converged,
                        cs.pressure,
                        cs.solid_fraction,
                        cs.coordination,
                        t0.elapsed().as_secs_f64()
                    );
                }
            }
            println!("total sweeps {sweeps}");
            std::fs::write(&a[3], serde_json::to_string(&w.state()).unwrap()).unwrap();
        }
        "shear" => {
            let s: dem::checkpoint::WorldState =
                serde_json::from_str(&std::fs::read_to_string(&a[2]).unwrap()).unwrap();
            let mut w = dem::World::from_state(s);
            let i: f64 = a[3].parse().unwrap();
            let strain: f64 = a[4].parse().unwrap();
            w.params.solver.tolerance = arg(&a, 5, 1e-4);
            w.params.overlap_rate = arg(&a, 6, 1e-4);
            let travel = arg(&a, 7, 0.02);
            let every = arg(&a, 8, 0.0) as u64;
            w.params.solver.max_iterations = arg(&a, 11, 300.0) as usize;
            let gain_factor = arg(&a, 12, 1.0);
            if let Some(m) = a.get(9) {
                w.params.solver.method = match m.as_str() {
                    "nlgs" => dem::solver::SolverMethod::Nlgs,
                    _ => dem::solver::SolverMethod::Auto,
                };
            }
            let d = mean_diameter(&w);
            let rmean = d / 2.0;
            let gd = i * (p / rho as f64).sqrt() / d;
            let dt = travel * rmean / (gd * d);
            w.params.dt = dt;
            let l = w.cell().map_or_else(Mat::zeros, |cell| cell.l);
            w.set_velocity_gradient(Mat::new(0.0, gd, 0.0, l[(1, 1)]));
            let cap = 0.02 * (p / rho as f64).sqrt() / d;
            w.cell_control = Some(implicit_cell_control(
                Imposed::Rate(0.0),
                Imposed::Stress(-p),
                Imposed::Rate(gd),
                cap.max(gd),
                p,
                false,
            ));
            if let Some(c) = w.cell_control.as_mut() {
                c.gain *= gain_factor;
            }
            w.record_problems = every > 0;
            let steps = (strain / (gd * dt)).ceil() as u64;
            println!("dt={dt:.3e} steps={steps}");
            let t0 = Instant::now();
            let mut sweeps = 0;
            let (mut smu, mut sphi, mut n) = (0.0, 0.0, 0.0);
            let mut dmu = Vec::new();
            for k in 0..steps {
                let r = w.step().unwrap();
                sweeps += r.solver.iterations;
                let cs = cell_state(&w.snapshot()).unwrap();
                let st = cs.stress;
                let mu = st[(0, 1)].abs() / -st[(1, 1)];
                println!("S {k} {mu} {} {} {} {}", cs.solid_fraction, st[(1, 1)], r.solver.iterations, r.solver.error);
                if k >= steps / 2 {
                    smu += mu;
                    sphi += cs.solid_fraction;
                    n += 1.0;
                }
                if every > 1_000_000 && k >= steps / 2 && k % every == 0 {
                    let t1 = Instant::now();
                    if let grainlaw::scenarios::sensitivity::Resolved::Solved((pair, exact)) =
                        grainlaw::scenarios::sensitivity::resolved_pair(&w, |snap| {
                            let s = cell_state(snap).ok()?.stress;
                            Some([s[(0, 1)], s[(1, 1)]])
                        })
                    {
                        let mu2 = pair[0].abs() / -pair[1];
                        dmu.push(mu2 - mu);
                        println!(
                            "  resolve k={k} mu={mu:.4} mu'={mu2:.4} syy'/syy={:.5} exact={exact} ({:.2}s)",
                            pair[1] / st[(1, 1)],
                            t1.elapsed().as_secs_f64()
                        );
                    }
                }
                if k % 20 == 19 || k + 1 == steps {
                    println!(
                        "{k} g={:.3} sw={} err={:.2e} conv={} mu={:.4} syy={:.1} phi={:.4} Z={:.2} pen={:.2e} wall={:.1}",
                        gd * dt * (k + 1) as f64,
                        r.solver.iterations,
                        r.solver.error,
                        r.solver.converged,
                        mu,
                        st[(1, 1)],
                        cs.solid_fraction,
                        cs.coordination,
                        r.max_penetration,
                        t0.elapsed().as_secs_f64()
                    );
                }
            }
            if every > 0 {
                let (problem, r) = w.last_step_problem().unwrap();
                let e0 = dem::fc::fc_error(&problem, &r);
                let st = cell_state(&w.snapshot()).unwrap().stress;
                println!("run error {e0:.3e} mu {:.5} syy {:.2}", st[(0, 1)].abs() / -st[(1, 1)], st[(1, 1)]);
                for (meth, its) in [("nlgs", 1000usize), ("nlgs", 5000), ("nlgs", 20000), ("newton", 200)] {
                    let t1 = Instant::now();
                    let opts = dem::fc::FcOptions {
                        tolerance: 1e-7,
                        max_iterations: its,
                        initial_guess: Some(r.clone()),
                        ..Default::default()
                    };
                    let m = if meth == "nlgs" { dem::fc::SolverMethod::Nlgs } else { dem::fc::SolverMethod::Newton };
                    match dem::fc::solve_by(&problem, &opts, m, &dem::fc::NewtonParams::default()) {
                        Ok((sol, _)) => {
                            let snap = w.snapshot_with_last_impulses(&sol.r).unwrap();
                            let s2 = cell_state(&snap).unwrap().stress;
                            println!("  {meth} {its}: err {:.3e} its {} mu {:.5} syy {:.2} ({:.2}s)", sol.error, sol.iterations, s2[(0, 1)].abs() / -s2[(1, 1)], s2[(1, 1)], t1.elapsed().as_secs_f64());
                        }
                        Err(e) => println!("  {meth}: {e}"),
                    }
                }
            }
            let m = dmu.iter().sum::<f64>() / dmu.len().max(1) as f64;
            println!(
                "total sweeps {sweeps} per step {:.1}; mean mu (2nd half) {:.4} phi {:.4}; resolve dmu mean {m:.2e} n={} wall {:.1}",
                sweeps as f64 / steps as f64,
                smu / n,
                sphi / n,
                dmu.len(),
                t0.elapsed().as_secs_f64()
            );
            if let Some(out) = a.get(10) {
                std::fs::write(out, serde_json::to_string(&w.state()).unwrap()).unwrap();
            }
        }
        _ => panic!(),
    }
}
