//! Time per step of a settled deposit for several grain counts:
//! `cargo run --release -p dem --example engine_bench -- 1000 10000`.
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
    println!(
        "{:>8} {:>9} {:>7} {:>12} {:>14} {:>6}",
        "grains", "contacts", "sweeps", "s/step", "updates/s", "unconv"
    );
    for n in ns {
        let r = dem::bench::deposit_benchmark(n, 1500, 100);
        println!(
            "{:>8} {:>9.0} {:>7.1} {:>12.3e} {:>14.3e} {:>6}",
            r.grains,
            r.contacts,
            r.sweeps,
            r.seconds_per_step,
            r.contact_updates_per_second,
            r.unconverged_steps
        );
    }
}
