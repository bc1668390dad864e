//! Exploration: settle a Janssen column of N grains to KE/PE < 1e-8, printing the solver effort.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(2000);
    let dt: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1e-3);
    let tol: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1e-4);
    let parallel = args.get(3).is_some_and(|s| s == "par");
    let mut w = dem::bench::grid_world(n, 0.12, 0.5, 1);
    w.params.dt = dt;
    w.params.solver.tolerance = tol;
    w.params.solver.max_iterations = std::env::var("CAP").map_or(2000, |c| c.parse().unwrap());
    w.params.solver.parallel = parallel;
    if let Ok(m) = std::env::var("AA") {
        w.params.solver.anderson_memory = m.parse().unwrap();
    }
    if let Ok(m) = std::env::var("OMEGA") {
        w.params.solver.relaxation = m.parse().unwrap();
    }
    let t0 = std::time::Instant::now();
    for s in 0..2000 {
        let r = w.step().unwrap();
        let e = dem::bench::energy_ratio(&w);
        if s % 10 == 0 || !r.solver.converged {
            println!(
                "{s:5} t={:.3} c={} it={} err={:.2e} conv={} KE/PE={e:.2e} pen={:.2e} wall={:.1}",
                w.time,
                r.contacts,
                r.solver.iterations,
                r.solver.error,
                r.solver.converged,
                r.max_penetration,
                t0.elapsed().as_secs_f64()
            );
        }
        if e < 1e-8 {
            println!("settled at step {s}, {:.2} s", t0.elapsed().as_secs_f64());
            break;
        }
    }
}
