//! Time per step of a settled deposit (about 25 grains deep, box widening with N) on 1 and 2
//! threads: `cargo run --release -p datasets --example engine_scaling -- 1000 10000 100000`.
use datasets::benchmarks::{scaling_deposit, scaling_exponent, time_steps};

fn main() {
    let ns: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let ns = if ns.is_empty() {
        vec![1000, 10_000]
    } else {
        ns
    };
    let relax: usize = std::env::var("RELAX").map_or(100, |v| v.parse().expect("RELAX"));
    let steps: usize = std::env::var("STEPS").map_or(20, |v| v.parse().expect("STEPS"));
    println!("grains threads contacts sweeps s/step updates/s unconverged");
    let mut rows = Vec::new();
    for n in ns {
        let t = std::time::Instant::now();
        let mut w0 = scaling_deposit(n, relax, true, 1).expect("deposit");
        if let Ok(v) = std::env::var("OVERLAP") {
            w0.params.overlap_rate = v.parse().expect("OVERLAP");
        }
        eprintln!("prepared {n} in {:.1} s", t.elapsed().as_secs_f64());
        for threads in [1, 2] {
            let mut w = w0.clone();
            let r = time_steps(&mut w, steps, threads).expect("steps");
            println!(
                "{:>8} {:>2} {:>9.0} {:>6.1} {:>10.3e} {:>10.3e} {:>3}",
                r.grains,
                r.threads,
                r.contacts,
                r.sweeps,
                r.seconds_per_step,
                r.updates_per_second,
                r.unconverged_steps
            );
            if threads == 1 {
                rows.push(r);
            }
        }
    }
    if let Some(a) = scaling_exponent(&rows) {
        println!("time per step ∝ N^{a:.3} (one thread)");
    }
}
