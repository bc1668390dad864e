//! Profile target: a settled 4000-grain deposit stepped at tight tolerance.
fn main() {
    let mut w = grainlaw_core::benchmarks::deposit_world(4000, 0.4, 1);
    for _ in 0..800 {
        let _ = w.step();
    }
    w.params.solver.tolerance = 1e-7;
    w.params.solver.max_iterations = 200;
    let t = std::time::Instant::now();
    let mut upd = 0usize;
    for _ in 0..100 {
        let r = w.step().unwrap();
        upd += r.contacts * r.solver.iterations;
    }
    let s = t.elapsed().as_secs_f64();
    println!("{:.3e} updates/s, {:.3e} s/step", upd as f64 / s, s / 100.0);
}
