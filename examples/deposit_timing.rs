//! Times the janssen deposition and relaxation phases for a few sub-step counts.
//! `cargo run --release --example deposit_timing -- [grains] [substeps...]`
use grainlaw::scenarios::phases::{run_until_rest, RunUntilRest};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let grains: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(350);
    let subs: Vec<usize> = if args.len() > 1 {
        args[1..].iter().filter_map(|s| s.parse().ok()).collect()
    } else {
        vec![1, 2, 4, 8]
    };
    let loaded =
        grainlaw::scenarios::registry::load("janssen", &[format!("grains={grains}")]).unwrap();
    let c: grainlaw::scenarios::janssen::config::JanssenConfig =
        grainlaw::scenarios::registry::config_of(&loaded).unwrap();
    for s in subs {
        let width =
            grainlaw::scenarios::common::build::column_width(&c.grain, c.grains, c.column_aspect);
        let mut col = grainlaw::scenarios::common::build::column(
            &c.grain,
            c.grains,
            width,
            &c.friction,
            c.seed,
            c.dt / s as f64,
        )
        .unwrap();
        col.world.params.solver = c.deposit.solver.params();
        let t0 = Instant::now();
        let st = run_until_rest(
            &mut col.world,
            &RunUntilRest {
                min_time: 0.0,
                max_time: c.deposit.max_time,
                rest_energy: c.deposit.rest_energy,
            },
            |_, _| true,
        )
        .unwrap();
        let td = t0.elapsed().as_secs_f64();
        col.world.params.dt = c.dt;
        col.world.params.solver = c.relax.solver.params();
        let t1 = Instant::now();
        let sr = run_until_rest(
            &mut col.world,
            &RunUntilRest {
                min_time: c.relax.min_time,
                max_time: c.relax.max_time,
                rest_energy: c.relax.rest_energy,
            },
            |w, r| {
                if std::env::var("VERB").is_ok() {
                    eprintln!(
                        "{} {} {:.2e} ke {:.2e} contacts {}",
                        r.step,
                        r.solver.iterations,
                        r.solver.error,
                        w.kinetic_energy(),
                        r.active_contacts
                    );
                }
                true
            },
        )
        .unwrap();
        let tr = t1.elapsed().as_secs_f64();
        let bottom = col.world.contact_force(col.bottom).0.y;
        let weight: f64 = col
            .world
            .bodies
            .iter()
            .filter(|b| b.kind == dem::BodyKind::Grain)
            .map(|b| b.mass * 9.81)
            .sum();
        println!("substeps {s}: width {:.4} deposit {:.2}s wall, {} steps ({:.3} s sim) rest {} mean sweeps {:.1} max {} unconv {} worst {:.2e} | relax {:.2}s wall {} steps rest {} sweeps {:.1} max {} unconv {} worst {:.2e} | bottom/weight {:.3}",
            width, td, st.steps, st.simulated_time, st.at_rest, st.mean_sweeps(), st.max_sweeps, st.unconverged_steps, st.worst_error,
            tr, sr.steps, sr.at_rest, sr.mean_sweeps(), sr.max_sweeps, sr.unconverged_steps, sr.worst_error, bottom / weight);
    }
}
